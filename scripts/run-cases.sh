#!/usr/bin/env bash
# Runs dynid on every bundled case (cases/**/*.yaml, found below, so new case folders need no entry here; this
# includes the mesh-file cases paper-frame-gmsh and paper-frame-abaqus, whose models come from frame.msh and
# frame.inp, and paper-frame-matrices, whose model comes from exported K/M and element matrices).
# Each case goes through `dynid run CASE --report`: modal analysis (mode shapes drawn on the structure), then the
# sections the case has: detect, update, discover (cases/discovery: exit code 4 if the expected effect is not
# found), and for a test: section simulate-test + identify (cases/virtual-tests). Results go to out/<case>/ (JSON,
# PNG figures, run.json, report.html); out/index.html links every report. Override the folder with DYNID_OUT.
# This is the "main job" of the README's first command; each case folder's README says what the case shows.
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
dynid=${DYNID_BIN:-$here/build/cli/dynid}
out=${DYNID_OUT:-$here/out}
mkdir -p "$out"
status=0
rows=""
while IFS= read -r file; do
  rel=${file#"$here/cases/"}
  # Files included by other cases (a model: section only, no name:) are not cases themselves.
  grep -q '^name:' "$file" || continue
  name=$(echo "${rel%.yaml}" | tr '/' '-')
  name=${name%-case}
  # Cases that read the shared real data (../shared beside the repository) need it there.
  if grep -q '\.\./\.\./\.\./shared/' "$file" && [ ! -d "$here/../shared/data" ]; then
    echo "-- $rel skipped: it reads ../shared/data beside the repository, which is not there"
    continue
  fi
  echo "== $rel"
  rc=0
  "$dynid" run "$file" --out "$out/$name" --report --force --quiet || rc=$?
  if [ "$rc" != 0 ]; then
    echo "!! $rel failed (exit code $rc; see $out/$name/report.html)" >&2
    status=1
  fi
  mark=$([ "$rc" = 0 ] && echo ok || echo "exit code $rc")
  rows+="<tr><td><a href=\"$name/report.html\">$name</a></td><td>$rel</td><td>$mark</td></tr>"$'\n'
done < <(find "$here/cases" -name '*.yaml' | sort)
{
  echo '<!DOCTYPE html><html lang="en"><head><meta charset="utf-8"><title>dynid: bundled cases</title>'
  echo '<style>body{font-family:sans-serif;margin:1em 2em}td,th{border:1px solid #bbb;padding:2px 8px}table{border-collapse:collapse}</style>'
  echo '</head><body><h1>dynid: reports of the bundled cases</h1><table><tr><th>report</th><th>case file</th><th>result</th></tr>'
  printf '%s' "$rows"
  echo '</table></body></html>'
} >"$out/index.html"
echo "results in $out; open $out/index.html"
exit $status
