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
# THE MAIN JOB. This is the one place to change what `./scripts/main.sh` runs.
main_job() {
  # The seed paper's kinetic-sorting experiment (Section 6): robust kinetic sorting at
  # eps = 1e-6, 1e-7, 1e-8 beside the classic scheduler on GRIDS, PARABOLA and RANDDC (n = 900).
  # Prints Table 1 beside the paper's values, the theorem checks and the classic failures;
  # writes CSV files and the plots of Figures 6-8 to build/release/experiment-sorting/. Its 15
  # runs go one per core (--workers): the same results as one after the other.
  "${kinetic}" experiment sorting --quick --workers "$(nproc)" --out "${build_dir}/experiment-sorting"
}
# ================================================================================================

main_job
