#!/usr/bin/env python3
"""Components stand below tools (docs/components.md): no file under components/ includes a
header that lives under tools/ (the command line's folder). An include is matched by its path:
"run_process.hpp" or "dyad/x.hpp" is a tools/ header when some header under tools/ has that path
at its end and no header under runtime/, support/ or components/ does. Prints every such include
as file:line and exits 1; exits 0 when there is none. KNOWN lists the ones still to move, each
with its reason: it may only shrink (an entry whose include is gone is a problem too).

    component_layers.py SOURCE_DIR
    component_layers.py --self-test   the checker finds what it must in a made-up tree
"""
import pathlib
import re
import sys

INCLUDE = re.compile(r'^\s*#\s*include\s*[<"]([^>"]+)[>"]')
BELOW = ["runtime", "support", "components"]  # where a component's includes may come from
SOURCES = ("*.hpp", "*.h", "*.cpp")
# (file, include): still to move below the components (issue #42 item 3, the part left): the
# learner's data set from a recording (tools/analyze/demonstrations.hpp and recording_tables.hpp,
# which read MCAP and make a pvrnn Dataset, so they belong in a component-level library, not in
# support/).
KNOWN = {("components/learner/learner.hpp", "demonstrations.hpp")}


def headers(root, folder):
    """Every header under root/folder, as paths relative to it."""
    base = root / folder
    return [p.relative_to(base).as_posix() for pattern in ("*.hpp", "*.h") for p in base.rglob(pattern)]


def ends_with(path, name):
    return path == name or path.endswith("/" + name)


def check(root, known=frozenset()):
    root = pathlib.Path(root)
    seen = set()
    tools = headers(root, "tools")
    below = [h for folder in BELOW for h in headers(root, folder)]
    problems = []
    files = sorted(p for pattern in SOURCES for p in (root / "components").rglob(pattern))
    for path in files:
        rel = path.relative_to(root).as_posix()
        for number, line in enumerate(path.read_text(errors="replace").splitlines(), 1):
            m = INCLUDE.match(line)
            if not m:
                continue
            name = m.group(1)
            from_tools = [t for t in tools if ends_with(t, name)]
            if from_tools and not any(ends_with(b, name) for b in below):
                if (rel, name) in known:
                    seen.add((rel, name))
                    continue
                problems.append(f"{rel}:{number}: includes {name} from tools/{from_tools[0]} "
                                f"(components stand below tools: move it to support/ or the runtime)")
    problems += [f"{f}:1: KNOWN in tests/component_layers.py lists its include of {n}, which is gone: drop the entry"
                 for f, n in sorted(set(known) - seen)]
    return problems, len(files)


def self_test():
    import tempfile
    with tempfile.TemporaryDirectory() as d:
        root = pathlib.Path(d)
        for folder in ("tools/support", "tools/analyze", "support", "runtime/include/dyad", "components/a"):
            (root / folder).mkdir(parents=True)
        (root / "tools/support/run_process.hpp").write_text("")
        (root / "tools/analyze/report.hpp").write_text("")
        (root / "tools/analyze/status.hpp").write_text("")  # also a runtime header's name: not a tools/ header
        (root / "runtime/include/dyad/status.hpp").write_text("")
        (root / "support/yaml_file.hpp").write_text("")
        (root / "components/a/a.cpp").write_text(
            '#include "run_process.hpp"\n#include "yaml_file.hpp"\n#include "dyad/status.hpp"\n#include <vector>\n')
        (root / "components/a/a.hpp").write_text('#pragma once\n#include "report.hpp"\n')
        problems, _ = check(root)
        want = ["components/a/a.cpp:1: includes run_process.hpp from tools/support/run_process.hpp",
                "components/a/a.hpp:2: includes report.hpp from tools/analyze/report.hpp"]
        assert len(problems) == len(want) and all(p.startswith(w) for p, w in zip(problems, want)), problems
        problems, _ = check(root, {("components/a/a.hpp", "report.hpp"), ("components/a/b.cpp", "x.hpp")})
        want = [want[0], "components/a/b.cpp:1: KNOWN in tests/component_layers.py lists its include of x.hpp"]
        assert len(problems) == len(want) and all(p.startswith(w) for p, w in zip(problems, want)), problems
    print("component_layers self-test: ok")
    return 0


def main(argv):
    if argv[1:] == ["--self-test"]:
        return self_test()
    if len(argv) != 2:
        print(__doc__, file=sys.stderr)
        return 2
    problems, n = check(argv[1], KNOWN)
    for p in problems:
        print(p)
    if not problems:
        print(f"component_layers: {n} files under components/, none includes from tools/ "
              f"(but the {len(KNOWN)} still to move: KNOWN)")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
