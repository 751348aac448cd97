"""The switching classifier of components/pvrnn/test/switching_test.cpp, for the bench's figure
scripts (nrl_switch_figures.py, sweep_switch_figures.py; import it from their folder):

    prims = load_primitives(DATA_DIR, fail)   # primitive_<p>_0.csv, p = 0, 1, ... (x,y rows)
    cls = classify(recent, prims)             # recent: the last 8 (x, y) intentions

The robot "follows" primitive p when its last 8 intentions are nearest (sum of squared
distances) to 8 consecutive steps of p's data set trajectory (any phase, cyclic) among all
primitives; the first nearest wins a tie. `fail(message)` is the caller's: it reports and exits
(a file that cannot be read or a line that is not x,y, named with its line)."""
import os


def load_primitives(data, fail):
    prims = []
    for p in range(100):
        path = os.path.join(data, f"primitive_{p}_0.csv")
        if not os.path.exists(path):
            break
        rows = []
        try:
            with open(path) as f:
                for n, line in enumerate(f, 1):
                    if line.strip():
                        try:
                            x, y = map(float, line.split(",")[:2])
                        except ValueError:
                            fail(f"{path}:{n}: expected x,y")
                        rows.append((x, y))
        except OSError as e:
            fail(f"{path}: cannot open ({e.strerror})")
        prims.append(rows)
    if not prims:
        fail(f"{data}: no primitive_<p>_0.csv")
    return prims


def classify(recent, prims):
    best, cls = float("inf"), -1
    for p, seq in enumerate(prims):
        T = len(seq)
        for ph in range(T):
            s = 0.0
            for i, (a, b) in enumerate(recent):
                qx, qy = seq[(ph + i) % T]
                s += (qx - a) ** 2 + (qy - b) ** 2
                if s >= best:
                    break
            if s < best:
                best, cls = s, p
    return cls
