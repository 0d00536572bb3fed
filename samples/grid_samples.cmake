# SPDX-License-Identifier: MIT
# Grid tools (issue 3): the bake tool and the grid benchmark.
add_executable(sdfccd_bake ${CMAKE_CURRENT_LIST_DIR}/sdfccd_bake.c)
target_link_libraries(sdfccd_bake PRIVATE sdfccd m)
sdfccd_target_defaults(sdfccd_bake)
install(TARGETS sdfccd_bake RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})

# The benchmark also times the core evaluation directly, so it sees the ABI internals.
add_executable(sdfccd_grid_bench ${CMAKE_CURRENT_LIST_DIR}/sdfccd_grid_bench.c)
target_link_libraries(sdfccd_grid_bench PRIVATE sdfccd sdfccd_core m)
target_include_directories(sdfccd_grid_bench PRIVATE ${PROJECT_SOURCE_DIR}/capi/src)
target_compile_definitions(sdfccd_grid_bench PRIVATE SDFCCD_DATA_DIR="${PROJECT_SOURCE_DIR}/data")
sdfccd_target_defaults(sdfccd_grid_bench)
