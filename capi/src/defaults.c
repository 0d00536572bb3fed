/* SPDX-License-Identifier: MIT
 * sdfccd C ABI: the sdfccd_default_* functions, what every def, the query parameters and a rigid
 * motion start as, in one place (in the order of the public headers: ccd.h, mesh.h, grid.h, sdf.h).
 * The create functions that take these check them where they are used. The headers document
 * each default next to its field: keep both in step. */
#include "capi_internal.h"

sdfccd_QueryParams sdfccd_default_query_params(void)
{
    sdfccd_QueryParams p;
    SDFCCD__DEF_BEGIN(p);
    p.method = SDFCCD_METHOD_FWGSS;
    p.margin = 0.0;
    p.time_tolerance = 1e-7;
    p.distance_tolerance = 1e-7;
    p.max_iterations = 32;
    p.max_line_search_iterations = 64;
    p.fwgss_restarts = 2;
    p.fwgss_vertex_trace = 64;
    p.subdivision = 1;
    p.subdivision_min_area = 1e-4;
    p.subdivision_max_depth = 3;
    p.contact_slop = 1e-4;
    p.toi_window = 1e-5;
    p.max_rotation_per_segment = 3.14159265358979323846;
    p.certified_time_tolerance = 1e-7;
    p.certified_max_regions = 2000000;
    p.broad_phase = 1;
    p.max_sdf_evaluations = SDFCCD_DEFAULT_MAX_SDF_EVALUATIONS;
    p.fwgss_secant_entry = 1;
    p.fwgss_speed_tolerance = 1;
    p.fwgss_clear_proof = 32;
    p.fwgss_brent_spatial = 0;
    p.fwgss_gap_tolerance = 0.5;
    p.certified_max_bytes = SDFCCD_DEFAULT_CERTIFIED_MAX_BYTES;
    p.fwgss_derivative_spatial = 1;
    p.fwgss_restart_at_witness = 1;
    p.fwgss_kink_guard = 1;
    p.fwgss_verify = 1;
    return p;
}

sdfccd_RigidMotion sdfccd_default_rigid_motion(void)
{
    sdfccd_RigidMotion m;
    memset(&m, 0, sizeof m);
    m.pose.orientation.w = 1.0;
    return m;
}

sdfccd_MeshDef sdfccd_default_mesh_def(void)
{
    sdfccd_MeshDef d;
    SDFCCD__DEF_BEGIN(d);
    return d;
}

sdfccd_MeshLoadDef sdfccd_default_mesh_load_def(void)
{
    sdfccd_MeshLoadDef d;
    SDFCCD__DEF_BEGIN(d);
    d.scale = 1.0;
    d.merge_vertices = 1;
    d.drop_degenerate = 1;
    d.max_file_bytes = (int64_t)256 << 20;
    d.formats = NULL;
    return d;
}

sdfccd_GridDef sdfccd_default_grid_def(void)
{
    sdfccd_GridDef d;
    SDFCCD__DEF_BEGIN(d);
    d.resolution[0] = d.resolution[1] = d.resolution[2] = 32;
    d.fit_domain = 1;
    d.band = 0.0;
    d.threads = 0;
    d.max_bytes = (int64_t)4 << 30;
    return d;
}

sdfccd_SpikeGridDef sdfccd_default_spike_grid_def(void)
{
    sdfccd_SpikeGridDef d;
    SDFCCD__DEF_BEGIN(d);
    d.spacing = 0.1;
    d.base_radius = 0.05;
    d.height = 0.1;
    d.count_x = d.count_y = 20;
    return d;
}

sdfccd_CallbackSdfDef sdfccd_default_callback_sdf_def(void)
{
    sdfccd_CallbackSdfDef d;
    SDFCCD__DEF_BEGIN(d);
    d.lipschitz = 1.0;
    d.bounds.lo.x = d.bounds.lo.y = d.bounds.lo.z = -INFINITY;
    d.bounds.hi.x = d.bounds.hi.y = d.bounds.hi.z = INFINITY;
    return d;
}

sdfccd_GuardParams sdfccd_default_guard_params(void)
{
    sdfccd_GuardParams g;
    SDFCCD__DEF_BEGIN(g);
    g.tolerance = 5e-4;
    g.query = sdfccd_default_query_params();
    return g;
}

sdfccd_ContactParams sdfccd_default_contact_params(void)
{
    sdfccd_ContactParams c;
    SDFCCD__DEF_BEGIN(c);
    c.query = sdfccd_default_query_params();
    c.vertex_distance = 0.02;
    c.same_place_distance = 0.0;
    c.feature_size = 0.0;
    c.reduced_count = 0;
    c.cover_depth = 0.0;
    c.end_skip_travel = 0.0;
    c.previous.ids = NULL;
    c.previous.count = 0;
    c.previous.depth = 5e-4;
    c.previous.share = 0.8;
    return c;
}
