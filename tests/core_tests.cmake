# SPDX-License-Identifier: MIT
# Core Check suites (one per module).
sdfccd_add_check_test(test_ccd test_ccd.c)
sdfccd_add_check_test(test_sweep test_sweep.c)
sdfccd_add_check_test(test_sdf test_sdf.c)
sdfccd_add_check_test(test_solvers test_solvers.c)
sdfccd_add_check_test(test_api test_api.c)
sdfccd_add_check_test(test_fall test_fall.c)

# Packaging: cmake --install, then find_package(sdfccd) and pkg-config from a separate project.
add_test(NAME install_consumer COMMAND ${CMAKE_COMMAND}
  -DBUILD_DIR=${PROJECT_BINARY_DIR} -DSOURCE_DIR=${CMAKE_CURRENT_SOURCE_DIR}/consumer
  -DWORK_DIR=${CMAKE_CURRENT_BINARY_DIR}/install_consumer -DC_COMPILER=${CMAKE_C_COMPILER}
  -P ${CMAKE_CURRENT_SOURCE_DIR}/consumer/run_install_test.cmake)
set_tests_properties(install_consumer PROPERTIES LABELS slow RUN_SERIAL TRUE)

# The README's C example, extracted from README.md between its example markers, built and run.
file(READ ${PROJECT_SOURCE_DIR}/README.md _readme)
string(REGEX MATCH "<!-- example:begin -->[^`]*```c\n(.*)\n```[^`]*<!-- example:end -->" _match "${_readme}")
if(NOT CMAKE_MATCH_1)
  message(FATAL_ERROR "README.md has no C example between <!-- example:begin --> and <!-- example:end -->")
endif()
file(WRITE ${CMAKE_CURRENT_BINARY_DIR}/readme_example.c "${CMAKE_MATCH_1}\n")
set_property(DIRECTORY APPEND PROPERTY CMAKE_CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/README.md)
add_executable(readme_example ${CMAKE_CURRENT_BINARY_DIR}/readme_example.c)
target_link_libraries(readme_example PRIVATE sdfccd m)
sdfccd_target_defaults(readme_example)
add_test(NAME readme_example COMMAND readme_example)

# The threading contract of base.h (concurrent queries, per-thread errors, concurrent handles).
sdfccd_add_check_test(test_threads test_threads.c)
target_link_libraries(test_threads PRIVATE Threads::Threads)

# Regression tests of the hardening findings (issue 11).
sdfccd_add_check_test(test_hardening test_hardening.c)
