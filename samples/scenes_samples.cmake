# SPDX-License-Identifier: MIT
# The scene library (samples/scenes/) and its runner, once per Bullet precision:
#   sdfccd_scenes_lib     + sdfccd_scenes      (float Bullet)
#   sdfccd_scenes_lib_f64 + sdfccd_scenes_f64  (double Bullet)
# The stability tests (tests/scenes_tests.cmake) run the runner with --check.
if(SDFCCD_BUILD_BULLET_BRIDGE)
  set(_scene_sources
    ${CMAKE_CURRENT_LIST_DIR}/scenes/scene.cpp
    ${CMAKE_CURRENT_LIST_DIR}/scenes/runner.cpp
    ${CMAKE_CURRENT_LIST_DIR}/scenes/snapshot.cpp
    ${CMAKE_CURRENT_LIST_DIR}/scenes/registry.cpp
    ${CMAKE_CURRENT_LIST_DIR}/scenes/bullet_scene.cpp
    ${CMAKE_CURRENT_LIST_DIR}/scenes/bullet_recreations.cpp)
  foreach(_tgt IN LISTS SDFCCD_BULLET_TARGETS)
    string(REPLACE "sdfccd_bullet" "" _suffix ${_tgt})      # "" or "_f64"
    add_library(sdfccd_scenes_lib${_suffix} STATIC ${_scene_sources})
    target_include_directories(sdfccd_scenes_lib${_suffix} PUBLIC ${CMAKE_CURRENT_LIST_DIR} ${CMAKE_CURRENT_LIST_DIR}/scenes)
    target_link_libraries(sdfccd_scenes_lib${_suffix} PUBLIC ${_tgt})
    sdfccd_target_defaults(sdfccd_scenes_lib${_suffix})
    add_executable(sdfccd_scenes${_suffix} ${CMAKE_CURRENT_LIST_DIR}/sdfccd_scenes.cpp)
    target_link_libraries(sdfccd_scenes${_suffix} PRIVATE sdfccd_scenes_lib${_suffix})
    target_compile_definitions(sdfccd_scenes${_suffix} PRIVATE SDFCCD_DATA_DIR="${PROJECT_SOURCE_DIR}/data")
    sdfccd_target_defaults(sdfccd_scenes${_suffix})
  endforeach()
endif()
