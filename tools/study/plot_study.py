#!/usr/bin/env python3
"""Plots of a study's analysis: each measure per condition.

    plot_study.py ANALYSIS_DIR [--include-incomplete]

From ANALYSIS_DIR/trials.csv and summary.csv (dyad study analyze), ANALYSIS_DIR/plots/<measure>.png
shows, for each condition (in summary.csv's order: by label when blind, else the study file's;
named with its blind label), every
participant's mean over their trials of it as a dot, a participant's conditions joined by a faint
line (the design is within participants: what matters is how each person changes), and the
condition's mean over participants with its 95% bootstrap interval from summary.csv (the same
numbers as the report). Trials that lack the measure are left out; a measure nobody has is not drawn.
Incomplete trials (trials.csv's `complete` false: cut short, or shorter than planned) are left
out, as summary.csv leaves them out, unless --include-incomplete (given when the analysis counted them).
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
        v = float(text)
    except (TypeError, ValueError):
        return None
    return v if math.isfinite(v) else None


def main():
    args = sys.argv[1:]
    include_incomplete = "--include-incomplete" in args
    args = [a for a in args if a != "--include-incomplete"]
    if len(args) != 1:
        sys.exit(__doc__)
    folder = args[0]
    with open(os.path.join(folder, "summary.csv"), newline="") as f:
        summary = list(csv.DictReader(f))
    with open(os.path.join(folder, "trials.csv"), newline="") as f:
        trials = [t for t in csv.DictReader(f) if include_incomplete or t.get("complete") != "false"]
    conditions, labels = [], {}
    for row in summary:
        if row["condition"] not in labels:
            conditions.append(row["condition"])
            labels[row["condition"]] = row["label"]
    measures = list(dict.fromkeys(row["measure"] for row in summary))
    out = os.path.join(folder, "plots")
    os.makedirs(out, exist_ok=True)
    drawn = 0
    for measure in measures:
        per = {}  # (participant, condition) -> values
        for t in trials:
            v = number(t.get(measure))
            if v is not None:
                per.setdefault((t["participant"], t["condition"]), []).append(v)
        if not per:
            continue
        fig, ax = plt.subplots(figsize=(1.8 + 1.6 * len(conditions), 4.2))
        x = {c: i for i, c in enumerate(conditions)}
        for p in sorted({p for p, _ in per}):
            pts = [(x[c], sum(per[(p, c)]) / len(per[(p, c)])) for c in conditions if (p, c) in per]
            ax.plot([a for a, _ in pts], [b for _, b in pts], color="0.75", lw=0.8, zorder=1)
            ax.scatter([a for a, _ in pts], [b for _, b in pts], s=18, color="0.35", zorder=2)
        for row in summary:
            if row["measure"] != measure:
                continue
            m, lo, hi = number(row["mean"]), number(row["ci_low"]), number(row["ci_high"])
            if m is None:
                continue
            i = x[row["condition"]]
            ax.errorbar([i + 0.12], [m], yerr=[[m - (lo if lo is not None else m)], [(hi if hi is not None else m) - m]],
                        fmt="D", color="#1f77b4", capsize=5, ms=7, zorder=3)
        ax.set_xticks(range(len(conditions)))
        # A blind analysis names a condition by its label already ("condition A").
        ax.set_xticklabels([c if c == "condition " + labels[c] else "%s (%s)" % (c, labels[c]) for c in conditions])
        ax.set_xlim(-0.5, len(conditions) - 0.5)
        ax.set_ylabel(measure)
        ax.set_title("%s\ngrey: each participant; blue: mean, 95%% bootstrap interval" % measure, fontsize=9)
        fig.tight_layout()
        fig.savefig(os.path.join(out, measure + ".png"), dpi=110)
        plt.close(fig)
        drawn += 1
    print("plots: %d measure%s in %s" % (drawn, "" if drawn == 1 else "s", out))


if __name__ == "__main__":
    main()
