#!/usr/bin/env bash
# ThreadSanitizer run of the threading tests (test_threads, test_hardening's destroy-while-
# querying race, and test_destroy's race over every entry point that takes a handle): a separate
# build in build-tsan/ with -fsanitize=thread. Fails on any report.
#   scripts/tsan.sh
set -euo pipefail
cd "$(dirname "$0")/.."
cmake -S . -B build-tsan -DCMAKE_BUILD_TYPE=RelWithDebInfo -DSDFCCD_BUILD_SAMPLES=OFF -DSDFCCD_BUILD_BULLET_BRIDGE=OFF \
  -DCMAKE_C_FLAGS="-fsanitize=thread -fno-omit-frame-pointer" -DCMAKE_EXE_LINKER_FLAGS="-fsanitize=thread" >/dev/null
cmake --build build-tsan -j2 --target test_threads test_hardening test_destroy >/dev/null
for t in test_threads test_hardening test_destroy; do
  echo "== TSan: $t"
  TSAN_OPTIONS="halt_on_error=1" CK_FORK=no ./build-tsan/tests/$t
done
