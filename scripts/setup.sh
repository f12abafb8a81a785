#!/usr/bin/env bash
# dynid set-up: installs the Debian 12 packages dynid needs (only those missing), then configures and builds
# a Release tree in ./build (override with DYNID_BUILD_DIR). Safe to run again: it skips what is already done.
#   scripts/setup.sh            install + configure + build
#   scripts/setup.sh --deps     install packages only
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
build=${DYNID_BUILD_DIR:-$here/build}

packages=(
  build-essential cmake git pkg-config
  libeigen3-dev libsuitesparse-dev libmetis-dev libspectra-dev libceres-dev libgoogle-glog-dev libgflags-dev
  libopenblas-dev liblapack-dev libgtest-dev libgmock-dev libbenchmark-dev
  nlohmann-json3-dev libyaml-cpp-dev libcli11-dev libfmt-dev libfftw3-dev
  libplplot-dev plplot-driver-cairo
  chromium  # scripts/check-report.sh: the report checked in a headless browser (ctest report.browser)
  clang libclang-rt-14-dev libomp-dev  # scripts/sanitize.sh, fuzz.sh: clang, libFuzzer, sanitizer run-times, OpenMP
  clang-format clang-tidy  # scripts/lint.sh (ctest lint.changed): the changed lines formatted and linted
  python3 python3-numpy python3-scipy python3-slepc4py python3-petsc4py
  python3-matplotlib  # bench/discovery: the concealed-physics benchmark's figures
  python3-dev pybind11-dev python3-pytest python3-h5py  # the Python package (python/, docs/python.md) and its tests
  libmatio-dev zlib1g-dev  # .mat files (v5 and v7.3); the report's compressed plotly.js
  libjs-three python3-plotly  # the report's 3D mode shapes (three.js) and zoomable plots (plotly.js), embedded
  libpetsc-real-dev libslepc-real-dev libopenmpi-dev openmpi-bin  # the distributed backend (docs/distributed.md)
)

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
  echo "dynid setup: installing ${#missing[@]} Debian packages: ${missing[*]}"
  SUDO=""
  if [ "$(id -u)" != 0 ]; then
    command -v sudo >/dev/null || { echo "dynid setup: need root or sudo to install: ${missing[*]}" >&2; exit 1; }
    SUDO=sudo
  fi
  $SUDO env DEBIAN_FRONTEND=noninteractive apt-get update -qq
  $SUDO env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi
# Debian's default BLAS is the slow reference one; CHOLMOD's supernodal factorization needs an optimized BLAS.
blas=$(readlink -f /usr/lib/x86_64-linux-gnu/libblas.so.3 2>/dev/null || true)
case "$blas" in
  *openblas*) ;;
  *) echo "dynid setup: warning: libblas.so.3 resolves to '$blas', not OpenBLAS; CHOLMOD will be slow." \
          "Select it with: update-alternatives --config libblas.so.3-x86_64-linux-gnu" >&2 ;;
esac

[ "${1:-}" = "--deps" ] && exit 0

jobs=$(nproc 2>/dev/null || echo 2)
cmake -S "$here" -B "$build" -DCMAKE_BUILD_TYPE=Release ${DYNID_CMAKE_ARGS:-} >/dev/null
cmake --build "$build" -j "$jobs"
# The Python package into Debian's python3 (/usr/local/lib/python3.X/dist-packages/dynid): `import dynid` works
# without PYTHONPATH (docs/python.md). Skipped without root or sudo; PYTHONPATH=build/python works then.
if [ "$(id -u)" = 0 ]; then
  cmake --install "$build" --component python >/dev/null
elif command -v sudo >/dev/null && sudo -n true 2>/dev/null; then
  sudo cmake --install "$build" --component python >/dev/null
else
  echo "dynid setup: the Python package stays in $build/python (no root): use PYTHONPATH=$build/python" >&2
fi
