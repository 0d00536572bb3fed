# SPDX-License-Identifier: MIT
# Broad phase (bounding-sphere hierarchy) suite; owned by the evaluation-suite work.
sdfccd_add_check_test(test_bsh test_bsh.c)
