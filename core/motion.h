/* SPDX-License-Identifier: MIT
 * sdfccd core: motion of a triangle over an interval, seen from the SDF's local frame.
 *
 * Rigid motion (the paper's Eq. 14): a body with pose (p0, q0) at t0 whose centre
 * g = p0 + R(q0) c moves with constant velocity v and which spins with constant world
 * angular velocity w about g:  x(t) = g(t0) + v tau + R(w tau) (x(t0) - g(t0)),  tau = t - t0.
 * Per-vertex linear motion: each vertex moves from its t0 to its t1 position.
 * A moving SDF: the world point is mapped into the SDF's frame at every time (relative motion).
 */
#ifndef SCC_MOTION_H
#define SCC_MOTION_H

#include <stdint.h>
#include "scc_math.h"

typedef struct scc_rigid {
    scc_vec3 p0;       /* frame origin at t0 (world) */
    scc_quat q0;       /* orientation at t0 (unit) */
    scc_vec3 c_local;  /* centre of rotation in the local frame */
    scc_vec3 v;        /* linear velocity of the centre (world) */
    scc_vec3 w;        /* angular velocity (world, rad/s) */
    double t0;
} scc_rigid;

/* Pose of the body frame at time t: x_world = R(q) x_local + p. */
void scc_rigid_pose_at(const scc_rigid* r, double t, scc_quat* out_q, scc_vec3* out_p);
/* The centre g(t). */
scc_vec3 scc_rigid_center_at(const scc_rigid* r, double t);

typedef enum scc_tri_motion_kind { SCC_TRI_RIGID, SCC_TRI_LINEAR } scc_tri_motion_kind;

/* What one query has learnt about one vertex path by FWGSS's conservative vertex trace
 * (fwgss.c). A mesh query keeps one per mesh vertex and hands the triangle solver the records of
 * its three vertices, so a vertex shared by several triangles is traced once per query instead of
 * once per triangle; a triangle query has none. */
typedef struct scc_vertex_trace {
    uint32_t epoch;     /* the mesh query's epoch when the record is in use (stale otherwise) */
    double speed;       /* speed bound of this vertex (SDF frame); < 0 until computed */
    double from, to;    /* the path is clear of the margin on [from, to) (empty when to <= from) */
    double hit_t;       /* earliest contact witnessed on the path (INFINITY: none) */
    double hit_phi;     /* phi there */
} scc_vertex_trace;

typedef struct scc_tri_motion {
    scc_tri_motion_kind kind;
    scc_vec3 local[3];       /* SCC_TRI_RIGID: vertices in the body's local frame */
    scc_vec3 start[3];       /* SCC_TRI_LINEAR: world vertices at t0 */
    scc_vec3 end[3];         /* SCC_TRI_LINEAR: world vertices at t1 */
    const scc_rigid* body;   /* SCC_TRI_RIGID */
    const scc_rigid* sdf;    /* NULL: the SDF is static at the world origin */
    double t0, t1;           /* the query interval (linear motion spans exactly this) */
    scc_vertex_trace* trace[3]; /* optional shared vertex traces (mesh query); NULL: traced locally */
} scc_tri_motion;

/* A snapshot of the triangle at one time: vertex positions and velocities in the SDF frame. */
typedef struct scc_tri_state {
    double t;
    scc_vec3 x[3];
    scc_vec3 v[3];
} scc_tri_state;

/* Vertices and their velocities at time t, in the SDF frame. */
void scc_tri_state_at(const scc_tri_motion* m, double t, scc_tri_state* out);

/* Point with barycentric weights b (b[0] + b[1] + b[2] = 1) at time t, in the SDF frame;
 * writes its velocity when out_vel is not NULL. */
scc_vec3 scc_tri_point_at(const scc_tri_motion* m, const double b[3], double t, scc_vec3* out_vel);

/* Upper bound on the speed (SDF frame) of any point of the triangle over [m->t0, m->t1]. */
double scc_tri_speed_bound(const scc_tri_motion* m);
/* The same for vertex i of the triangle alone. */
double scc_vertex_speed_bound(const scc_tri_motion* m, int i);

/* Upper bound on the acceleration (SDF frame) of any point of the triangle over [m->t0, m->t1]. */
double scc_tri_accel_bound(const scc_tri_motion* m);

/* Total relative rotation angle over [ta, tb] (radians, an upper bound). */
double scc_tri_rotation_angle(const scc_tri_motion* m, double ta, double tb);

/* Map a world point at time t into the SDF frame (identity when sdf is NULL), and back. */
scc_vec3 scc_sdf_frame_point(const scc_rigid* sdf, double t, scc_vec3 world);
scc_vec3 scc_world_point(const scc_rigid* sdf, double t, scc_vec3 local);
scc_vec3 scc_world_vector(const scc_rigid* sdf, double t, scc_vec3 local);

#endif
