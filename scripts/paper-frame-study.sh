#!/usr/bin/env bash
# Regenerates the noise-study table of cases/paper-frame-damage/README.md (200 seeded trials per level and case).
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
dynid=${DYNID_BIN:-$here/build/cli/dynid}
echo "| element | case | shape noise | paper pseudo residual: 1st | top 3 | dynid: 1st | top 3 | in 95 % set | mean set size | mirror twin ranked 1st | twin called |"
echo "|---|---|---|---|---|---|---|---|---|---|---|"
for e in 9 28; do
  for c in 1 2 3; do
    "$dynid" -q detect "$here/cases/paper-frame-damage/element$e-case$c.yaml" --study | grep -E '^\| [0-9]+ %' | sed "s/^/| $e | $c /"
  done
done
