# SPDX-License-Identifier: MIT
# Grid SDF suites (issue 3): element, .cdf files and Discregrid compatibility, exact mesh
# distance, grid building, and Bullet's btSdfCollisionShape reading our files.
sdfccd_add_check_test(test_grid_cdf test_grid_cdf.c)
target_compile_definitions(test_grid_cdf PRIVATE SDFCCD_TEST_TMP_DIR="${CMAKE_CURRENT_BINARY_DIR}")
sdfccd_add_check_test(test_mesh_distance test_mesh_distance.c)
sdfccd_add_check_test(test_grid_build test_grid_build.c)
target_compile_definitions(test_grid_build PRIVATE SDFCCD_TEST_TMP_DIR="${CMAKE_CURRENT_BINARY_DIR}")
