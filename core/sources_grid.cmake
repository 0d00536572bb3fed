# SPDX-License-Identifier: MIT
# Grid SDFs built in-tree (issue 3): the cubic cell, grid evaluation and building, exact mesh distance.
target_sources(sdfccd_core PRIVATE
  ${CMAKE_CURRENT_LIST_DIR}/grid_cell.c
  ${CMAKE_CURRENT_LIST_DIR}/grid.c
  ${CMAKE_CURRENT_LIST_DIR}/grid_bounds.c
  ${CMAKE_CURRENT_LIST_DIR}/grid_build.c
  ${CMAKE_CURRENT_LIST_DIR}/tri_bvh.c
  ${CMAKE_CURRENT_LIST_DIR}/mesh_distance.c
)
