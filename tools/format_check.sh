#!/usr/bin/env bash
# The C++ lines a change touched follow .clang-format (clang-format 14; .ci/run runs this first).
#
#   bash tools/format_check.sh          the lines changed by the last commit (HEAD~1..HEAD) and
#                                       by the work tree's uncommitted edits
#   bash tools/format_check.sh BASE     the lines changed since BASE (e.g. origin/main, or the
#                                       commit a branch started from): what a reviewer would read
#   DYAD_FORMAT_BASE=BASE               the same, for CI
#
# Only changed lines are checked (git clang-format), never whole files: the code written before
# .clang-format was adopted is not reformatted wholesale, and the check costs a second or two.
# Why the last commit by default: CI runs in a clean clone, where the branch's start (a merge-base
# with what landed before) is not known; the last commit is the one base every clone has. A
# series of commits is checked by giving its base. A clone without HEAD~1 (a shallow clone of
# depth 1, or the first commit) has nothing to compare against: the check says so and passes.
#
# Exit 0: the changed lines are formatted (or there is no base). Exit 1: they are not; the diff
# clang-format wants is printed (apply it: git clang-format-14 BASE). Exit 2: a bad argument or
# a missing tool.
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
cd "$here"
base=${1:-${DYAD_FORMAT_BASE:-}}
tool=git-clang-format-14
command -v "$tool" > /dev/null || bash tools/setup.sh
command -v "$tool" > /dev/null || { echo "format_check: $tool not found (Debian package clang-format-14)" >&2; exit 2; }
if [ -z "$base" ]; then
  if ! git rev-parse -q --verify HEAD~1 > /dev/null; then
    echo "format_check: no HEAD~1 in this clone (shallow or first commit): nothing to compare, skipped"
    exit 0
  fi
  base=HEAD~1
fi
git rev-parse -q --verify "$base^{commit}" > /dev/null || { echo "format_check: '$base' is not a commit" >&2; exit 2; }

# git clang-format compares the work tree with BASE: the last commit's lines and any uncommitted edit.
out=$("$tool" --binary clang-format-14 --extensions cpp,hpp,h,cc --diff "$base" -- 2>&1) || status=$?
case "$out" in
  "no modified files to format"* | "clang-format did not modify any files"*)
    echo "format_check: the C++ lines changed since $(git rev-parse --short "$base") follow .clang-format"
    exit 0 ;;
esac
if [ "${status:-1}" -gt 1 ] || ! grep -q '^diff ' <<< "$out"; then
  echo "format_check: $tool failed:" >&2
  echo "$out" >&2
  exit 2
fi
echo "$out"
echo "format_check: lines changed since $(git rev-parse --short "$base") do not follow .clang-format (the diff above);" \
  "apply it with: git clang-format-14 $base" >&2
exit 1
