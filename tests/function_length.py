#!/usr/bin/env python3
"""No function a reader has to scroll: every C++ function under a folder is at most LIMIT lines
long (the house rule, docs/runtime.md; runs on runtime/, components/ and tools/). Functions are found
by universal-ctags (their start and end lines); lambdas count as part of the function that holds them.
Tests and generated code are aside: a file under a folder named test, tests or generated is not
checked (a TEST body is a scenario read top to bottom). Prints each longer one as
file:line: name: N lines and exits 1; exits 0 when there is none.

    function_length.py [--limit N] DIR
    function_length.py --self-test   the checker finds what it must in a made-up file
"""
import json
import pathlib
import subprocess
import sys
import tempfile

DEFAULT_LIMIT = 80
ASIDE = {"test", "tests", "generated"}  # folders whose files are not checked


def functions(root):
    """(path, first line, name, lines) of every function defined under root."""
    try:
        out = subprocess.run(
            ["ctags", "--languages=C++", "--kinds-C++=f", "--fields=+ne", "--output-format=json", "-R", "-f", "-",
             str(root)], check=True, capture_output=True, text=True).stdout
    except FileNotFoundError:
        sys.exit("function_length: universal-ctags is not installed (bash tools/setup.sh installs it)")
    for line in out.splitlines():
        tag = json.loads(line)
        if tag.get("_type") == "tag" and "end" in tag and not aside(root, tag["path"]):
            scope = [s for s in tag.get("scope", "").split("::") if s and not s.startswith("__anon")]
            yield tag["path"], tag["line"], "::".join(scope + [tag["name"]]), tag["end"] - tag["line"] + 1


def aside(root, path):
    """True for a file under a test or generated folder (below root: root itself may be one)."""
    return bool(ASIDE & set(pathlib.Path(path).relative_to(root).parts[:-1]))


def check(root, limit):
    return [f"{path}:{line}: {name}: {lines} lines (at most {limit})"
            for path, line, name, lines in sorted(functions(root)) if lines > limit]


def self_test():
    with tempfile.TemporaryDirectory() as d:
        body = "\n".join(f"  x += {i};" for i in range(10))
        pathlib.Path(d, "a.cpp").write_text(
            "int Short() {\n  return 1;\n}\n\n"
            f"int Long(int x) {{\n{body}\n  return x;\n}}\n\n"
            f"struct S {{\n  void Method() {{\n{body}\n  }}\n}};\n")
        for folder in ("test", "generated"):
            pathlib.Path(d, "x", folder).mkdir(parents=True)
            pathlib.Path(d, "x", folder, "b.cpp").write_text(f"int Long(int x) {{\n{body}\n  return x;\n}}\n")
        problems = check(d, 8)
        assert len(problems) == 2, problems
        assert problems[0].endswith("a.cpp:5: Long: 13 lines (at most 8)"), problems
        assert "S::Method: 12 lines" in problems[1], problems
        assert check(d, 13) == [], check(d, 13)
        assert len(check(pathlib.Path(d, "x", "test"), 8)) == 1  # the root itself may be named test
    print("function_length self-test: ok")
    return 0


def main(argv):
    if argv[1:] == ["--self-test"]:
        return self_test()
    limit = DEFAULT_LIMIT
    if len(argv) == 4 and argv[1] == "--limit":
        limit, argv = int(argv[2]), [argv[0], argv[3]]
    if len(argv) != 2:
        print(__doc__, file=sys.stderr)
        return 2
    problems = check(argv[1], limit)
    for p in problems:
        print(p)
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
