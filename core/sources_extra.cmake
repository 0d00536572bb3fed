# SPDX-License-Identifier: MIT
# Marching-tetrahedra isosurface extraction; owned by the Bullet-bridge work.
target_sources(sdfccd_core PRIVATE ${CMAKE_CURRENT_LIST_DIR}/marching_tetrahedra.c)
