/* SPDX-License-Identifier: MIT */
/** @file sdfccd.h  Umbrella header: triangle-SDF continuous collision detection. */
#ifndef SDFCCD_SDFCCD_H
#define SDFCCD_SDFCCD_H

#include "base.h"
#include "types.h"
#include "sdf.h"
#include "mesh.h"
#include "ccd.h"
#include "extract.h"
#include "grid.h"
#include "contact.h"
#include "soft.h"
#include "cases.h"
#include "sampled.h"

#endif
