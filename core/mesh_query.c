/* SPDX-License-Identifier: MIT
 * sdfccd core: a moving mesh against an SDF. Each triangle is queried on [t0, best + window]
 * where `best` is the earliest TOI found so far, so the interval shrinks as earlier hits are
 * found (Section 5.3). The result is the earliest TOI with the contacts of every triangle whose
 * TOI lies within the window of it (plus their subdivision contacts). */
#include "ccd.h"

typedef struct contact_buf {
    scc_contact* a;
    size_t n, cap;
    const scc_allocator* alloc;
} contact_buf;

static int buf_push(contact_buf* b, const scc_contact* c)
{
    if (b->n == b->cap) {
        size_t cap = b->cap ? 2 * b->cap : 32;
        scc_contact* na = scc_alloc(b->alloc, cap * sizeof *na);
        if (!na) return 0;
        for (size_t i = 0; i < b->n; ++i) na[i] = b->a[i];
        scc_free(b->alloc, b->a, b->cap * sizeof *b->a);
        b->a = na;
        b->cap = cap;
    }
    b->a[b->n++] = *c;
    return 1;
}

/* Drops contacts later than `limit`. */
static void buf_prune(contact_buf* b, double limit)
{
    size_t k = 0;
    for (size_t i = 0; i < b->n; ++i)
        if (b->a[i].toi <= limit) b->a[k++] = b->a[i];
    b->n = k;
}

static void fill_triangle_motion(const scc_mesh_motion* mm, uint32_t t, scc_tri_motion* m)
{
    const uint32_t* f = mm->mesh->indices + 3 * t;
    m->sdf = mm->sdf;
    m->t0 = mm->t0;
    m->t1 = mm->t1;
    if (mm->body) {
        m->kind = SCC_TRI_RIGID;
        m->body = mm->body;
        for (int i = 0; i < 3; ++i) m->local[i] = mm->mesh->vertices[f[i]];
    } else {
        m->kind = SCC_TRI_LINEAR;
        m->body = NULL;
        for (int i = 0; i < 3; ++i) {
            m->start[i] = mm->start[f[i]];
            m->end[i] = mm->end[f[i]];
        }
    }
}

int scc_query_mesh(const scc_sdf* sdf, const scc_mesh_motion* mm, const scc_params* p, const scc_allocator* alloc,
                   scc_contact* out, int capacity, scc_query_summary* sum)
{
    contact_buf buf = { NULL, 0, 0, alloc };
    scc_contact local[1 + SCC_MAX_SUBDIVISION_CONTACTS];
    double best = INFINITY, lower = INFINITY;
    scc_state best_state = SCC_NO_HIT;
    int any_not_converged = 0, ok = 1;
    sum->iterations = sum->evals = sum->triangles_tested = 0;
    for (uint32_t t = 0; t < mm->mesh->triangle_count && ok; ++t) {
        double tb = fmin(mm->t1, best + p->toi_window);
        scc_tri_motion m;
        fill_triangle_motion(mm, t, &m);
        scc_query_summary s;
        if (!scc_query_triangle(sdf, &m, mm->t0, tb, p, alloc, t, local, 1 + SCC_MAX_SUBDIVISION_CONTACTS, &s)) {
            ok = 0;
            break;
        }
        sum->iterations += s.iterations;
        sum->evals += s.evals;
        sum->triangles_tested += 1;
        lower = fmin(lower, s.toi_lower);
        if (!s.hit) {
            any_not_converged |= s.state == SCC_NOT_CONVERGED;
            continue;
        }
        int n = s.contacts_found < 1 + SCC_MAX_SUBDIVISION_CONTACTS ? s.contacts_found : 1 + SCC_MAX_SUBDIVISION_CONTACTS;
        for (int i = 0; i < n && ok; ++i) ok = buf_push(&buf, &local[i]);
        if (s.toi < best) {
            best = s.toi;
            best_state = s.state;
            buf_prune(&buf, best + p->toi_window);
        }
    }
    if (!ok) {
        scc_free(alloc, buf.a, buf.cap * sizeof *buf.a);
        return 0;
    }
    /* Earliest first; insertion sort is fine for the handful of contacts at one TOI. */
    for (size_t i = 1; i < buf.n; ++i) {
        scc_contact c = buf.a[i];
        size_t j = i;
        while (j > 0 && buf.a[j - 1].toi > c.toi) { buf.a[j] = buf.a[j - 1]; --j; }
        buf.a[j] = c;
    }
    sum->hit = isfinite(best);
    sum->toi = sum->hit ? best : mm->t1;
    sum->toi_lower = fmin(lower, sum->toi); /* certified: no triangle touches before this */
    sum->state = sum->hit ? best_state : (any_not_converged ? SCC_NOT_CONVERGED : SCC_NO_HIT);
    sum->contacts_found = (int)buf.n;
    for (size_t i = 0; i < buf.n && (int)i < capacity; ++i) out[i] = buf.a[i];
    scc_free(alloc, buf.a, buf.cap * sizeof *buf.a);
    return 1;
}
