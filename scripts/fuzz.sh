#!/usr/bin/env bash
# Builds the libFuzzer targets (clang-14, ASan + UBSan, build-fuzz/) and runs each for a fixed
# time. Fails on any finding (crash, sanitizer report, failed result check, leak, timeout).
#   scripts/fuzz.sh [SECONDS_PER_TARGET] [TARGET...]     default 45 s, all four targets
# New inputs go to build-fuzz/corpus/<target> (the committed seeds in tests/fuzz/corpus are read
# only); a finding is written to build-fuzz/artifacts/<target>/ and can be replayed with
#   build-fuzz/tests/fuzz/<target> build-fuzz/artifacts/<target>/crash-...
# Longer runs: e.g. scripts/fuzz.sh 3600 fuzz_query, or run the binary with -jobs=N.
set -euo pipefail
cd "$(dirname "$0")/.."
secs="${1:-45}"
shift || true
targets=("$@")
[ ${#targets[@]} -eq 0 ] && targets=(fuzz_query fuzz_cdf fuzz_cases fuzz_mesh)
CC="${FUZZ_CC:-clang-14}"
cmake -S . -B build-fuzz -DCMAKE_C_COMPILER="$CC" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DSDFCCD_FUZZ=ON \
  -DSDFCCD_BUILD_TESTS=OFF -DSDFCCD_BUILD_SAMPLES=OFF -DSDFCCD_BUILD_BULLET_BRIDGE=OFF >/dev/null
cmake --build build-fuzz -j2 >/dev/null
export ASAN_OPTIONS="detect_leaks=1:allocator_may_return_null=1"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
export LSAN_OPTIONS="suppressions=$PWD/tests/fuzz/lsan.supp"
for t in "${targets[@]}"; do
  mkdir -p "build-fuzz/corpus/$t" "build-fuzz/artifacts/$t"
  echo "== $t: ${secs} s"
  # -timeout: one input (two identical queries) over 20 s is a finding; -rss_limit_mb: 2 GB.
  # -report_slow_units: inputs slower than 2 s are saved as slow-unit-* (timing only, not a failure).
  ./build-fuzz/tests/fuzz/"$t" -max_total_time="$secs" -timeout=20 -rss_limit_mb=2048 -print_final_stats=1 -report_slow_units=2 \
    -artifact_prefix="build-fuzz/artifacts/$t/" "build-fuzz/corpus/$t" "tests/fuzz/corpus/$t" 2>"build-fuzz/$t.log" \
    || { tail -60 "build-fuzz/$t.log"; echo "fuzz: $t reported a finding (build-fuzz/artifacts/$t/)"; exit 1; }
  grep -E "stat::number_of_executed_units|sdfccd-fuzz:" "build-fuzz/$t.log" || true
done
