/* SPDX-License-Identifier: MIT
 * sdfccd C ABI: the guarantee over all the checks of one body (contact.h, sdfccd_guard_body): each
 * pair through sdfccd_guard_step_rigid, the earliest rollback by scc_guard_earlier (core/guard.h). */
#include "capi_internal.h"
#include "../../core/guard.h"

#include <string.h>

sdfccd_Status sdfccd_guard_body(sdfccd_Workspace* ws, const sdfccd_GuardPair* pairs, int32_t count, double t0, double t1,
                                const sdfccd_GuardParams* params, sdfccd_GuardBodyResult* out)
{
    sdfccd_Status st;
    if ((st = sdfccd__check_ptr(out, "sdfccd_guard_body: out")) || (st = sdfccd__check_ptr(params, "sdfccd_guard_body: params"))) return st;
    if (count < 0 || (count > 0 && !pairs))
        return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "sdfccd_guard_body: count must be >= 0 with pairs not NULL (got %d, %p)", (int)count,
                             (const void*)pairs);
    sdfccd_GuardBodyResult r;
    memset(&r, 0, sizeof r);
    r.index = -1;
    r.first.state = SDFCCD_GUARD_CLEAR;
    r.first.toi = t1;
    r.first.fraction = 1.0;
    r.first.min_gap_start = INFINITY;
    for (int32_t i = 0; i < count; ++i) {
        const sdfccd_GuardPair* p = &pairs[i];
        sdfccd_GuardResult g;
        const sdfccd_Status s = sdfccd_guard_step_rigid(ws, p->sdf, p->sdf_motion, p->mesh, &p->executed, t0, t1, params, &g);
        if (s != SDFCCD_OK) {
            if (!r.failed++) r.error = s;
            continue;
        }
        r.sdf_evaluations += g.sdf_evaluations;
        r.certified += g.certified != 0;
        if (scc_guard_earlier(g.state == SDFCCD_GUARD_ROLLED_BACK, g.toi, r.first.toi)) {
            r.first = g;
            r.index = i;
        }
    }
    *out = r;
    return SDFCCD_OK;
}
