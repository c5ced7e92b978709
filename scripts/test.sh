#!/usr/bin/env bash
# Builds kinetic's test configuration in build/test -- Debug with -O1 and line tables (-g1: the
# sanitizers' reports name files and lines, at three quarters of -g's compile time),
# AddressSanitizer and UndefinedBehaviorSanitizer, tests and benchmarks (benchmarks are compiled
# without their peers and only their harness is run: the peers are compiled by the Release
# build) -- and runs the whole test suite with CTest; then builds the Python module (pip install .
# into a venv, scripts/test-python.sh) and runs its pytest suite. Exits non-zero when either fails.
# Installs missing Debian packages first (see scripts/install-deps.sh). Safe to re-run.
set -euo pipefail

repo_root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "${repo_root}"

build_dir="build/test"
jobs="$(nproc)"

# Also in effect while building: gtest_discover_tests runs the sanitized test binary at build time.
export ASAN_OPTIONS="detect_leaks=1:abort_on_error=1"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"

bash scripts/install-deps.sh

cmake -S . -B "${build_dir}" \
  -DCMAKE_BUILD_TYPE=Debug \
  "-DCMAKE_CXX_FLAGS_DEBUG=-O1 -g1" \
  -DKINETIC_SANITIZE=ON \
  -DKINETIC_BUILD_TOOLS=ON \
  -DKINETIC_BUILD_TESTS=ON \
  -DKINETIC_BUILD_BENCHMARKS=ON \
  -DKINETIC_BENCH_PEERS=OFF
cmake --build "${build_dir}" -j"${jobs}"

# The viewer's browser tests drive Debian's chromium with puppeteer-core from the npm registry
# (tests/viewer/package-lock.json pins it); installed again only when the lock changed.
if [[ ! -f tests/viewer/node_modules/.package-lock.json ||
      tests/viewer/package-lock.json -nt tests/viewer/node_modules/.package-lock.json ]]; then
  npm ci --prefix tests/viewer --no-audit --no-fund
fi

status=0
ctest --test-dir "${build_dir}" --output-on-failure -j"${jobs}" || status=$?

# The Python module: built with `pip install .` (Release, its own build directory) and tested
# with pytest (scripts/test-python.sh).
python_status=0
bash scripts/test-python.sh || python_status=$?
if ((python_status != 0)); then
  echo "test: the Python tests failed (status ${python_status})" >&2
  status=1
fi
exit "${status}"
