#!/usr/bin/env python3
"""Switching figures of an ER trace (nrl_er_harness's CSV), with the classifier of
components/pvrnn/test/switching_test.cpp (switch_classifier.py): the robot "follows" primitive p
when its last 8 intentions are nearest (sum of squared distances) to 8 consecutive steps of p's
data set trajectory (any phase, cyclic) among all primitives.

    bench/pvrnn/nrl_switch_figures.py TRACE.csv [DATA_DIR] [--pushed 2] [--own 1] [--human 100]

Prints: first step following the pushed primitive, pushed steps of the human's (and bursts),
own-primitive steps after release. Errors name the file and line, exit 2."""
import csv, sys

from switch_classifier import classify, load_primitives

def fail(msg):
    print(f"nrl_switch_figures: {msg}", file=sys.stderr)
    sys.exit(2)

def main(argv):
    args, opts = [], {"--pushed": 2, "--own": 1, "--human": 100}
    it = iter(argv)
    for a in it:
        if a in opts:
            try:
                opts[a] = int(next(it))
            except (StopIteration, ValueError):
                fail(f"{a}: needs an integer")
        else:
            args.append(a)
    if not 1 <= len(args) <= 2:
        fail("usage: nrl_switch_figures.py TRACE.csv [DATA_DIR] [--pushed P] [--own P] [--human H]")
    data = args[1] if len(args) > 1 else "/work/shared/data/vcbot/dataset/Macaw"
    prims = load_primitives(data, fail)
    recent, first, pushed, bursts, own_after, following = [], None, 0, 0, 0, False
    try:
        f = open(args[0])
    except OSError as e:
        fail(f"{args[0]}: cannot open ({e.strerror})")
    with f:
        for n, row in enumerate(csv.DictReader(f), 2):
            try:
                t, x, y = int(row["step"]), float(row["intention_x"]), float(row["intention_y"])
            except (KeyError, ValueError, TypeError):
                fail(f"{args[0]}:{n}: needs step, intention_x, intention_y")
            recent = (recent + [(x, y)])[-8:]
            cls = classify(recent, prims)
            if 0 <= t < opts["--human"]:
                if cls == opts["--pushed"]:
                    first = t if first is None else first
                    pushed += 1
                    bursts += not following
                following = cls == opts["--pushed"]
            elif t >= opts["--human"] and cls == opts["--own"]:
                own_after += 1
    print(f"first follows pushed at step {first if first is not None else 'never'} | "
          f"pushed {pushed}/{opts['--human']} steps in {bursts} bursts | own after release {own_after}")

if __name__ == "__main__":
    main(sys.argv[1:])
