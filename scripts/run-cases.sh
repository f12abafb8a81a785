#!/usr/bin/env bash
# Runs dynid on every bundled case (cases/*/), writing results under out/ (override with DYNID_OUT).
# Each case folder's README says what it shows; this is the "main job" of the README's first command.
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
dynid=${DYNID_BIN:-$here/build/cli/dynid}
out=${DYNID_OUT:-$here/out}
mkdir -p "$out"
status=0
for dir in "$here"/cases/*/; do
  name=$(basename "$dir")
  [ -f "$dir/case.yaml" ] || [ -f "$dir/case.json" ] || continue
  echo "== $name"
  if ! "$dynid" modal "$dir" --json "$out/$name.modal.json" --force; then
    echo "!! $name failed" >&2
    status=1
  fi
done
echo "results in $out"
exit $status
