# SPDX-License-Identifier: MIT
# Isosurface extraction (Check) and the Bullet bridge tests, run for every Bullet precision built.
sdfccd_add_check_test(test_extract bullet/test_extract.c)
target_include_directories(test_extract PRIVATE ${PROJECT_SOURCE_DIR}/core)

if(SDFCCD_BUILD_BULLET_BRIDGE)
  foreach(_tgt IN LISTS SDFCCD_BULLET_TARGETS)
    string(REPLACE "sdfccd_bullet" "bridge_tests" _exe ${_tgt})   # bridge_tests, bridge_tests_f64
    if(_exe STREQUAL "bridge_tests")
      set(_exe bridge_tests_f32)
    endif()
    add_executable(${_exe} bullet/bridge_tests.cpp)
    target_link_libraries(${_exe} PRIVATE ${_tgt})
    target_compile_definitions(${_exe} PRIVATE SDFCCD_DATA_DIR="${SDFCCD_DATA_DIR}")
    sdfccd_target_defaults(${_exe})
    # One ctest per scene, so a failure names the scene.
    foreach(_case cube_mesh_first cube_sdf_first cube_tunnels_without_bridge torus_spinning kinematic_sdf
                  dynamic_sdf_on_mesh_floor cdf_concave_box
                  convex_box_on_triangulation shape_aabb registration closest_points_and_toi hard_clamp)
      add_test(NAME ${_exe}.${_case} COMMAND ${_exe} ${_case})
      set_tests_properties(${_exe}.${_case} PROPERTIES LABELS bullet)
    endforeach()
  endforeach()

  # The README example, compiled and run.
  if(TARGET sdfccd::bullet)
    add_executable(bullet_hello ${PROJECT_SOURCE_DIR}/samples/bullet_hello.cpp)
    target_link_libraries(bullet_hello PRIVATE sdfccd::bullet)
    sdfccd_target_defaults(bullet_hello)
    add_test(NAME bullet_hello COMMAND bullet_hello)
    set_tests_properties(bullet_hello PROPERTIES LABELS bullet)
  endif()
endif()

# The compile-time precision check: the bridge's headers compiled with a btScalar that differs
# from the bridge library's (SDFCCD_BULLET_SCALAR_BYTES) must fail with config.h's message; the
# matching combination must compile (so the failure is the check's, not a broken command).
if(SDFCCD_BUILD_BULLET_BRIDGE)
  foreach(_tgt IN LISTS SDFCCD_BULLET_TARGETS)
    if(_tgt STREQUAL "sdfccd_bullet_f64")
      set(_right 8)
      set(_wrong 4)
    else()
      set(_right 4)
      set(_wrong 8)
    endif()
    set(_inc -I${PROJECT_SOURCE_DIR}/capi/include -I${PROJECT_SOURCE_DIR}/bullet_bridge/include)
    foreach(_d IN LISTS SDFCCD_BULLET_INCLUDE_DIRS_${_tgt})
      list(APPEND _inc -I${_d})
    endforeach()
    set(_cmd ${CMAKE_CXX_COMPILER} -std=c++11 -fsyntax-only ${SDFCCD_BULLET_CFLAGS_${_tgt}} ${_inc}
             ${CMAKE_CURRENT_SOURCE_DIR}/bullet/precision_check.cpp)
    add_test(NAME ${_tgt}.precision_match COMMAND ${_cmd} -DSDFCCD_BULLET_SCALAR_BYTES=${_right})
    add_test(NAME ${_tgt}.precision_mismatch_rejected COMMAND ${_cmd} -DSDFCCD_BULLET_SCALAR_BYTES=${_wrong})
    set_tests_properties(${_tgt}.precision_match ${_tgt}.precision_mismatch_rejected PROPERTIES LABELS bullet)
    set_tests_properties(${_tgt}.precision_mismatch_rejected PROPERTIES
      PASS_REGULAR_EXPRESSION "BT_USE_DOUBLE_PRECISION does not match the bridge library")
  endforeach()
endif()
