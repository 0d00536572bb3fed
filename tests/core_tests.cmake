# SPDX-License-Identifier: MIT
# Core Check suites (one per module).
sdfccd_add_check_test(test_ccd test_ccd.c)
sdfccd_add_check_test(test_sweep test_sweep.c)
sdfccd_add_check_test(test_sdf test_sdf.c)
sdfccd_add_check_test(test_solvers test_solvers.c)
sdfccd_add_check_test(test_api test_api.c)
