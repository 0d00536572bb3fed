/* SPDX-License-Identifier: MIT
 * sdfccd core: analytic signed distance fields with exact gradients, CSG and transforms.
 * Each struct embeds scc_sdf first; the *_init functions fill the interface. */
#ifndef SCC_SDF_ANALYTIC_H
#define SCC_SDF_ANALYTIC_H

#include "sdf.h"

typedef struct scc_sdf_sphere { scc_sdf base; double radius; } scc_sdf_sphere;
typedef struct scc_sdf_box { scc_sdf base; scc_vec3 half; double radius; } scc_sdf_box; /* radius > 0: rounded */
typedef struct scc_sdf_torus { scc_sdf base; double major, minor; } scc_sdf_torus;
typedef struct scc_sdf_capsule { scc_sdf base; double half_height, radius; } scc_sdf_capsule;
typedef struct scc_sdf_cylinder { scc_sdf base; double half_height, radius; } scc_sdf_cylinder;
typedef struct scc_sdf_half_space { scc_sdf base; scc_vec3 normal; double offset; } scc_sdf_half_space;
typedef struct scc_sdf_spike_grid {
    scc_sdf base;
    double spacing, base_radius, height;
    int count_x, count_y;
    double x0, y0; /* centre of cone (0, 0) */
} scc_sdf_spike_grid;

typedef enum scc_csg_op { SCC_CSG_UNION, SCC_CSG_INTERSECTION, SCC_CSG_DIFFERENCE } scc_csg_op;
typedef struct scc_sdf_csg { scc_sdf base; scc_csg_op op; const scc_sdf* a; const scc_sdf* b; } scc_sdf_csg;
typedef struct scc_sdf_transform { scc_sdf base; const scc_sdf* child; scc_xform xf; double scale; } scc_sdf_transform;

/* Parameters are validated by the caller (the ABI layer): positive sizes, finite values. */
void scc_sdf_sphere_init(scc_sdf_sphere* s, double radius);
void scc_sdf_box_init(scc_sdf_box* s, scc_vec3 half, double radius);
void scc_sdf_torus_init(scc_sdf_torus* s, double major, double minor);
void scc_sdf_capsule_init(scc_sdf_capsule* s, double half_height, double radius);
void scc_sdf_cylinder_init(scc_sdf_cylinder* s, double half_height, double radius);
void scc_sdf_half_space_init(scc_sdf_half_space* s, scc_vec3 unit_normal, double offset);
void scc_sdf_spike_grid_init(scc_sdf_spike_grid* s, double spacing, double base_radius, double height, int nx, int ny);
void scc_sdf_csg_init(scc_sdf_csg* s, scc_csg_op op, const scc_sdf* a, const scc_sdf* b);
void scc_sdf_transform_init(scc_sdf_transform* s, const scc_sdf* child, scc_xform xf, double scale);

/* Inlined even where the compiler would call it (their bodies look large): the solvers' hot
 * loops evaluate through them. */
#if defined(__GNUC__) || defined(__clang__)
#define SCC_HOT_INLINE static inline __attribute__((always_inline))
#else
#define SCC_HOT_INLINE static inline
#endif

/* The evaluators of the simple analytic fields, inline: a solver's hot loop calls them directly
 * (scc_sdf_eval_builtin) instead of through the eval pointer, the same arithmetic. */
static inline double scc_sign_of(double x) { return x < 0.0 ? -1.0 : 1.0; }
static inline double scc_sdf_sphere_value(const scc_sdf_sphere* s, scc_vec3 p, scc_vec3* g)
{
    double l = scc_len_safe(p);
    if (g) *g = l > 0.0 ? scc_v3(p.x / l, p.y / l, p.z / l) : scc_v3(0.0, 0.0, 1.0);
    return l - s->radius;
}

static inline double scc_sdf_box_value(const scc_sdf_box* s, scc_vec3 p, scc_vec3* g)
{
    scc_vec3 inner = scc_sub(s->half, scc_v3(s->radius, s->radius, s->radius));
    scc_vec3 q = scc_sub(scc_vabs(p), inner);
    scc_vec3 qp = scc_vmax(q, scc_v3(0, 0, 0));
    double outside = scc_len_safe(qp);
    double inside = fmin(scc_maxc(q), 0.0);
    if (g) {
        if (outside > 0.0) {
            *g = scc_v3(qp.x / outside * scc_sign_of(p.x), qp.y / outside * scc_sign_of(p.y), qp.z / outside * scc_sign_of(p.z));
        } else if (q.x >= q.y && q.x >= q.z) {
            *g = scc_v3(scc_sign_of(p.x), 0, 0);
        } else if (q.y >= q.z) {
            *g = scc_v3(0, scc_sign_of(p.y), 0);
        } else {
            *g = scc_v3(0, 0, scc_sign_of(p.z));
        }
    }
    return outside + inside - s->radius;
}

SCC_HOT_INLINE double scc_sdf_torus_value(const scc_sdf_torus* s, scc_vec3 p, scc_vec3* g)
{
    double rho = scc_hypot2(p.x, p.y);
    double qx = rho - s->major, qz = p.z;
    double l = scc_hypot2(qx, qz);
    if (g) {
        double ex = rho > 0.0 ? p.x / rho : 1.0, ey = rho > 0.0 ? p.y / rho : 0.0;
        *g = l > 0.0 ? scc_v3(qx / l * ex, qx / l * ey, qz / l) : scc_v3(ex, ey, 0.0);
    }
    return l - s->minor;
}

static inline double scc_sdf_capsule_value(const scc_sdf_capsule* s, scc_vec3 p, scc_vec3* g)
{
    scc_vec3 d = scc_v3(p.x, p.y, p.z - scc_clamp(p.z, -s->half_height, s->half_height));
    double l = scc_len_safe(d);
    if (g) *g = l > 0.0 ? scc_v3(d.x / l, d.y / l, d.z / l) : scc_v3(1.0, 0.0, 0.0);
    return l - s->radius;
}

static inline double scc_sdf_cylinder_value(const scc_sdf_cylinder* s, scc_vec3 p, scc_vec3* g)
{
    double rho = scc_hypot2(p.x, p.y);
    double ex = rho > 0.0 ? p.x / rho : 1.0, ey = rho > 0.0 ? p.y / rho : 0.0;
    double dr = rho - s->radius, dz = fabs(p.z) - s->half_height;
    double or_ = fmax(dr, 0.0), oz = fmax(dz, 0.0);
    double outside = scc_hypot2(or_, oz);
    if (g) {
        if (outside > 0.0)
            *g = scc_v3(or_ / outside * ex, or_ / outside * ey, oz / outside * scc_sign_of(p.z));
        else if (dr > dz)
            *g = scc_v3(ex, ey, 0.0);
        else
            *g = scc_v3(0.0, 0.0, scc_sign_of(p.z));
    }
    return outside + fmin(fmax(dr, dz), 0.0);
}

static inline double scc_sdf_half_space_value(const scc_sdf_half_space* s, scc_vec3 p, scc_vec3* g)
{
    if (g) *g = s->normal;
    return scc_dot(s->normal, p) - s->offset;
}

/* Their eval functions (the scc_sdf.eval of each kind). */
double scc_sdf_sphere_eval(const scc_sdf* self, scc_vec3 p, scc_vec3* g);
double scc_sdf_box_eval(const scc_sdf* self, scc_vec3 p, scc_vec3* g);
double scc_sdf_torus_eval(const scc_sdf* self, scc_vec3 p, scc_vec3* g);
double scc_sdf_capsule_eval(const scc_sdf* self, scc_vec3 p, scc_vec3* g);
double scc_sdf_cylinder_eval(const scc_sdf* self, scc_vec3 p, scc_vec3* g);
double scc_sdf_half_space_eval(const scc_sdf* self, scc_vec3 p, scc_vec3* g);

/* scc_sdf_eval with the simple analytic fields evaluated inline (identified by their eval pointer,
 * so a struct of another kind with the same tag is never misread). */
SCC_HOT_INLINE double scc_sdf_eval_builtin(const scc_sdf* s, scc_vec3 p, scc_vec3* g)
{
    /* a chain of tests, the torus first, rather than a switch's jump table: fewer instructions per sample */
    const scc_sdf_kind k = s->kind;
    if (k == SCC_SDF_TORUS && s->eval == scc_sdf_torus_eval) return scc_sdf_torus_value((const scc_sdf_torus*)s, p, g);
    if (k == SCC_SDF_SPHERE && s->eval == scc_sdf_sphere_eval) return scc_sdf_sphere_value((const scc_sdf_sphere*)s, p, g);
    if (k == SCC_SDF_CAPSULE && s->eval == scc_sdf_capsule_eval) return scc_sdf_capsule_value((const scc_sdf_capsule*)s, p, g);
    if (k == SCC_SDF_HALF_SPACE && s->eval == scc_sdf_half_space_eval)
        return scc_sdf_half_space_value((const scc_sdf_half_space*)s, p, g);
    return s->eval(s, p, g);
}

#endif
