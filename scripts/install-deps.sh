#!/usr/bin/env bash
# Installs the Debian packages needed to build, test and benchmark kinetic, and to draw its plots.
# Usage: scripts/install-deps.sh [fuzz]
# Only packages that are missing are installed; when nothing is missing, nothing is done (no
# `apt-get update`, no sudo). Safe to run any number of times.
set -euo pipefail

packages=(
  build-essential
  cmake
  pkg-config
  libgmp-dev
  nlohmann-json3-dev
  libcli11-dev
  libgtest-dev
  libgmock-dev
  librapidcheck-dev
  libbenchmark-dev
  python3
  python3-matplotlib
  # The Python module (docs/python.md): built by `pip install .` in a venv of Debian's python3,
  # tested with pytest.
  python3-dev
  python3-numpy
  python3-pip
  python3-pytest
  python3-venv
  pybind11-dev
  # Sweeps of many runs on Dask distributed (kinetic.sweep, docs/scale-out.md).
  python3-distributed
  # The replay viewer's browser tests (tests/viewer): Debian's chromium, driven from Node.js.
  chromium
  # Benchmark-only: the anchors bench/bench_crop.cpp compares CROP with (FLINT/Arb and CGAL).
  # The library needs GMP alone; without these, bench_crop still builds and skips the anchors.
  libflint-dev
  libflint-arb-dev
  libcgal-dev
  # Benchmark-only: the static peers bench/bench_kdtree.cpp compares the kinetic kd-tree with
  # (nanoflann, CGAL's Kd_tree above, Boost.Geometry's rtree); without them it skips those peers.
  libnanoflann-dev
  libboost-dev
  # Benchmark-only: qhull, a static peer of bench/bench_hull.cpp beside CGAL's convex_hull_2.
  libqhull-dev
  # Benchmark-only: the per-frame broad phases bench/bench_collision.cpp compares the kinetic
  # BVH and sweep-and-prune with (FCL's dynamic AABB tree, Bullet's btDbvtBroadphase, Box2D's
  # dynamic tree); without them it skips those peers.
  libfcl-dev
  libbullet-dev
  libbox2d-dev
)

# Node.js and npm for the viewer's tests, unless the machine has them already (from Debian or
# another source, e.g. NodeSource's nodejs, which brings its own npm).
if ! command -v node >/dev/null 2>&1; then packages+=(nodejs); fi
if ! command -v npm >/dev/null 2>&1; then packages+=(npm); fi

# `install-deps.sh fuzz` adds clang and its libFuzzer runtime for scripts/fuzz.sh (the test suite
# runs the fuzz harnesses on their corpora with the default compiler and does not need them).
if [[ "${1:-}" == "fuzz" ]]; then
  packages+=(clang-14 libclang-rt-14-dev)
fi

is_installed() {
  local status
  status="$(dpkg-query -W -f='${db:Status-Status}' "$1" 2>/dev/null || true)"
  [[ "${status}" == "installed" ]]
}

if ! command -v dpkg-query >/dev/null 2>&1; then
  echo "install-deps: dpkg-query not found; this script supports Debian/Ubuntu only." >&2
  echo "install-deps: please install the equivalents of: ${packages[*]}" >&2
  exit 1
fi

missing=()
for package in "${packages[@]}"; do
  if ! is_installed "${package}"; then
    missing+=("${package}")
  fi
done

if ((${#missing[@]} == 0)); then
  echo "install-deps: all ${#packages[@]} required packages are already installed; nothing to do."
  exit 0
fi

echo "install-deps: installing missing packages: ${missing[*]}"

sudo_cmd=()
if ((EUID != 0)); then
  if ! command -v sudo >/dev/null 2>&1; then
    echo "install-deps: not running as root and sudo is not available." >&2
    echo "install-deps: run as root: apt-get update && apt-get install -y ${missing[*]}" >&2
    exit 1
  fi
  sudo_cmd=(sudo)
fi

"${sudo_cmd[@]}" env DEBIAN_FRONTEND=noninteractive apt-get update
"${sudo_cmd[@]}" env DEBIAN_FRONTEND=noninteractive \
  apt-get install -y --no-install-recommends "${missing[@]}"

# Check that everything is really there now (a renamed or unavailable package fails loudly).
still_missing=()
for package in "${missing[@]}"; do
  if ! is_installed "${package}"; then
    still_missing+=("${package}")
  fi
done
if ((${#still_missing[@]} != 0)); then
  echo "install-deps: failed to install: ${still_missing[*]}" >&2
  exit 1
fi
echo "install-deps: done."
