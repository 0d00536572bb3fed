# SPDX-License-Identifier: MIT
# Broad phase (bounding-sphere hierarchy) suite; owned by the evaluation-suite work.
sdfccd_add_check_test(test_bsh test_bsh.c)

# A smoke run of the benchmark program (4 cases per mesh, accuracy tables and chart only): ctest
# checks only that it runs; benchmark figures never decide a test.
if(TARGET sdfccd_bench)
  add_test(NAME sdfccd_bench_smoke COMMAND sdfccd_bench report ${CMAKE_CURRENT_BINARY_DIR}/bench_smoke --smoke)
endif()
