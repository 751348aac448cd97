#!/usr/bin/env python3
"""What `dyad dataset from-recording --preview` cut: each primitive of an NRL data set drawn in
the workspace (its start marked), titled with the segment it came from and any warning.

    plot_dataset.py DATASET_DIR OUT.png [--label K=TEXT]...
"""
import argparse
import csv
import glob
import os
import re

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("dataset")
    ap.add_argument("out")
    ap.add_argument("--label", action="append", default=[], help="K=TEXT: the title of primitive K")
    a = ap.parse_args()
    labels = dict(entry.split("=", 1) for entry in a.label)
    files = sorted(glob.glob(os.path.join(a.dataset, "primitive_*_0.csv")),
                   key=lambda f: int(re.search(r"primitive_(\d+)_0", f).group(1)))
    if not files:
        raise SystemExit(f"{a.dataset}: no primitive_<id>_0.csv")
    cols = min(4, len(files))
    rows = (len(files) + cols - 1) // cols
    fig, axes = plt.subplots(rows, cols, figsize=(3.2 * cols, 3.2 * rows), squeeze=False)
    for ax in axes.flat:
        ax.axis("off")
    for k, f in enumerate(files):
        with open(f) as fh:
            pts = [(float(r[0]), float(r[1])) for r in csv.reader(fh) if r]
        ax = axes.flat[k]
        ax.axis("on")
        ax.plot([p[0] for p in pts], [p[1] for p in pts], "-", color="#1f77b4", lw=1.5)
        ax.plot(pts[0][0], pts[0][1], "o", color="#2ca02c", label="start")
        ax.set_aspect("equal", adjustable="datalim")
        ax.set_title(labels.get(str(k), f"primitive {k}"), fontsize=8, wrap=True)
        ax.tick_params(labelsize=7)
    fig.tight_layout()
    fig.savefig(a.out, dpi=100)


if __name__ == "__main__":
    main()
