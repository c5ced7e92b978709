#!/usr/bin/env bash
# Runs one fuzz harness with libFuzzer for SECONDS seconds (docs/reliability.md):
#   scripts/fuzz.sh NAME SECONDS [extra libFuzzer flags]
# NAME: scenario_reader, crop, structures or delaunay (fuzz/fuzz_NAME.cpp). Builds kinetic with clang,
# libFuzzer, AddressSanitizer and UndefinedBehaviorSanitizer in build/fuzz (once; incremental
# after), then fuzzes from the seed corpus fuzz/corpus/NAME into build/fuzz/corpus/NAME (new
# inputs stay there; the seed corpus is not modified). Prints libFuzzer's final statistics;
# exits non-zero when an input violates a property (the input is saved as build/fuzz/crash-*).
# Installs missing Debian packages first (see scripts/install-deps.sh).
set -euo pipefail

if (($# < 2)); then
  echo "usage: scripts/fuzz.sh NAME SECONDS [libFuzzer flags]   (NAME: scenario_reader, crop, structures, delaunay)" >&2
  exit 2
fi
name="$1"
seconds="$2"
shift 2

repo_root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "${repo_root}"
if [[ ! -f "fuzz/fuzz_${name}.cpp" ]]; then
  echo "fuzz.sh: no harness fuzz/fuzz_${name}.cpp (scenario_reader, crop, structures, delaunay)" >&2
  exit 2
fi

bash scripts/install-deps.sh fuzz
build_dir="build/fuzz"
flags="-fsanitize=fuzzer-no-link,address,undefined -fno-sanitize-recover=all -fno-omit-frame-pointer"
cmake -S . -B "${build_dir}" \
  -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DCMAKE_CXX_COMPILER=clang++-14 \
  "-DCMAKE_CXX_FLAGS=${flags}" \
  "-DCMAKE_EXE_LINKER_FLAGS=-fsanitize=address,undefined" \
  -DKINETIC_FUZZ=ON -DKINETIC_BUILD_TESTS=OFF -DKINETIC_BUILD_BENCHMARKS=OFF \
  -DKINETIC_BUILD_TOOLS=OFF -DKINETIC_WARNINGS_AS_ERRORS=OFF >/dev/null
cmake --build "${build_dir}" -j"$(nproc)" --target "fuzz_${name}"

corpus="${build_dir}/corpus/${name}"
mkdir -p "${corpus}"
export ASAN_OPTIONS="detect_leaks=1:abort_on_error=1"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
cd "${build_dir}"
exec "./fuzz/fuzz_${name}" -max_total_time="${seconds}" -timeout=20 -rss_limit_mb=4096 \
  -print_final_stats=1 "$@" "corpus/${name}" "${repo_root}/fuzz/corpus/${name}"
