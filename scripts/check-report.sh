#!/usr/bin/env bash
# Opens a dynid report in headless Chromium (Debian's `chromium`, installed by scripts/setup.sh), checks that
# every embedded figure decoded (the page sets data-images-loaded on load; compared with data-images) and saves
# a screenshot of the page (default: REPORT-screenshot.png). Exit code 0 when the page rendered whole.
#   scripts/check-report.sh REPORT.html [SCREENSHOT.png]
set -euo pipefail
if (($# < 1)); then
  echo "usage: scripts/check-report.sh REPORT.html [SCREENSHOT.png]" >&2
  exit 2
fi
report=$(realpath "$1")
shot=${2:-${report%.html}-screenshot.png}
[ -f "$report" ] || { echo "check-report: $1: no such file" >&2; exit 2; }
browser=$(command -v chromium || command -v chromium-browser || command -v google-chrome || true)
if [ -z "$browser" ]; then
  echo "check-report: no Chromium found; scripts/setup.sh installs Debian's chromium package" >&2
  exit 2
fi
# --no-sandbox: CI runs as root, where Chromium's sandbox refuses to start.
flags=(--headless --no-sandbox --disable-gpu --hide-scrollbars --disable-dev-shm-usage --no-first-run)
profile=$(mktemp -d)
trap 'rm -rf "$profile"' EXIT
flags+=(--user-data-dir="$profile")
dom=$(timeout 120 "$browser" "${flags[@]}" --virtual-time-budget=10000 --dump-dom "file://$report" 2>/dev/null)
want=$(grep -o 'data-images="[0-9]*"' <<<"$dom" | head -1 | grep -o '[0-9][0-9]*' || true)
got=$(grep -o 'data-images-loaded="[0-9]*"' <<<"$dom" | head -1 | grep -o '[0-9][0-9]*' || true)
if [ -z "$want" ] || [ "$want" = 0 ] || [ "$got" != "$want" ]; then
  echo "check-report: $report: ${got:-no} of ${want:-?} figures decoded in the browser" >&2
  exit 1
fi
timeout 120 "$browser" "${flags[@]}" --window-size=1400,3000 --screenshot="$shot" "file://$report" >/dev/null 2>&1
# A PNG of the requested size (signature, then IHDR width and height, big-endian), not a near-empty page.
sig=$(head -c 8 "$shot" | od -An -tx1 | tr -d ' \n')
width=$((16#$(od -An -tx1 -j16 -N4 "$shot" | tr -d ' \n')))
height=$((16#$(od -An -tx1 -j20 -N4 "$shot" | tr -d ' \n')))
bytes=$(stat -c %s "$shot")
if [ "$sig" != 89504e470d0a1a0a ] || [ "$width" != 1400 ] || [ "$height" != 3000 ] || ((bytes < 100000)); then
  echo "check-report: $shot: not the expected screenshot (signature $sig, ${width}x${height}, $bytes bytes)" >&2
  exit 1
fi
echo "check-report: $report: $got of $want figures decoded; screenshot $shot (${width}x${height}, $bytes bytes)"
