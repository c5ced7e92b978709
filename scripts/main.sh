#!/usr/bin/env bash
# Builds kinetic in Release (build/release) and runs the main job.
# Installs missing Debian packages first (see scripts/install-deps.sh). Safe to re-run: the
# configure and build steps are incremental and the main job overwrites its own outputs.
set -euo pipefail

repo_root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "${repo_root}"

build_dir="build/release"
jobs="$(nproc)"

bash scripts/install-deps.sh

cmake -S . -B "${build_dir}" \
  -DCMAKE_BUILD_TYPE=Release \
  -DKINETIC_BUILD_TOOLS=ON \
  -DKINETIC_BUILD_TESTS=OFF \
  -DKINETIC_BUILD_BENCHMARKS=OFF
cmake --build "${build_dir}" -j"${jobs}"

kinetic="${build_dir}/kinetic"

# ================================================================================================
# THE MAIN JOB. This is the one place to change what `./scripts/main.sh` runs (e.g. to
# `"${kinetic}" experiment sorting --quick` once experiments exist).
main_job() {
  # The paper's PARABOLA input (900 congruent parabolas, many simultaneous crossings), sorted
  # kinetically with the robust scheduler (the default) and with the classic baseline.
  "${kinetic}" generate parabola --n 900 --queries 5 --query-type max --out "${build_dir}/demo.json"
  echo "== robust scheduling (eps 1e-9): answers, then statistics"
  "${kinetic}" run "${build_dir}/demo.json" --structure sort --stats -
  echo "== classic scheduling: answers, then statistics"
  "${kinetic}" run "${build_dir}/demo.json" --structure sort --scheduler classic --stats -
}
# ================================================================================================

main_job
