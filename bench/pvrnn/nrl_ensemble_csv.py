#!/usr/bin/env python3
"""NRL's ensemble switching figures as the CSV the ensemble test reads
(components/pvrnn/test/data/nrl/nrl_ensemble.csv, switching_test.cpp's
Switching.NrlModeSwitchesLikeNrlOverAnEnsemble), from the output of nrl_reference.sh runs:

    NRL_ENSEMBLE=20 bench/pvrnn/nrl_reference.sh NRL /tmp/o3 > o3.log
    NRL_FLAGS="-O3 -march=native -DNDEBUG" NRL_ENSEMBLE=20 bench/pvrnn/nrl_reference.sh NRL /tmp/nat > native.log
    bench/pvrnn/nrl_ensemble_csv.py O3=o3.log O3-native=native.log > components/pvrnn/test/data/nrl/nrl_ensemble.csv

Each BUILD=LOG reads the log's "seed S: first follows pushed at step N | pushed P/100 steps in B
bursts | own after release H" lines. Errors name the file, exit 2."""
import re
import sys

LINE = re.compile(r"seed (\d+): first follows pushed at step (\S+) \| pushed (\d+)/\d+ steps in (\d+) bursts \| "
                  r"own after release (\d+)")


def main(argv):
    if not argv or any("=" not in a for a in argv):
        print("usage: nrl_ensemble_csv.py BUILD=LOG [BUILD=LOG ...]", file=sys.stderr)
        return 2
    print("build,seed,first_follow,beak_steps,bursts,head_after_release")
    for arg in argv:
        build, path = arg.split("=", 1)
        try:
            lines = open(path).read().splitlines()
        except OSError as e:
            print(f"nrl_ensemble_csv: {path}: cannot open ({e.strerror})", file=sys.stderr)
            return 2
        runs = [m.groups() for m in map(LINE.match, lines) if m]
        if not runs:
            print(f"nrl_ensemble_csv: {path}: no 'seed S: first follows ...' lines", file=sys.stderr)
            return 2
        for run in runs:
            print(",".join((build,) + run))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
