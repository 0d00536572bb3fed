# SPDX-License-Identifier: MIT
# Isosurface extraction (extract.h); owned by the Bullet-bridge work.
target_sources(sdfccd PRIVATE ${CMAKE_CURRENT_LIST_DIR}/src/extract_api.c)
