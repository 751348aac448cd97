#!/usr/bin/env python3
"""Plots of a sweep's table: each metric against each swept parameter.

    plot_sweep.py SWEEP_CSV OUT_DIR

For every metric column of sweep.csv (the columns after `seed`) and every swept parameter (the
columns between `status` and `seed`), OUT_DIR/<metric>__<parameter>.png shows, for each value of
the parameter, the mean of the metric over the runs with that value (every seed and every value
of the other parameters) and its 95% confidence interval (mean +- 1.96 standard errors; none
with one run). Numeric parameter values are placed on a numeric axis, others side by side in the
order they first appear. Runs that failed, or lack the metric, are left out.
"""
import csv
import math
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def number(text):
    try:
        return float(text)
    except ValueError:
        return None


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    with open(sys.argv[1], newline="") as f:
        rows = list(csv.DictReader(f))
        header = next(csv.reader(open(sys.argv[1], newline="")))
    seed = header.index("seed")
    params, metrics = header[2:seed], header[seed + 1:]
    rows = [r for r in rows if r["status"] == "ok"]
    os.makedirs(sys.argv[2], exist_ok=True)
    drawn = 0
    for metric in metrics:
        for param in params:
            groups = {}
            for r in rows:
                v = number(r[metric])
                if v is None or not math.isfinite(v):
                    continue
                groups.setdefault(r[param], []).append(v)
            if not groups:
                continue
            keys = list(groups)
            xs = [number(k) for k in keys]
            numeric = all(x is not None for x in xs)
            positions = xs if numeric else list(range(len(keys)))
            means, errors = [], []
            for k in keys:
                vals = groups[k]
                m = sum(vals) / len(vals)
                sd = math.sqrt(sum((v - m) ** 2 for v in vals) / (len(vals) - 1)) if len(vals) > 1 else 0.0
                means.append(m)
                errors.append(1.96 * sd / math.sqrt(len(vals)))
            order = sorted(range(len(keys)), key=lambda i: positions[i]) if numeric else range(len(keys))
            fig, ax = plt.subplots(figsize=(5, 3.5))
            ax.errorbar([positions[i] for i in order], [means[i] for i in order], yerr=[errors[i] for i in order],
                        marker="o", capsize=4)
            if not numeric:
                ax.set_xticks(positions)
                ax.set_xticklabels(keys, rotation=20)
            ax.set_xlabel(param)
            ax.set_ylabel(metric)
            ax.set_title(f"{metric} (mean, 95% CI)")
            fig.tight_layout()
            fig.savefig(os.path.join(sys.argv[2], f"{metric}__{param.replace('/', '_')}.png"), dpi=100)
            plt.close(fig)
            drawn += 1
    print(f"{drawn} plots in {sys.argv[2]}")


if __name__ == "__main__":
    main()
