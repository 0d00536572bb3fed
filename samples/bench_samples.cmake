# SPDX-License-Identifier: MIT
# The evaluation suite (issue 4): sdfccd_bench (C; meshoptimizer for the scaling meshes) and its
# peers program sdfccd_peers (C++; Bullet's GImpact and FCL). Built only when their packages are found.
find_library(SDFCCD_MESHOPT_LIB meshoptimizer)
find_path(SDFCCD_MESHOPT_INC meshoptimizer.h)
if(SDFCCD_MESHOPT_LIB AND SDFCCD_MESHOPT_INC AND NOT SDFCCD_BUILD_SHARED)
  add_executable(sdfccd_bench ${CMAKE_CURRENT_LIST_DIR}/sdfccd_bench.c)
  # The scaling table times single triangles through the core's instrumented mesh query.
  target_link_libraries(sdfccd_bench PRIVATE sdfccd sdfccd_core ${SDFCCD_MESHOPT_LIB} m)
  target_include_directories(sdfccd_bench PRIVATE ${SDFCCD_MESHOPT_INC} ${PROJECT_SOURCE_DIR}/capi/src)
  target_compile_definitions(sdfccd_bench PRIVATE SDFCCD_BENCH_DATA_DIR="${PROJECT_SOURCE_DIR}/data"
    SDFCCD_BENCH_SOURCE_DIR="${PROJECT_SOURCE_DIR}")
  sdfccd_target_defaults(sdfccd_bench)
else()
  message(STATUS "sdfccd_bench: not built (needs libmeshoptimizer-dev and a static libsdfccd)")
endif()

pkg_check_modules(SDFCCD_FCL IMPORTED_TARGET fcl)
if(SDFCCD_FCL_FOUND AND SDFCCD_BUILD_BULLET_BRIDGE AND SDFCCD_BULLET_TARGETS)
  list(GET SDFCCD_BULLET_TARGETS 0 _sdfccd_peer_bridge)
  add_executable(sdfccd_peers ${CMAKE_CURRENT_LIST_DIR}/sdfccd_peers.cpp)
  target_link_libraries(sdfccd_peers PRIVATE ${_sdfccd_peer_bridge} sdfccd PkgConfig::SDFCCD_FCL)
  sdfccd_target_defaults(sdfccd_peers)
else()
  message(STATUS "sdfccd_peers: not built (needs libfcl-dev and the Bullet bridge)")
endif()

