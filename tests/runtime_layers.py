#!/usr/bin/env python3
"""The runtime's layers (docs/runtime.md, "Layers"): a file includes only its own layer and the
layers below it, graph <- dds <- exec <- hosts, and Fast DDS's headers only in dds/ (and in the
one hosts/ file that runs a bare discovery-server participant). Prints every upward include as
file:line and exits 1; exits 0 when there is none.

    runtime_layers.py RUNTIME_DIR
    runtime_layers.py --self-test   the checker finds what it must in a made-up runtime
"""
import pathlib
import re
import sys

LAYERS = ["graph", "dds", "exec", "hosts"]
# Public headers (runtime/include/dyad) by the layer that implements them; None: the component
# API every layer may use.
PUBLIC = {
    "component.hpp": None, "join_list.hpp": None, "message_traits.hpp": None, "status.hpp": None, "params.hpp": None,
    "thread_annotations.hpp": None,
    "graph.hpp": "graph", "validate.hpp": "graph", "catalog.hpp": "graph", "topic_select.hpp": "graph", "topic_readers.hpp": "graph",
    "diagnostic.hpp": "graph", "strict_yaml.hpp": "graph", "security.hpp": "graph", "ros2_names.hpp": "graph",
    "wire_names.hpp": "graph", "keystore_graph.hpp": "graph",
    "on_demand_subscription.hpp": "graph", "run_stopping.hpp": "graph",
    "decode_sample.hpp": "dds", "encode_sample.hpp": "dds",
    "interrupt.hpp": "exec", "private_file.hpp": "exec",
    "run.hpp": "hosts", "introspect.hpp": "hosts", "guest.hpp": "hosts", "discovery_server.hpp": "hosts",
}
FASTDDS_ALLOWED = {"hosts/discovery_server.cpp"}
INCLUDE = re.compile(r'^\s*#\s*include\s*[<"]([^>"]+)[>"]')


def layer_of_include(name):
    """The layer of an included file, None for the component API, '' for anything else."""
    parts = name.split("/")
    if len(parts) == 2 and parts[0] in LAYERS:
        return parts[0]
    if len(parts) == 2 and parts[0] == "dyad" and parts[1] in PUBLIC:
        return PUBLIC[parts[1]]
    return ""


def check(root):
    problems = []
    files = [(f, f.parent.name) for layer in LAYERS for f in sorted((root / layer).glob("*.[ch]pp"))]
    files += [(f, PUBLIC.get(f.name, "")) for f in sorted((root / "include" / "dyad").glob("*.hpp"))]
    for path, layer in files:
        rel = path.relative_to(root).as_posix()
        if layer == "" and path.parent.name == "dyad":
            problems.append(f"{rel}:1: a public header the layer map of tests/runtime_layers.py does not know")
            continue
        for number, line in enumerate(path.read_text().splitlines(), 1):
            m = INCLUDE.match(line)
            if not m:
                continue
            name = m.group(1)
            if name.startswith(("fastdds/", "fastrtps/", "fastcdr/")):
                if layer not in ("dds", None) and rel not in FASTDDS_ALLOWED and path.name != "message_traits.hpp":
                    problems.append(f"{rel}:{number}: includes Fast DDS ({name}) outside the dds layer")
                continue
            target = layer_of_include(name)
            if target in ("", None):
                continue
            if layer is None or LAYERS.index(target) > LAYERS.index(layer):
                problems.append(f"{rel}:{number}: {layer or 'the component API'} includes {name} "
                                f"from the {target} layer above it")
    return problems, len(files)


def self_test():
    import tempfile
    with tempfile.TemporaryDirectory() as d:
        root = pathlib.Path(d)
        for layer in LAYERS:
            (root / layer).mkdir()
        (root / "include" / "dyad").mkdir(parents=True)
        (root / "graph" / "up.cpp").write_text('#include "graph/ok.hpp"\n#include "exec/executor.hpp"\n')
        (root / "exec" / "dds_direct.cpp").write_text('#include "dds/transport.hpp"\n#include <fastdds/dds/core/Entity.hpp>\n')
        (root / "dds" / "public_up.cpp").write_text('#include <dyad/run.hpp>\n#include <dyad/graph.hpp>\n')
        (root / "include" / "dyad" / "graph.hpp").write_text('#include <dyad/run.hpp>\n')
        (root / "include" / "dyad" / "unknown.hpp").write_text('')
        problems, _ = check(root)
    want = ["exec/dds_direct.cpp:2:", "graph/up.cpp:2:", "dds/public_up.cpp:1:", "include/dyad/graph.hpp:1:",
            "include/dyad/unknown.hpp:1:"]
    found = [w for w in want if any(p.startswith(w) for p in problems)]
    if sorted(found) != sorted(want) or len(problems) != len(want):
        print("runtime_layers self-test: expected problems at", want, "got", problems, file=sys.stderr)
        return 1
    print(f"runtime_layers self-test: the {len(want)} planted problems found, nothing else")
    return 0


def main():
    if sys.argv[1:] == ["--self-test"]:
        return self_test()
    if len(sys.argv) != 2:
        print(__doc__, file=sys.stderr)
        return 2
    root = pathlib.Path(sys.argv[1])
    if not all((root / layer).is_dir() for layer in LAYERS):
        print(f"{root}: not the runtime folder (no {', '.join(LAYERS)} folders)", file=sys.stderr)
        return 2
    problems, count = check(root)
    for p in problems:
        print(p)
    if problems:
        print(f"runtime_layers: {len(problems)} include(s) against the layers", file=sys.stderr)
        return 1
    print(f"runtime_layers: {count} files, every include downward")
    return 0


if __name__ == "__main__":
    sys.exit(main())
