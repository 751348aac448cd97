#!/usr/bin/env python3
"""Regenerates the parts of docs/ that come from the code, or checks that they match it.

    python3 tools/docs.py [--dyad build/bin/dyad]          rewrite them
    python3 tools/docs.py --check [--dyad build/bin/dyad]  exit 1 with a diff if they drifted (CTest)

- docs/components.md: each block between
      <!-- BEGIN dyad types --markdown NAME ... -->  and  <!-- END dyad types --markdown NAME -->
  is replaced by `dyad types --markdown NAME` (from the type's Describe()). Every built-in
  component type must have exactly one such block.
- docs/messages.md: the whole file is `dyad types --messages --markdown` (from idl/).
Only the built-in plugins are read (DYAD_PLUGIN_PATH is ignored).
"""
import argparse
import difflib
import os
import re
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
BLOCK = re.compile(r"<!-- BEGIN dyad types --markdown (\S+)[^\n]*-->\n.*?<!-- END dyad types --markdown \1 -->\n",
                   re.S)


def dyad(binary, *args):
    env = {k: v for k, v in os.environ.items() if k != "DYAD_PLUGIN_PATH"}
    return subprocess.run([binary, *args], check=True, capture_output=True, text=True, env=env).stdout


def components_md(binary, text, problems):
    generated = {m.group(1): m.group(0) for m in BLOCK.finditer(dyad(binary, "types", "--markdown"))}
    seen = []

    def replace(m):
        name = m.group(1)
        seen.append(name)
        if name not in generated:
            problems.append(f"docs/components.md: a block for '{name}', which is not a built-in component type")
            return m.group(0)
        return generated[name]

    text = BLOCK.sub(replace, text)
    for name in sorted(generated):
        if seen.count(name) != 1:
            problems.append(f"docs/components.md: component type '{name}' needs exactly one generated block "
                            f"(found {seen.count(name)}): add '<!-- BEGIN dyad types --markdown {name} -->' and "
                            f"'<!-- END dyad types --markdown {name} -->' to its section")
    return text


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--dyad", default=os.path.join(ROOT, "build", "bin", "dyad"))
    parser.add_argument("--check", action="store_true")
    args = parser.parse_args()
    problems = []
    files = {
        "docs/components.md": lambda old: components_md(args.dyad, old, problems),
        "docs/messages.md": lambda old: dyad(args.dyad, "types", "--messages", "--markdown"),
    }
    drifted = []
    for rel, make in files.items():
        path = os.path.join(ROOT, rel)
        old = open(path).read() if os.path.exists(path) else ""
        new = make(old)
        if new == old:
            continue
        drifted.append(rel)
        if args.check:
            sys.stdout.writelines(difflib.unified_diff(old.splitlines(True), new.splitlines(True), rel, rel + " (generated)"))
        else:
            with open(path, "w") as f:
                f.write(new)
            print(f"docs: rewrote {rel}")
    for p in problems:
        print(p, file=sys.stderr)
    if args.check and drifted:
        print(f"docs: {', '.join(drifted)} differ from the code: run python3 tools/docs.py", file=sys.stderr)
    return 1 if problems or (args.check and drifted) else 0


if __name__ == "__main__":
    sys.exit(main())
