# SPDX-License-Identifier: MIT
# Broad phase (bounding-sphere hierarchy, Section 4.6); owned by the evaluation-suite work.
target_sources(sdfccd_core PRIVATE ${CMAKE_CURRENT_LIST_DIR}/bsh.c)
