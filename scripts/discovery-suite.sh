#!/usr/bin/env bash
# Runs the concealed-data discovery suite (cases/discovery) and regenerates the results table in
# cases/discovery/README.md. Usage: scripts/discovery-suite.sh [SEEDS]   (SEEDS > 1: robustness over noise seeds)
# Expects a built tree in build/ (scripts/setup.sh builds one). Results: build/discovery/<case>.json and .png.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
seeds="${1:-1}"
dynid="${DYNID:-$root/build/cli/dynid}"
out="${DYNID_SUITE_OUT:-$root/build/discovery}"
[ -x "$dynid" ] || { echo "discovery-suite: $dynid not found; run scripts/setup.sh first" >&2; exit 2; }
mkdir -p "$out"
status=0
for dir in "$root"/cases/discovery/*/; do
  [ -f "$dir/case.yaml" ] || continue
  name="$(basename "$dir")"
  if ! "$dynid" discover "$dir" --seeds "$seeds" --json "$out/$name.json" --plot "$out/$name.png" --force --quiet; then
    echo "discovery-suite: $name failed" >&2
    status=1
  fi
done
python3 "$root/scripts/discovery_table.py" "$out" "$root/cases/discovery/README.md" "$seeds"
exit $status
