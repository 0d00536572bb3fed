#!/usr/bin/env bash
# valgrind memcheck over the unit-test binaries (not the slow ones): no invalid access, no use of
# uninitialised values, no leak of any kind (definite, indirect, possible or still reachable;
# scripts/valgrind.supp: only what shared libraries keep from their static initialisers).
#   scripts/valgrind.sh [BUILD_DIR]      default build/ (configured and built if needed)
set -euo pipefail
cd "$(dirname "$0")/.."
b="${1:-build}"
[ -f "$b/CMakeCache.txt" ] || cmake -S . -B "$b" -DCMAKE_BUILD_TYPE=Release >/dev/null
tests="test_api test_sdf test_ccd test_hardening test_destroy test_solvers test_grid_cdf test_extract test_mesh_distance test_guard test_guard_world test_contacts test_soft test_soft_step test_cases test_sampled test_bend test_stretch"
cmake --build "$b" -j2 --target $tests >/dev/null
for t in $tests; do
  echo "== valgrind: $t"
  # The test's own output is shown only when it fails (valgrind's reports go to stderr as they come).
  CK_FORK=no valgrind --tool=memcheck --error-exitcode=1 --leak-check=full --show-leak-kinds=all \
    --errors-for-leak-kinds=all --track-origins=yes --quiet \
    --suppressions=scripts/valgrind.supp "$b/tests/$t" >"$b/valgrind_$t.out" \
    || { tail -40 "$b/valgrind_$t.out"; echo "valgrind: $t failed"; exit 1; }
done
echo "valgrind: all clean"
