#!/usr/bin/env bash
# Runs dynid on every bundled case (cases/**/*.yaml, found below, so new case folders need no entry here; this
# includes the mesh-file cases paper-frame-gmsh and paper-frame-abaqus, whose models come from frame.msh and
# frame.inp): `detect` for cases with a detect: section, `simulate-test` then `identify` for cases with a test:
# section (cases/virtual-tests), `discover` for cases with a discover: section (cases/discovery: exit code 4 if the
# expected effect is not found), `modal` otherwise. Results (JSON, and plots for
# detect) go to out/ (override with DYNID_OUT). This is the "main job" of the README's first command; each case
# folder's README says what the case shows.
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
dynid=${DYNID_BIN:-$here/build/cli/dynid}
out=${DYNID_OUT:-$here/out}
mkdir -p "$out"
status=0
while IFS= read -r file; do
  rel=${file#"$here/cases/"}
  name=$(echo "${rel%.yaml}" | tr '/' '-')
  name=${name%-case}
  if grep -q '^test:' "$file"; then
    echo "== simulate-test + identify $rel"
    band=$(sed -n 's/.*identify:.*band_hz: *\[\([0-9.]*\), *\([0-9.]*\)\].*/\1 \2/p' "$file")
    "$dynid" simulate-test "$file" -o "$out/$name.uff" --force &&
      "$dynid" identify $(ls "$out/$name"*.uff | grep -v -- '-modes.uff') ${band:+--band $band} --out "$out/$name" --force ||
      { echo "!! $rel failed" >&2; status=1; }
  elif grep -q '^discover:' "$file"; then
    echo "== discover $rel"
    "$dynid" discover "$file" --json "$out/$name.discover.json" --plot "$out/$name.discover.png" --force --quiet ||
      { echo "!! $rel failed" >&2; status=1; }
  elif grep -q '^detect:' "$file"; then
    echo "== detect $rel"
    "$dynid" detect "$file" --json "$out/$name.detect.json" --force || { echo "!! $rel failed" >&2; status=1; }
  else
    echo "== modal $rel"
    "$dynid" modal "$file" --json "$out/$name.modal.json" --force || { echo "!! $rel failed" >&2; status=1; }
  fi
done < <(find "$here/cases" -name '*.yaml' | sort)
echo "results in $out"
exit $status
