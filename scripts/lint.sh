#!/usr/bin/env bash
# Style and lint gate on what a change touches (not the whole tree): the C++ lines added or changed since BASE
# must be formatted as .clang-format says (120 columns; clang-format-diff) and pass the clang-tidy checks of
# .clang-tidy (clang-tidy-diff, with the compile commands of the build tree). Run by ctest (lint.changed) and so
# by .ci/run.
#   scripts/lint.sh [BASE]     BASE: a git revision (default: DYNID_LINT_BASE, else the merge-base with main,
#                              or HEAD~1 on main itself); uncommitted changes count too
#   scripts/lint.sh --fix      reformat the changed lines in place (clang-format only)
# Environment: DYNID_BUILD_DIR (default build/) for compile_commands.json. Exit 0 clean, 1 findings, 2 set-up.
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
cd "$here"
build=${DYNID_BUILD_DIR:-$here/build}
fix=0
if [ "${1:-}" = "--fix" ]; then fix=1; shift; fi
base=${1:-${DYNID_LINT_BASE:-}}
if [ -z "$base" ]; then  # a branch: all it adds to main; main itself: its last commit (and what is uncommitted)
  if [ "$(git rev-parse --abbrev-ref HEAD)" != main ]; then base=$(git merge-base HEAD main 2>/dev/null || true); fi
  [ -n "$base" ] || base=$(git rev-parse -q --verify HEAD~1 || git rev-parse HEAD)
fi
for tool in clang-format-diff clang-tidy-diff clang-tidy; do
  command -v "$tool" >/dev/null || { echo "lint: $tool not found (Debian packages clang-format, clang-tidy: scripts/setup.sh)" >&2; exit 2; }
done
# C++ sources of the project (not third-party, not generated), as they differ from BASE in the working tree.
paths=(mesh solvers engine io cli tests bench fuzz python/src examples)
changed() { git diff -U0 --no-color --diff-filter=AMR "$base" -- "${paths[@]/%//*.cpp}" "${paths[@]/%//*.hpp}" "$@"; }
if [ -z "$(changed --name-only)" ]; then
  echo "lint: no C++ change since $(git rev-parse --short "$base")"
  exit 0
fi
status=0
if [ "$fix" = 1 ]; then
  changed | clang-format-diff -p1 -i
  exit 0
fi
format=$(changed | clang-format-diff -p1 || true)
if [ -n "$format" ]; then
  echo "$format"
  echo "lint: the changed lines above are not formatted as .clang-format says; scripts/lint.sh --fix reformats them" >&2
  status=1
fi
# clang-tidy on the changed lines of the compiled files (the libraries, the command line, the examples).
[ -f "$build/compile_commands.json" ] || { echo "lint: no $build/compile_commands.json (configure first)" >&2; exit 2; }
tidy=$(git diff -U0 --no-color --diff-filter=AMR "$base" -- mesh/'*.cpp' solvers/'*.cpp' engine/'*.cpp' io/'*.cpp' cli/'*.cpp' examples/'*.cpp' |
       clang-tidy-diff -p1 -path "$build" -quiet -j 2 2>&1 || true)
if echo "$tidy" | grep -q "error:\|warning:"; then
  echo "$tidy" | grep -v "^[0-9]* warnings\? generated\|^Suppressed\|^Use -header-filter\|^Running clang-tidy" >&2
  echo "lint: clang-tidy findings on the changed lines (checks: .clang-tidy)" >&2
  status=1
fi
[ "$status" = 0 ] && echo "lint: the changed lines since $(git rev-parse --short "$base") are formatted and pass clang-tidy"
exit $status
