# SPDX-License-Identifier: MIT
# Grid SDF suites (issue 3): element, .cdf files and Discregrid compatibility, exact mesh
# distance, grid building, and Bullet's btSdfCollisionShape reading our files.
sdfccd_add_check_test(test_grid_cdf test_grid_cdf.c)
target_compile_definitions(test_grid_cdf PRIVATE SDFCCD_TEST_TMP_DIR="${CMAKE_CURRENT_BINARY_DIR}")
sdfccd_add_check_test(test_mesh_distance test_mesh_distance.c)
sdfccd_add_check_test(test_grid_build test_grid_build.c)
target_compile_definitions(test_grid_build PRIVATE SDFCCD_TEST_TMP_DIR="${CMAKE_CURRENT_BINARY_DIR}")

# Bullet reads our files: one executable per Bullet precision found through pkg-config (Debian's
# CMake configs for Bullet are broken). Independent of the bridge option.
include(CheckLanguage)
check_language(CXX)
if(CMAKE_CXX_COMPILER)
  enable_language(CXX)
  foreach(_pc bullet bullet-float64)
    string(MAKE_C_IDENTIFIER "${_pc}" _id)
    pkg_check_modules(SDFCCD_GRIDTEST_${_id} QUIET IMPORTED_TARGET ${_pc})
    if(SDFCCD_GRIDTEST_${_id}_FOUND)
      set(_exe test_grid_${_id})
      add_executable(${_exe} test_grid_bullet.cpp)
      target_link_libraries(${_exe} PRIVATE sdfccd PkgConfig::SDFCCD_GRIDTEST_${_id})
      target_compile_definitions(${_exe} PRIVATE SDFCCD_DATA_DIR="${SDFCCD_DATA_DIR}" SDFCCD_TEST_TMP_DIR="${CMAKE_CURRENT_BINARY_DIR}")
      sdfccd_target_defaults(${_exe})
      add_test(NAME ${_exe} COMMAND ${_exe})
      set_tests_properties(${_exe} PROPERTIES LABELS bullet)
    else()
      message(STATUS "sdfccd: pkg-config ${_pc} not found; ${_pc} grid compatibility test skipped")
    endif()
  endforeach()
endif()

# The bake tool: a good run, and clear failures (exit status 1 for a bad mesh, 2 for bad usage).
if(TARGET sdfccd_bake)
  add_test(NAME sdfccd_bake_box COMMAND sdfccd_bake ${SDFCCD_DATA_DIR}/discregrid/box.obj -r 5 -t 2 --samples 2000
           -o ${CMAKE_CURRENT_BINARY_DIR}/bake_box_r5.cdf)
  set_tests_properties(sdfccd_bake_box PROPERTIES PASS_REGULAR_EXPRESSION "cells: 125 stored of 125; nodes: 1296;.*file: 27040 bytes")
  add_test(NAME sdfccd_bake_missing_mesh COMMAND sdfccd_bake ${SDFCCD_DATA_DIR}/no_such_mesh.obj -r 8 -o ${CMAKE_CURRENT_BINARY_DIR}/x.cdf)
  set_tests_properties(sdfccd_bake_missing_mesh PROPERTIES WILL_FAIL TRUE)
  add_test(NAME sdfccd_bake_bad_usage COMMAND sdfccd_bake ${SDFCCD_DATA_DIR}/discregrid/box.obj -r zero -o ${CMAKE_CURRENT_BINARY_DIR}/x.cdf)
  set_tests_properties(sdfccd_bake_bad_usage PROPERTIES WILL_FAIL TRUE)
endif()
