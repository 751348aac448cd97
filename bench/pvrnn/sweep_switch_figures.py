#!/usr/bin/env python3
"""Switching figures of a `dyad sweep` of the study's experiment, per swept setting (for example
configs/sweeps/macaw_nrl.yaml: dyad's error regression and NRL's, side by side).

    python3 bench/pvrnn/sweep_switch_figures.py SWEEP_OUT [--data DIR] [--event 0] [--own 1] [--release 100]

For each run of SWEEP_OUT/sweep.csv with status ok it reads the analysis' timeline.csv and
events.csv (SWEEP_OUT/runs/<id>/report/) and applies the classifier of
components/pvrnn/test/switching_test.cpp (switch_classifier.py) to the robot's intentions: the
robot "follows" primitive p when its last 8 intentions are nearest (sum of squared distances)
to 8 consecutive steps of p's data set trajectory (any phase, cyclic) among all primitives. Event `--event` (the
first: the human pushes the beak from step 100 to 200 in configs/macaw.yaml) gives, per run: the
first step of the push (0 = its first) at which the robot follows the pushed primitive, the push
steps on it (of the event's length) and in how many bursts, and the steps on `--own` (the start
primitive, the head) among the `--release` steps after the release. Per setting (the swept
columns but the seed): the median and range of those over the runs, the means of the sweep's
own metrics (all events, the observer's classes), and the deliberator's solve time per step
(timeline's optimisation_s, wall time even under the stepped clock) as median and p99 over every
step of every run. Prints a Markdown table. Errors name the file and line, exit 2."""
import csv, os, statistics, sys

from switch_classifier import classify, load_primitives


def fail(msg):
    print(f"sweep_switch_figures: {msg}", file=sys.stderr)
    sys.exit(2)


def read_rows(path):
    try:
        with open(path, newline="") as f:
            return list(csv.DictReader(f))
    except OSError as e:
        fail(f"{path}: cannot open ({e.strerror})")


def run_figures(report, opts, prims):
    events = read_rows(os.path.join(report, "events.csv"))
    if len(events) <= opts["--event"]:
        fail(f"{report}/events.csv: no event {opts['--event']}")
    ev = events[opts["--event"]]
    try:
        start, end, pushed = int(ev["start_step"]), int(ev["end_step"]), int(ev["primitive"])
    except (KeyError, ValueError):
        fail(f"{report}/events.csv:{opts['--event'] + 2}: needs start_step, end_step, primitive")
    timeline = os.path.join(report, "timeline.csv")
    xy, solve = {}, []
    for n, row in enumerate(read_rows(timeline), 2):
        try:
            t, x, y, s = int(row["step"]), float(row["robot_x"]), float(row["robot_y"]), float(row["optimisation_s"])
        except (KeyError, ValueError, TypeError):
            fail(f"{timeline}:{n}: needs step, robot_x, robot_y, optimisation_s")
        xy[t] = (x, y)
        if t > 0 and s == s:
            solve.append(s)
    first, on, bursts, own, following = None, 0, 0, 0, False
    for t in range(start, end + opts["--release"]):
        recent = [xy[k] for k in range(t - 7, t + 1) if k in xy]
        if t not in xy or len(recent) < 8:
            fail(f"{timeline}: steps {t - 7}..{t} missing (the run is shorter than the event and its release)")
        cls = classify(recent, prims)
        if t < end:
            if cls == pushed:
                first = t - start if first is None else first
                on += 1
                bursts += not following
            following = cls == pushed
        elif cls == opts["--own"]:
            own += 1
    return {"first": first, "on": on, "of": end - start, "bursts": bursts, "own": own}, solve


def spread(values):
    got = [v for v in values if v is not None]
    never = len(values) - len(got)
    if not got:
        return "never"
    text = f"{statistics.median(got):g} ({min(got):g}-{max(got):g})"
    return text + (f", never in {never}" if never else "")


def percentile(values, q):
    s = sorted(values)
    return s[min(len(s) - 1, int(q * len(s)))] if s else float("nan")


def main(argv):
    opts, args = {"--event": 0, "--own": 1, "--release": 100}, []
    data = "/work/shared/data/vcbot/dataset/Macaw"
    it = iter(argv)
    for a in it:
        if a == "--data":
            data = next(it, None) or fail("--data: needs a folder")
        elif a in opts:
            try:
                opts[a] = int(next(it))
            except (StopIteration, ValueError):
                fail(f"{a}: needs an integer")
        else:
            args.append(a)
    if len(args) != 1:
        fail("usage: sweep_switch_figures.py SWEEP_OUT [--data DIR] [--event E] [--own P] [--release N]")
    out = args[0]
    prims = load_primitives(data, fail)
    rows = read_rows(os.path.join(out, "sweep.csv"))
    if not rows:
        fail(f"{out}/sweep.csv: no runs")
    cols = list(rows[0].keys())
    keys = cols[cols.index("status") + 1:cols.index("seed")]
    settings = {}
    for n, row in enumerate(rows, 2):
        if row["status"] != "ok":
            print(f"sweep_switch_figures: {out}/sweep.csv:{n}: run {row['run']} is {row['status']}, left out", file=sys.stderr)
            continue
        figs, solve = run_figures(os.path.join(out, "runs", row["run"], "report"), opts, prims)
        s = settings.setdefault(" ".join(f"{k}={row[k]}" for k in keys if row[k] != ""), {"runs": [], "solve": [], "metrics": []})
        s["runs"].append(figs)
        s["solve"] += solve
        s["metrics"].append(row)
    if not settings:
        fail(f"{out}/sweep.csv: no run is ok")
    event_steps = next(iter(settings.values()))["runs"][0]["of"]
    print(f"| setting | runs | first follows pushed | push steps on it (of {event_steps}) "
          f"| bursts | own after release (of {opts['--release']}) | switched_fraction | switch_latency_s | robot_follows "
          f"| solve ms median | solve ms p99 |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    for name, s in settings.items():
        mean = lambda m: statistics.mean(float(r[m]) for r in s["metrics"] if r[m] not in ("", "nan"))
        print(f"| {name} | {len(s['runs'])} | {spread([r['first'] for r in s['runs']])} | {spread([r['on'] for r in s['runs']])} "
              f"| {spread([r['bursts'] for r in s['runs']])} | {spread([r['own'] for r in s['runs']])} "
              f"| {mean('switched_fraction'):.3f} | {mean('switch_latency_s'):.2f} | {mean('robot_follows'):.3f} "
              f"| {1e3 * statistics.median(s['solve']):.3f} | {1e3 * percentile(s['solve'], 0.99):.3f} |")


if __name__ == "__main__":
    main(sys.argv[1:])
