# SPDX-License-Identifier: MIT
# Bullet bridge measurements: bullet_cube_bench (float Bullet) and bullet_cube_bench_f64.
if(SDFCCD_BUILD_BULLET_BRIDGE)
  foreach(_tgt IN LISTS SDFCCD_BULLET_TARGETS)
    string(REPLACE "sdfccd_bullet" "bullet_cube_bench" _exe ${_tgt})
    add_executable(${_exe} ${CMAKE_CURRENT_LIST_DIR}/bullet_cube_bench.cpp)
    target_link_libraries(${_exe} PRIVATE ${_tgt})
    sdfccd_target_defaults(${_exe})
  endforeach()
endif()
