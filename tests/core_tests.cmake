# SPDX-License-Identifier: MIT
# Core Check suites (one per module).
sdfccd_add_check_test(test_ccd test_ccd.c)
sdfccd_add_check_test(test_sweep test_sweep.c)
