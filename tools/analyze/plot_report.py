#!/usr/bin/env python3
"""Draws the PNG plots of a `dyad analyze` report folder from its CSV tables.

usage: plot_report.py REPORT_DIR [--dataset DATASET_DIR]

Reads REPORT_DIR/timeline.csv and events.csv (written by `dyad analyze`), params.csv when the
run had live parameter changes (dotted lines on the time axes), notes.csv when the experimenter
wrote notes (dashed green lines with the note) and, when given, the
data set's primitive_<id>_0.csv files (NRL layout) as a grey watermark. Writes
workspace.png, nelbo.png and congruence.png into REPORT_DIR. Needs python3-matplotlib only.
"""
import argparse
import csv
import glob
import math
import os
import re
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def number(text):
    return float(text) if text not in ("", None) else math.nan


def read_csv(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def engaged_spans(rows):
    """(start_s, end_s) of each run of engaged steps."""
    spans, start = [], None
    period = number(rows[1]["time_s"]) - number(rows[0]["time_s"]) if len(rows) > 1 else 0.1
    for r in rows:
        t, on = number(r["time_s"]), r["engaged"] == "1"
        if on and start is None:
            start = t
        if not on and start is not None:
            spans.append((start, t))
            start = None
    if start is not None:
        spans.append((start, number(rows[-1]["time_s"]) + period))
    return spans


def load_dataset(folder):
    shapes = []
    files = glob.glob(os.path.join(folder, "primitive_*_0.csv"))
    for path in sorted(files, key=lambda p: int(re.findall(r"primitive_(\d+)_0", p)[0])):
        xs, ys = [], []
        with open(path) as f:
            for line in f:
                parts = line.strip().split(",")
                if len(parts) >= 2:
                    xs.append(float(parts[0]))
                    ys.append(float(parts[1]))
        shapes.append((xs, ys))
    return shapes


def column(rows, name):
    return [number(r[name]) for r in rows]


def read_optional(report_dir, name):
    """The rows of REPORT_DIR/name; none when the report has no such file."""
    path = os.path.join(report_dir, name)
    return read_csv(path) if os.path.exists(path) else []


def short(text, limit=40):
    """A line's label: a long text cut, a '$' kept out of mathtext."""
    if len(text) > limit:
        text = text[:limit - 1] + "\u2026"
    return text.replace("$", r"\$")


def read_marks(report_dir):
    """What the time axes mark: the live parameter changes (params.csv), e.g. mixer.gain 0.9→0.2,
    and the experimenter's notes (notes.csv), as (kind, time_s, label)."""
    marks = [("parameter change", number(c["time_s"]), short(f"{c['component']}.{c['param']} {c['old_value']}\u2192{c['value']}"))
             for c in read_optional(report_dir, "params.csv")]
    marks += [("experimenter's note", number(n["time_s"]), short("note: " + n["text"]))
              for n in read_optional(report_dir, "notes.csv")]
    return marks


MARK_STYLE = {"parameter change": dict(color="0.3", ls=":"), "experimenter's note": dict(color="tab:green", ls="--")}


def mark_times(ax, marks):
    """Each mark as a vertical line at its time, its label rotated along it near the top."""
    seen = set()
    for kind, t, label in marks:
        style = MARK_STYLE[kind]
        ax.axvline(t, lw=1.0, zorder=3, label=kind if kind not in seen else None, **style)
        seen.add(kind)
        # x in data, y in axes fractions: the label stays near the top whatever the y scale.
        ax.text(t, 0.97, label, transform=ax.get_xaxis_transform(), rotation=90, fontsize=6.5,
                ha="right", va="top", color=style["color"], zorder=4)


def plot_workspace(rows, shapes, out):
    fig, ax = plt.subplots(figsize=(7, 7))
    for i, (xs, ys) in enumerate(shapes):
        ax.plot(xs + xs[:1], ys + ys[:1], color="0.85", lw=6, zorder=0, solid_capstyle="round")
    for i, (xs, ys) in enumerate(shapes):
        # At the primitive's first point (where a human tracing it starts), above the lines: at
        # the centroid, the labels of shapes around the origin fell on one spot under the traces.
        ax.annotate(f"p{i}", (xs[0], ys[0]), color="0.25", fontsize=8, ha="center", va="center", zorder=5,
                    bbox=dict(boxstyle="round,pad=0.15", fc="white", ec="0.6", lw=0.5, alpha=0.9))
    ax.plot(column(rows, "robot_x"), column(rows, "robot_y"), color="tab:blue", lw=0.6, alpha=0.7, label="robot intention")
    ax.plot(column(rows, "executed_x"), column(rows, "executed_y"), color="black", lw=0.8, label="executed")
    hx = [number(r["human_x"]) if r["engaged"] == "1" else math.nan for r in rows]
    hy = [number(r["human_y"]) if r["engaged"] == "1" else math.nan for r in rows]
    ax.plot(hx, hy, ".", color="tab:red", ms=2.5, label="human (engaged)")
    ax.set_aspect("equal")
    ax.set_xlabel("x (workspace units)")
    ax.set_ylabel("y (workspace units)")
    ax.set_title("Trajectories in the workspace" + (" (data set in grey, pN at primitive N's start)" if shapes else ""),
                 fontsize=10)
    ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.08), ncol=3, fontsize=8)
    fig.tight_layout()
    fig.savefig(out, dpi=110)
    plt.close(fig)


def shade(ax, spans):
    for i, (a, b) in enumerate(spans):
        ax.axvspan(a, b, color="tab:red", alpha=0.12, lw=0, label="human engaged" if i == 0 else None)


def plot_nelbo(rows, marks, out):
    t = column(rows, "time_s")
    fig, ax = plt.subplots(figsize=(10, 3.5))
    shade(ax, engaged_spans(rows))
    ax.plot(t, column(rows, "nelbo"), color="tab:purple", lw=0.8, label="N-ELBO")
    ax.plot(t, column(rows, "reconstruction"), color="tab:green", lw=0.6, alpha=0.7, label="reconstruction")
    ax.set_yscale("symlog", linthresh=1e-3)
    mark_times(ax, marks)
    ax.set_xlabel("time (s)")
    ax.set_ylabel("free energy of the window")
    ax.set_title("Robot's N-ELBO after each step's error regression")
    ax.legend(loc="upper left", bbox_to_anchor=(1.0, 1.0), fontsize=8)
    fig.tight_layout()
    fig.savefig(out, dpi=110)
    plt.close(fig)


def plot_congruence(rows, events, marks, out):
    t = column(rows, "time_s")
    fig, (top, bottom) = plt.subplots(2, 1, figsize=(10, 6), gridspec_kw={"height_ratios": [2, 1]})
    shade(top, engaged_spans(rows))
    top.plot(t, column(rows, "congruence"), color="tab:orange", lw=0.9, label="P(C_t)")
    top.set_ylim(-0.02, 1.02)
    mark_times(top, marks)
    top.set_xlabel("time (s)")
    top.set_ylabel("intention congruence")
    top.legend(loc="upper left", bbox_to_anchor=(1.0, 1.0), fontsize=8)
    labels = [f"{e['event']}\n(p{e['primitive']})" for e in events]
    means = [number(e["mean_congruence"]) for e in events]
    finals = [number(e["final_congruence"]) for e in events]
    xs = list(range(len(events)))
    bottom.bar([x - 0.2 for x in xs], means, width=0.4, label="mean during event", color="tab:orange")
    bottom.bar([x + 0.2 for x in xs], finals, width=0.4, label="at event end", color="tab:brown")
    bottom.set_xticks(xs)
    bottom.set_xticklabels(labels, fontsize=8)
    bottom.set_ylim(0, 1)
    bottom.set_ylabel("P(C)")
    bottom.set_xlabel("event (primitive traced by the human)")
    bottom.legend(loc="upper left", bbox_to_anchor=(1.0, 1.0), fontsize=8)
    fig.tight_layout()
    fig.savefig(out, dpi=110)
    plt.close(fig)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("report_dir")
    parser.add_argument("--dataset", default="")
    args = parser.parse_args()
    try:
        rows = read_csv(os.path.join(args.report_dir, "timeline.csv"))
        events = read_csv(os.path.join(args.report_dir, "events.csv"))
        marks = read_marks(args.report_dir)
    except (OSError, csv.Error, KeyError) as e:
        print(f"plot_report.py: {e}", file=sys.stderr)
        return 2
    if not rows:
        print(f"plot_report.py: {args.report_dir}/timeline.csv has no steps", file=sys.stderr)
        return 2
    shapes = load_dataset(args.dataset) if args.dataset else []
    plot_workspace(rows, shapes, os.path.join(args.report_dir, "workspace.png"))
    plot_nelbo(rows, marks, os.path.join(args.report_dir, "nelbo.png"))
    plot_congruence(rows, events, marks, os.path.join(args.report_dir, "congruence.png"))
    return 0


if __name__ == "__main__":
    sys.exit(main())
