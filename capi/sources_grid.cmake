# SPDX-License-Identifier: MIT
# Grid SDFs, .cdf files and mesh import (issue 3).
target_sources(sdfccd PRIVATE
  ${CMAKE_CURRENT_LIST_DIR}/src/grid_api.c
  ${CMAKE_CURRENT_LIST_DIR}/src/grid_file.c
  ${CMAKE_CURRENT_LIST_DIR}/src/mesh_import.c
  ${CMAKE_CURRENT_LIST_DIR}/src/obj_reader.c
)
