/* jdem_mesh.c — the mesh topology and the per-sphere contact rule of jdem_mesh.h. */
#include "jdem_mesh.h"

#include <math.h>

/* ---------------------------------------------------------------------------------------- */
/* An allocation-free heap sort of indices (deterministic: ties broken by the index).         */

typedef int (*less_fn)(const void *ctx, int64_t a, int64_t b);

static void sift_down(int64_t *a, size_t root, size_t n, less_fn less, const void *ctx) {
    for (;;) {
        size_t child = 2 * root + 1;
        if (child >= n) return;
        if (child + 1 < n && less(ctx, a[child], a[child + 1])) child++;
        if (!less(ctx, a[root], a[child])) return;
        const int64_t t = a[root];
        a[root] = a[child];
        a[child] = t;
        root = child;
    }
}

static void heap_sort(int64_t *a, size_t n, less_fn less, const void *ctx) {
    for (size_t k = n / 2; k-- > 0;) sift_down(a, k, n, less, ctx);
    for (size_t end = n; end-- > 1;) {
        const int64_t t = a[0];
        a[0] = a[end];
        a[end] = t;
        sift_down(a, 0, end, less, ctx);
    }
}

/* corners c = 3 t + k, ordered by their coordinates (x, then y, then z), then by c */
static int corner_less(const void *ctx, int64_t a, int64_t b) {
    const double(*corner)[3][3] = ctx;
    const double *pa = corner[a / 3][a % 3], *pb = corner[b / 3][b % 3];
    for (int d = 0; d < 3; d++)
        if (pa[d] != pb[d]) return pa[d] < pb[d];
    return a < b;
}

static void edge_ends(const jd_mesh *m, int64_t c, int32_t *lo, int32_t *hi) {
    const int32_t *tv = m->tri_vertex[c / 3];
    const int32_t u = tv[c % 3], v = tv[(c % 3 + 1) % 3];
    *lo = u < v ? u : v;
    *hi = u < v ? v : u;
}

/* corner slots c = 3 t + k (edge k of triangle t), ordered by the edge's (lo, hi), then by c */
static int edge_less(const void *ctx, int64_t a, int64_t b) {
    int32_t la, ha, lb, hb;
    edge_ends(ctx, a, &la, &ha);
    edge_ends(ctx, b, &lb, &hb);
    if (la != lb) return la < lb;
    if (ha != hb) return ha < hb;
    return a < b;
}

static int same_point(const double a[3], const double b[3]) {
    return a[0] == b[0] && a[1] == b[1] && a[2] == b[2];
}

static void weld_vertices(size_t ntri, const double (*corner)[3][3], const jd_mesh_storage *st,
                          jd_mesh *m) {
    const size_t nc = 3 * ntri;
    for (size_t c = 0; c < nc; c++) st->scratch[c] = (int64_t)c;
    heap_sort(st->scratch, nc, corner_less, corner);
    m->nvert = 0;
    for (size_t k = 0; k < nc; k++) {
        const int64_t c = st->scratch[k];
        const double *x = corner[c / 3][c % 3];
        if (m->nvert == 0 || !same_point(m->vertex[m->nvert - 1], x)) {
            for (int d = 0; d < 3; d++) m->vertex[m->nvert][d] = x[d];
            m->vertex_valence[m->nvert] = 0;
            m->nvert++;
        }
        m->tri_vertex[c / 3][c % 3] = (int32_t)(m->nvert - 1);
    }
}

static void number_edges(size_t ntri, const jd_mesh_storage *st, jd_mesh *m) {
    const size_t nc = 3 * ntri;
    for (size_t c = 0; c < nc; c++) st->scratch[c] = (int64_t)c;
    heap_sort(st->scratch, nc, edge_less, m);
    m->nedge = 0;
    for (size_t k = 0; k < nc; k++) {
        const int64_t c = st->scratch[k];
        int32_t lo, hi;
        edge_ends(m, c, &lo, &hi);
        if (m->nedge == 0 || m->edge_vertex[m->nedge - 1][0] != lo ||
            m->edge_vertex[m->nedge - 1][1] != hi) {
            m->edge_vertex[m->nedge][0] = lo;
            m->edge_vertex[m->nedge][1] = hi;
            m->edge_valence[m->nedge] = 0;
            m->nedge++;
        }
        m->edge_valence[m->nedge - 1]++;
        m->tri_edge[c / 3][c % 3] = (int32_t)(m->nedge - 1);
    }
}

static int degenerate(const jd_mesh *m, size_t t) {
    const int32_t *v = m->tri_vertex[t];
    if (v[0] == v[1] || v[1] == v[2] || v[2] == v[0]) return 1;
    const double *a = m->vertex[v[0]], *b = m->vertex[v[1]], *c = m->vertex[v[2]];
    const double ab[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
    const double ac[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
    double n[3];
    jd_cross(ab, ac, n);
    return !(jd_dot(n, n) > 0.0);
}

int jd_mesh_build(size_t ntri, const double (*corner)[3][3], const jd_mesh_storage *st, jd_mesh *m,
                  size_t *bad) {
    if (ntri > (size_t)INT32_MAX / 3) return JD_MESH_TOO_LARGE;
    *m = (jd_mesh){.ntri = ntri, .vertex = st->vertex, .tri_vertex = st->tri_vertex,
                   .tri_edge = st->tri_edge, .edge_vertex = st->edge_vertex,
                   .edge_valence = st->edge_valence, .vertex_valence = st->vertex_valence};
    weld_vertices(ntri, corner, st, m);
    for (size_t t = 0; t < ntri; t++)
        if (degenerate(m, t)) {
            *bad = t;
            return JD_MESH_DEGENERATE;
        }
    number_edges(ntri, st, m);
    for (size_t t = 0; t < ntri; t++)
        for (int k = 0; k < 3; k++) m->vertex_valence[m->tri_vertex[t][k]]++;
    return JD_MESH_OK;
}

/* ---------------------------------------------------------------------------------------- */
/* The closest feature of one triangle                                                       */

static double dist2_to(const double p[3], const double q[3]) {
    const double d[3] = {p[0] - q[0], p[1] - q[1], p[2] - q[2]};
    return jd_dot(d, d);
}

/* ((b - a) x (p - a)) . n: > 0 when p lies on the inner side of the edge a -> b */
static double edge_side(const double a[3], const double b[3], const double p[3], const double n[3]) {
    const double ab[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
    const double ap[3] = {p[0] - a[0], p[1] - a[1], p[2] - a[2]};
    double c[3];
    jd_cross(ab, ap, c);
    return jd_dot(c, n);
}

/* The foot of p on triangle t's plane, in foot (returns 1 when it lies strictly inside). */
static int plane_foot(const jd_mesh *m, int32_t t, const double p[3], double foot[3]) {
    const int32_t *v = m->tri_vertex[t];
    const double *a = m->vertex[v[0]], *b = m->vertex[v[1]], *cc = m->vertex[v[2]];
    const double ab[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
    const double ac[3] = {cc[0] - a[0], cc[1] - a[1], cc[2] - a[2]};
    double n[3];
    jd_cross(ab, ac, n);
    const double ap[3] = {p[0] - a[0], p[1] - a[1], p[2] - a[2]};
    const double s = jd_dot(ap, n) / jd_dot(n, n);
    for (int d = 0; d < 3; d++) foot[d] = p[d] - s * n[d];
    return edge_side(a, b, p, n) > 0.0 && edge_side(b, cc, p, n) > 0.0 &&
           edge_side(cc, a, p, n) > 0.0;
}

/* Edge e's parameter from its lower vertex, clamped: -1 (ends at lo), +1 (ends at hi) or 0
 * (open edge, point filled). */
static int edge_param(const jd_mesh *m, int32_t e, const double p[3], double q[3]) {
    const double *lo = m->vertex[m->edge_vertex[e][0]], *hi = m->vertex[m->edge_vertex[e][1]];
    const double u[3] = {hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]};
    const double lp[3] = {p[0] - lo[0], p[1] - lo[1], p[2] - lo[2]};
    const double s = jd_dot(lp, u) / jd_dot(u, u);
    if (!(s > 0.0)) return -1;
    if (!(s < 1.0)) return 1;
    for (int d = 0; d < 3; d++) q[d] = lo[d] + s * u[d];
    return 0;
}

/* The vertex where edge e ends (end -1: its lower vertex, +1: its higher one). */
static int32_t edge_end_vertex(const jd_mesh *m, int32_t e, int end) {
    return m->edge_vertex[e][end < 0 ? 0 : 1];
}

static void set_vertex(const jd_mesh *m, int32_t v, jd_mesh_closest *c) {
    c->kind = JD_MESH_VERTEX;
    c->feature = v;
    for (int d = 0; d < 3; d++) c->point[d] = m->vertex[v][d];
}

/* The open edges are ranked by the distance of their points from the foot of p on the
 * triangle's plane: the same order as by the distance from p (Pythagoras), without the
 * common out-of-plane part that would round small in-plane differences away (a sphere on a
 * flat mesh would take a slanted neighbouring edge by a tie). */
static void boundary_feature(const jd_mesh *m, int32_t t, const double p[3], const double foot[3],
                             jd_mesh_closest *c) {
    int end[3];
    double q[3][3];
    for (int k = 0; k < 3; k++) end[k] = edge_param(m, m->tri_edge[t][k], p, q[k]);
    /* corner k lies on edges k and (k + 2) % 3: the closest feature when both end there */
    for (int k = 0; k < 3; k++) {
        const int32_t v = m->tri_vertex[t][k];
        const int32_t e1 = m->tri_edge[t][k], e2 = m->tri_edge[t][(k + 2) % 3];
        if (end[k] != 0 && end[(k + 2) % 3] != 0 && edge_end_vertex(m, e1, end[k]) == v &&
            edge_end_vertex(m, e2, end[(k + 2) % 3]) == v) {
            set_vertex(m, v, c);
            return;
        }
    }
    int best = -1;
    double best_d2 = INFINITY;
    for (int k = 0; k < 3; k++) {
        if (end[k] != 0) continue;
        const double d2 = dist2_to(foot, q[k]);
        if (best < 0 || d2 < best_d2 ||
            (d2 == best_d2 && m->tri_edge[t][k] < m->tri_edge[t][best])) {
            best = k;
            best_d2 = d2;
        }
    }
    if (best >= 0) {
        c->kind = JD_MESH_EDGE;
        c->feature = m->tri_edge[t][best];
        for (int d = 0; d < 3; d++) c->point[d] = q[best][d];
        return;
    }
    /* no open edge and no vertex at both its edges' ends: round-off at a region boundary; the
     * nearest corner (ties to the lower vertex id) */
    int32_t v = m->tri_vertex[t][0];
    for (int k = 1; k < 3; k++) {
        const int32_t w = m->tri_vertex[t][k];
        const double dw = dist2_to(foot, m->vertex[w]), dv = dist2_to(foot, m->vertex[v]);
        if (dw < dv || (dw == dv && w < v)) v = w;
    }
    set_vertex(m, v, c);
}

void jd_mesh_closest_feature(const jd_mesh *m, int32_t t, const double p[3], jd_mesh_closest *c) {
    c->tri = t;
    double foot[3];
    if (plane_foot(m, t, p, foot)) {
        for (int d = 0; d < 3; d++) c->point[d] = foot[d];
        c->kind = JD_MESH_FACE;
        c->feature = t;
    } else {
        boundary_feature(m, t, p, foot, c);
    }
    c->dist2 = dist2_to(p, c->point);
}

/* ---------------------------------------------------------------------------------------- */
/* The contacts of one sphere                                                                */

static int same_feature(const jd_mesh_closest *a, const jd_mesh_closest *b) {
    return a->kind == b->kind && a->feature == b->feature;
}

static int32_t valence(const jd_mesh *m, const jd_mesh_closest *c) {
    return c->kind == JD_MESH_EDGE ? m->edge_valence[c->feature]
           : c->kind == JD_MESH_VERTEX ? m->vertex_valence[c->feature] : 1;
}

size_t jd_mesh_contacts(const jd_mesh *m, size_t n, const jd_mesh_closest *c, double R,
                        unsigned char *contact) {
    size_t found = 0;
    for (size_t k = 0; k < n; k++) {
        contact[k] = 0;
        if (!(c[k].dist2 < R * R)) continue;
        int32_t reporters = 0;
        int owner = 1;
        for (size_t j = 0; j < n; j++)
            if (same_feature(&c[j], &c[k])) {
                reporters++;
                if (c[j].tri < c[k].tri) owner = 0;
            }
        if (owner && reporters == valence(m, &c[k])) {
            contact[k] = 1;
            found++;
        }
    }
    return found;
}

/* ---------------------------------------------------------------------------------------- */
/* History slots and wall velocity                                                            */

void jd_mesh_match_history(size_t nold, const double (*old_n)[3], size_t nnew,
                           const double (*new_n)[3], int *from) {
    unsigned char used[JD_MESH_SLOTS] = {0};
    for (size_t k = 0; k < nnew; k++) from[k] = -1;
    for (;;) {
        double best = JD_MESH_HISTORY_COS;
        int bk = -1, bj = -1;
        for (size_t k = 0; k < nnew; k++) {
            if (from[k] >= 0) continue;
            for (size_t j = 0; j < nold; j++) {
                if (used[j]) continue;
                const double c = jd_dot(old_n[j], new_n[k]);
                if (c > best) {
                    best = c;
                    bk = (int)k;
                    bj = (int)j;
                }
            }
        }
        if (bk < 0) return;
        from[bk] = bj;
        used[bj] = 1;
    }
}

static void copy3(double to[3], const double from[3]) {
    for (int d = 0; d < 3; d++) to[d] = from[d];
}

int jd_mesh_sphere_contacts(const jd_mesh *m, size_t n, const int32_t *tri, const double x[3],
                            double R, const double *slots, size_t stride, jd_mesh_closest *closest,
                            unsigned char *is_contact, jd_mesh_sphere *out) {
    out->n = 0;
    for (size_t k = 0; k < n; k++) jd_mesh_closest_feature(m, tri[k], x, &closest[k]);
    jd_mesh_contacts(m, n, closest, R, is_contact);
    for (size_t k = 0; k < n; k++) {
        if (!is_contact[k]) continue;
        if (out->n == JD_MESH_SLOTS) return JD_MESH_TOO_MANY;
        if (!jd_geom_mesh(&closest[k], x, R, &out->geom[out->n])) continue;
        out->feature[out->n++] = &closest[k];
    }
    double old_n[JD_MESH_SLOTS][3], new_n[JD_MESH_SLOTS][3];
    for (size_t s = 0; s < JD_MESH_SLOTS; s++) copy3(old_n[s], slots + s * stride);
    for (size_t c = 0; c < out->n; c++) copy3(new_n[c], out->geom[c].n);
    jd_mesh_match_history(JD_MESH_SLOTS, (const double(*)[3])old_n, out->n,
                          (const double(*)[3])new_n, out->from);
    return JD_MESH_OK;
}

void jd_mesh_history_next(const double *slots, size_t stride, const jd_mesh_sphere *s, double *next) {
    for (size_t k = 0; k < JD_MESH_SLOTS * stride; k++) next[k] = 0.0;
    for (size_t c = 0; c < s->n; c++) {
        double *to = next + c * stride;
        copy3(to, s->geom[c].n);
        if (s->from[c] < 0) continue;
        const double *was = slots + (size_t)s->from[c] * stride;
        for (size_t k = 3; k < stride; k++) to[k] = was[k];
    }
}

void jd_mesh_point_velocity(const jd_mesh *m, const jd_mesh_closest *c, const double vnode[3][3],
                            double v[3]) {
    const int32_t *tv = m->tri_vertex[c->tri];
    const double *a = m->vertex[tv[0]], *b = m->vertex[tv[1]], *cc = m->vertex[tv[2]];
    const double e1[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
    const double e2[3] = {cc[0] - a[0], cc[1] - a[1], cc[2] - a[2]};
    const double ep[3] = {c->point[0] - a[0], c->point[1] - a[1], c->point[2] - a[2]};
    const double d11 = jd_dot(e1, e1), d12 = jd_dot(e1, e2), d22 = jd_dot(e2, e2);
    const double dp1 = jd_dot(ep, e1), dp2 = jd_dot(ep, e2);
    const double det = d11 * d22 - d12 * d12;
    const double b1 = (d22 * dp1 - d12 * dp2) / det, b2 = (d11 * dp2 - d12 * dp1) / det;
    for (int d = 0; d < 3; d++)
        v[d] = vnode[0][d] + b1 * (vnode[1][d] - vnode[0][d]) + b2 * (vnode[2][d] - vnode[0][d]);
}
