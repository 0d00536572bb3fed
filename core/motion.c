/* SPDX-License-Identifier: MIT
 * sdfccd core: rigid (Eq. 14), per-vertex linear and relative motion (Section 4.1). */
#include "motion.h"

/* Centre of rotation at t. */
static inline scc_vec3 center_at(const scc_rigid* r, double t)
{
    scc_vec3 g0 = scc_add(r->p0, scc_quat_rotate(r->q0, r->c_local));
    return scc_madd(g0, r->v, t - r->t0);
}

/* Pose (q, p) and centre g at t, the centre computed once (every query sample needs all three).
 * A body that does not spin keeps q0 (no rotation vector to turn into a quaternion: the product
 * with the identity would give the same numbers, up to the sign of a zero). */
static inline void pose_center_at(const scc_rigid* r, double t, scc_quat* out_q, scc_vec3* out_p, scc_vec3* out_g)
{
    const int spins = r->w.x != 0.0 || r->w.y != 0.0 || r->w.z != 0.0;
    const scc_quat q = spins ? scc_quat_mul(scc_quat_from_rotvec(scc_scale(r->w, t - r->t0)), r->q0) : r->q0;
    const scc_vec3 g = center_at(r, t);
    *out_q = q;
    *out_p = scc_sub(g, scc_quat_rotate(q, r->c_local));
    *out_g = g;
}

void scc_rigid_pose_at(const scc_rigid* r, double t, scc_quat* out_q, scc_vec3* out_p)
{
    scc_vec3 g;
    pose_center_at(r, t, out_q, out_p, &g);
}

scc_vec3 scc_rigid_center_at(const scc_rigid* r, double t)
{
    return center_at(r, t);
}

/* World position and velocity of a body-local point. */
static scc_vec3 rigid_point(const scc_rigid* r, scc_quat q, scc_vec3 p, scc_vec3 g, scc_vec3 local, scc_vec3* vel)
{
    scc_vec3 x = scc_add(scc_quat_rotate(q, local), p);
    if (vel) *vel = scc_add(r->v, scc_cross(r->w, scc_sub(x, g)));
    return x;
}

typedef struct sdf_frame { scc_quat q; scc_vec3 p, g; int moving; } sdf_frame;

static sdf_frame frame_at(const scc_rigid* sdf, double t)
{
    sdf_frame f;
    f.moving = sdf != NULL;
    if (sdf) {
        pose_center_at(sdf, t, &f.q, &f.p, &f.g);
    } else {
        f.q = scc_quat_identity();
        f.p = f.g = scc_v3(0, 0, 0);
    }
    return f;
}

/* World point and velocity -> SDF frame point and velocity. */
static scc_vec3 to_sdf(const scc_rigid* sdf, const sdf_frame* f, scc_vec3 x, scc_vec3* vel)
{
    if (!f->moving) return x;
    if (vel) {
        scc_vec3 rel = scc_sub(scc_sub(*vel, sdf->v), scc_cross(sdf->w, scc_sub(x, f->g)));
        *vel = scc_quat_rotate(scc_quat_conj(f->q), rel);
    }
    return scc_quat_rotate(scc_quat_conj(f->q), scc_sub(x, f->p));
}

void scc_tri_state_at(const scc_tri_motion* m, double t, scc_tri_state* out)
{
    sdf_frame f = frame_at(m->sdf, t);
    out->t = t;
    if (m->kind == SCC_TRI_RIGID) {
        scc_quat q;
        scc_vec3 p;
        scc_vec3 g;
        pose_center_at(m->body, t, &q, &p, &g);
        for (int i = 0; i < 3; ++i) {
            out->x[i] = rigid_point(m->body, q, p, g, m->local[i], &out->v[i]);
            out->x[i] = to_sdf(m->sdf, &f, out->x[i], &out->v[i]);
        }
    } else {
        double span = m->t1 - m->t0;
        double s = span > 0.0 ? (t - m->t0) / span : 0.0;
        for (int i = 0; i < 3; ++i) {
            out->v[i] = span > 0.0 ? scc_scale(scc_sub(m->end[i], m->start[i]), 1.0 / span) : scc_v3(0, 0, 0);
            out->x[i] = scc_lerp(m->start[i], m->end[i], s);
            out->x[i] = to_sdf(m->sdf, &f, out->x[i], &out->v[i]);
        }
    }
}

scc_vec3 scc_tri_point_at(const scc_tri_motion* m, const double b[3], double t, scc_vec3* out_vel)
{
    sdf_frame f = frame_at(m->sdf, t);
    scc_vec3 x, v;
    if (m->kind == SCC_TRI_RIGID) {
        scc_vec3 local = scc_add(scc_add(scc_scale(m->local[0], b[0]), scc_scale(m->local[1], b[1])), scc_scale(m->local[2], b[2]));
        scc_quat q;
        scc_vec3 p;
        scc_vec3 g;
        pose_center_at(m->body, t, &q, &p, &g);
        x = rigid_point(m->body, q, p, g, local, &v);
    } else {
        double span = m->t1 - m->t0;
        double s = span > 0.0 ? (t - m->t0) / span : 0.0;
        scc_vec3 x0 = scc_add(scc_add(scc_scale(m->start[0], b[0]), scc_scale(m->start[1], b[1])), scc_scale(m->start[2], b[2]));
        scc_vec3 x1 = scc_add(scc_add(scc_scale(m->end[0], b[0]), scc_scale(m->end[1], b[1])), scc_scale(m->end[2], b[2]));
        x = scc_lerp(x0, x1, s);
        v = span > 0.0 ? scc_scale(scc_sub(x1, x0), 1.0 / span) : scc_v3(0, 0, 0);
    }
    x = to_sdf(m->sdf, &f, x, out_vel ? &v : NULL);
    if (out_vel) *out_vel = v;
    return x;
}

/* scc_tri_speed_bound of the n vertices idx[0..n-1] of m (the triangle: 0, 1, 2; a vertex alone: i). */
static double speed_bound_of(const scc_tri_motion* m, const int* idx, int n)
{
    double T = m->t1 - m->t0;
    double speed = 0.0, reach = 0.0; /* reach: bound on |x_world(t) - g_sdf(t)| */
    scc_vec3 gs0 = m->sdf ? scc_rigid_center_at(m->sdf, m->t0) : scc_v3(0, 0, 0);
    if (m->kind == SCC_TRI_RIGID) {
        scc_vec3 c = m->body->c_local;
        double r = 0.0;
        for (int i = 0; i < n; ++i) r = scc_fmax(r, scc_dist(m->local[idx[i]], c));
        speed = scc_len(m->body->v) + scc_len(m->body->w) * r;
        if (m->sdf) {
            scc_vec3 g0 = scc_rigid_center_at(m->body, m->t0);
            reach = scc_dist(g0, gs0) + r + (scc_len(m->body->v) + scc_len(m->sdf->v)) * fabs(T);
        }
    } else {
        for (int i = 0; i < n; ++i) {
            double d = scc_dist(m->end[idx[i]], m->start[idx[i]]);
            speed = scc_fmax(speed, T > 0.0 ? d / T : 0.0);
            if (m->sdf) reach = scc_fmax(reach, scc_dist(m->start[idx[i]], gs0) + d + scc_len(m->sdf->v) * fabs(T));
        }
    }
    if (m->sdf) speed += scc_len(m->sdf->v) + scc_len(m->sdf->w) * reach;
    return speed;
}

double scc_tri_speed_bound(const scc_tri_motion* m)
{
    static const int all[3] = { 0, 1, 2 };
    return speed_bound_of(m, all, 3);
}

double scc_vertex_speed_bound(const scc_tri_motion* m, int i)
{
    return speed_bound_of(m, &i, 1); /* the vertex once (its bound repeated three times is the same max) */
}

double scc_tri_accel_bound(const scc_tri_motion* m)
{
    /* World acceleration of a point of a body spinning at constant w about a centre moving at
     * constant velocity: w x (w x r), so |a| <= |w|^2 r. In a frame rotating at constant w_s the
     * apparent acceleration adds Coriolis and centripetal terms: 2 |w_s| |v_rel| + |w_s|^2 |r_s|. */
    double a = 0.0, r = 0.0;
    if (m->kind == SCC_TRI_RIGID) {
        for (int i = 0; i < 3; ++i) r = scc_fmax(r, scc_dist(m->local[i], m->body->c_local));
        a = scc_len2(m->body->w) * r;
    }
    if (m->sdf) {
        double ws = scc_len(m->sdf->w);
        if (ws > 0.0) {
            double S = scc_tri_speed_bound(m);
            double T = fabs(m->t1 - m->t0);
            scc_vec3 gs0 = scc_rigid_center_at(m->sdf, m->t0);
            double reach = 0.0;
            for (int i = 0; i < 3; ++i) {
                scc_vec3 x0 = m->kind == SCC_TRI_RIGID ? scc_xform_apply((scc_xform){ m->body->q0, m->body->p0 }, m->local[i]) : m->start[i];
                reach = scc_fmax(reach, scc_dist(x0, gs0));
            }
            reach += (S + scc_len(m->sdf->v)) * T;
            a += 2.0 * ws * S + ws * ws * reach;
        }
    }
    return a;
}

double scc_tri_rotation_angle(const scc_tri_motion* m, double ta, double tb)
{
    double w = 0.0;
    if (m->kind == SCC_TRI_RIGID) w += scc_len(m->body->w);
    if (m->sdf) w += scc_len(m->sdf->w);
    return w * fabs(tb - ta);
}

scc_vec3 scc_sdf_frame_point(const scc_rigid* sdf, double t, scc_vec3 world)
{
    if (!sdf) return world;
    sdf_frame f = frame_at(sdf, t);
    return to_sdf(sdf, &f, world, NULL);
}

scc_vec3 scc_world_point(const scc_rigid* sdf, double t, scc_vec3 local)
{
    if (!sdf) return local;
    sdf_frame f = frame_at(sdf, t);
    return scc_add(scc_quat_rotate(f.q, local), f.p);
}

scc_vec3 scc_world_vector(const scc_rigid* sdf, double t, scc_vec3 local)
{
    if (!sdf) return local;
    sdf_frame f = frame_at(sdf, t);
    return scc_quat_rotate(f.q, local);
}
