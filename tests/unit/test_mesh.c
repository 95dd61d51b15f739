/* test_mesh.c — the mesh wall's topology and contact rule (kernel/jdem_mesh.h) against closed
 * forms: Euler's formula on a closed cube, the distance to a plane, a line and a point, and an
 * independent brute-force distance to a triangle. */
#include "unit.h"

#include <stdlib.h>
#include <string.h>

#include "jdem_mesh.h"

#define MAXTRI 512
#define JD_TEST_PI 3.14159265358979323846

typedef struct built {
    double vertex[3 * MAXTRI][3];
    int32_t tri_vertex[MAXTRI][3], tri_edge[MAXTRI][3], edge_vertex[3 * MAXTRI][2];
    int32_t edge_valence[3 * MAXTRI], vertex_valence[3 * MAXTRI];
    int64_t scratch[3 * MAXTRI];
    jd_mesh m;
} built;

static built *build(size_t ntri, const double (*corner)[3][3]) {
    built *b = calloc(1, sizeof *b);
    assert_non_null(b);
    const jd_mesh_storage st = {b->vertex, b->tri_vertex, b->tri_edge, b->edge_vertex,
                                b->edge_valence, b->vertex_valence, b->scratch};
    size_t bad = 0;
    assert_int_equal(jd_mesh_build(ntri, corner, &st, &b->m, &bad), JD_MESH_OK);
    return b;
}

static void set3(double p[3], double x, double y, double z) {
    p[0] = x;
    p[1] = y;
    p[2] = z;
}

/* The closed unit cube [0, 1]^3, two triangles per face (corner c at (c & 1, c >> 1 & 1, c >> 2)). */
static void unit_cube(double tri[12][3][3]) {
    static const int q[6][4] = {{0, 1, 3, 2}, {4, 6, 7, 5}, {0, 4, 5, 1},
                                {2, 3, 7, 6}, {0, 2, 6, 4}, {1, 5, 7, 3}};
    for (int f = 0; f < 6; f++)
        for (int h = 0; h < 2; h++) {
            const int idx[3] = {q[f][0], q[f][1 + h], q[f][2 + h]};
            for (int k = 0; k < 3; k++)
                set3(tri[2 * f + h][k], idx[k] & 1, (idx[k] >> 1) & 1, (idx[k] >> 2) & 1);
        }
}

/* An n x n grid of unit squares in the plane z = 0, two triangles each, alternating diagonals. */
static size_t grid(int n, double (*tri)[3][3]) {
    size_t t = 0;
    for (int i = 0; i < n; i++)
        for (int j = 0; j < n; j++) {
            double c[4][3];
            set3(c[0], i, j, 0);
            set3(c[1], i + 1, j, 0);
            set3(c[2], i + 1, j + 1, 0);
            set3(c[3], i, j + 1, 0);
            const int d = (i + j) % 2;
            const int a[2][3] = {{0, 1, 2 + d}, {d, 2, 3}};
            for (int h = 0; h < 2; h++, t++)
                for (int k = 0; k < 3; k++) memcpy(tri[t][k], c[a[h][k]], sizeof c[0]);
        }
    return t;
}

/* All candidates of a sphere (every triangle), its contacts. */
static size_t contacts_of(const jd_mesh *m, const double p[3], double R, jd_mesh_closest *c,
                          unsigned char *contact) {
    for (size_t t = 0; t < m->ntri; t++) jd_mesh_closest_feature(m, (int32_t)t, p, &c[t]);
    return jd_mesh_contacts(m, m->ntri, c, R, contact);
}

static double urand(unsigned *s) {
    *s = *s * 1103515245u + 12345u;
    return (double)((*s >> 8) & 0xFFFFFF) / (double)0x1000000;
}

/* A closed cube: V - E + F = 2, every edge shared by two triangles, 36 corners in all. */
static void cube_topology_obeys_euler(void **state) {
    (void)state;
    double tri[12][3][3];
    unit_cube(tri);
    built *b = build(12, (const double(*)[3][3])tri);
    assert_int_equal(b->m.nvert, 8);
    assert_int_equal(b->m.nedge, 18);
    assert_int_equal((long)b->m.nvert - (long)b->m.nedge + 12, 2);
    int corners = 0;
    for (size_t e = 0; e < b->m.nedge; e++) assert_int_equal(b->m.edge_valence[e], 2);
    for (size_t v = 0; v < b->m.nvert; v++) corners += b->m.vertex_valence[v];
    assert_int_equal(corners, 36);
    /* the same mesh with the triangles reversed and their corners rotated: the same vertices */
    double rev[12][3][3];
    for (int t = 0; t < 12; t++)
        for (int k = 0; k < 3; k++) memcpy(rev[11 - t][k], tri[t][(k + 1) % 3], sizeof tri[t][k]);
    built *r = build(12, (const double(*)[3][3])rev);
    assert_memory_equal(r->vertex, b->vertex, 8 * sizeof b->vertex[0]);
    assert_memory_equal(r->edge_vertex, b->edge_vertex, 18 * sizeof b->edge_vertex[0]);
    free(b);
    free(r);
}

/* A sphere over a flat grid has exactly one contact, at the foot of the perpendicular, wherever
 * its centre lies: over a face, an edge, a vertex (grid points and half-grid points included). */
static void flat_grid_gives_one_contact_at_the_foot(void **state) {
    (void)state;
    double (*tri)[3][3] = malloc(32 * sizeof *tri);
    const size_t n = grid(4, tri);
    built *b = build(n, (const double(*)[3][3])tri);
    jd_mesh_closest c[32];
    unsigned char contact[32];
    unsigned seed = 7;
    const double R = 0.3;
    for (int trial = 0; trial < 2000; trial++) {
        double p[3];
        if (trial < 81) /* every grid point and half point of the inner 2 x 2 squares */
            set3(p, 1.0 + 0.25 * (trial % 9), 1.0 + 0.25 * (trial / 9), 0.1);
        else
            set3(p, 0.5 + 3.0 * urand(&seed), 0.5 + 3.0 * urand(&seed), 0.29 * urand(&seed) + 0.005);
        if (trial % 2) p[2] = -p[2]; /* two-sided */
        const size_t found = contacts_of(&b->m, p, R, c, contact);
        assert_int_equal(found, 1);
        for (size_t t = 0; t < n; t++)
            if (contact[t]) {
                assert_rel(c[t].point[0], p[0], 1e-14);
                assert_rel(c[t].point[1], p[1], 1e-14);
                assert_rel(c[t].point[2], 0.0, 1e-14);
                assert_rel(sqrt(c[t].dist2), fabs(p[2]), 1e-12);
            }
    }
    free(b);
    free(tri);
}

/* A roof: two planes meeting at the ridge x = 0, z = 0 at a convex angle.  Above the ridge,
 * outside both faces' prisms, one contact at the ridge at the distance to the line; over a face
 * near the ridge, one contact on that face at the distance to its plane. */
static void convex_ridge_gives_one_contact(void **state) {
    (void)state;
    const double s = 0.5; /* slope: z = -s |x| */
    double tri[4][3][3];
    double c4[6][3];
    set3(c4[0], -1, 0, -s);
    set3(c4[1], 0, 0, 0);
    set3(c4[2], 1, 0, -s);
    set3(c4[3], -1, 1, -s);
    set3(c4[4], 0, 1, 0);
    set3(c4[5], 1, 1, -s);
    const int t[4][3] = {{0, 1, 4}, {0, 4, 3}, {1, 2, 5}, {1, 5, 4}};
    for (int k = 0; k < 4; k++)
        for (int j = 0; j < 3; j++) memcpy(tri[k][j], c4[t[k][j]], sizeof c4[0]);
    built *b = build(4, (const double(*)[3][3])tri);
    jd_mesh_closest c[4];
    unsigned char contact[4];
    double p[3];
    set3(p, 0.02, 0.4, 0.1); /* in the ridge's region: |x| < s z */
    assert_int_equal(contacts_of(&b->m, p, 0.2, c, contact), 1);
    for (int k = 0; k < 4; k++)
        if (contact[k]) {
            assert_int_equal(c[k].kind, JD_MESH_EDGE);
            assert_rel(sqrt(c[k].dist2), sqrt(0.02 * 0.02 + 0.1 * 0.1), 1e-14);
        }
    set3(p, 0.3, 0.4, 0.1); /* over the right face */
    assert_int_equal(contacts_of(&b->m, p, 0.3, c, contact), 1);
    for (int k = 0; k < 4; k++)
        if (contact[k]) {
            assert_int_equal(c[k].kind, JD_MESH_FACE);
            /* distance to the plane s x + z = 0 */
            assert_rel(sqrt(c[k].dist2), (s * 0.3 + 0.1) / sqrt(1 + s * s), 1e-14);
        }
    free(b);
}

/* A concave corner (floor z = 0 and wall x = 0): a sphere touching both has two face contacts,
 * at its distances to the two planes. */
static void concave_corner_gives_one_contact_per_face(void **state) {
    (void)state;
    double tri[4][3][3];
    double c6[6][3];
    set3(c6[0], 0, 0, 0);
    set3(c6[1], 1, 0, 0);
    set3(c6[2], 1, 1, 0);
    set3(c6[3], 0, 1, 0);
    set3(c6[4], 0, 0, 1);
    set3(c6[5], 0, 1, 1);
    const int t[4][3] = {{0, 1, 2}, {0, 2, 3}, {0, 3, 5}, {0, 5, 4}};
    for (int k = 0; k < 4; k++)
        for (int j = 0; j < 3; j++) memcpy(tri[k][j], c6[t[k][j]], sizeof c6[0]);
    built *b = build(4, (const double(*)[3][3])tri);
    jd_mesh_closest c[4];
    unsigned char contact[4];
    double p[3];
    set3(p, 0.08, 0.37, 0.06);
    assert_int_equal(contacts_of(&b->m, p, 0.1, c, contact), 2);
    double d[2];
    int n = 0;
    for (int k = 0; k < 4; k++)
        if (contact[k]) {
            assert_int_equal(c[k].kind, JD_MESH_FACE);
            d[n++] = sqrt(c[k].dist2);
        }
    assert_rel(fmin(d[0], d[1]), 0.06, 1e-14);
    assert_rel(fmax(d[0], d[1]), 0.08, 1e-14);
    free(b);
}

/* Outside a closed cube, beyond a corner along its diagonal: one vertex contact at the corner. */
static void convex_corner_gives_one_vertex_contact(void **state) {
    (void)state;
    double tri[12][3][3];
    unit_cube(tri);
    built *b = build(12, (const double(*)[3][3])tri);
    jd_mesh_closest c[12];
    unsigned char contact[12];
    double p[3];
    set3(p, 1.05, 1.04, 1.03);
    assert_int_equal(contacts_of(&b->m, p, 0.1, c, contact), 1);
    for (int k = 0; k < 12; k++)
        if (contact[k]) {
            assert_int_equal(c[k].kind, JD_MESH_VERTEX);
            assert_rel(sqrt(c[k].dist2), sqrt(0.05 * 0.05 + 0.04 * 0.04 + 0.03 * 0.03), 1e-14);
        }
    /* beyond an edge (x, z > 1, 0 < y < 1): one edge contact */
    set3(p, 1.05, 0.3, 1.02);
    assert_int_equal(contacts_of(&b->m, p, 0.1, c, contact), 1);
    for (int k = 0; k < 12; k++)
        if (contact[k]) {
            assert_int_equal(c[k].kind, JD_MESH_EDGE);
            assert_rel(sqrt(c[k].dist2), sqrt(0.05 * 0.05 + 0.02 * 0.02), 1e-14);
        }
    free(b);
}

/* Independent reference: the distance to a triangle as the least of the distance to its plane
 * (when the foot is inside, by barycentric coordinates) and to its three segments. */
static double segment_d2(const double p[3], const double a[3], const double b[3]) {
    double ab[3], ap[3];
    for (int d = 0; d < 3; d++) {
        ab[d] = b[d] - a[d];
        ap[d] = p[d] - a[d];
    }
    double t = jd_dot(ap, ab) / jd_dot(ab, ab);
    t = t < 0 ? 0 : t > 1 ? 1 : t;
    double r = 0;
    for (int d = 0; d < 3; d++) r += (ap[d] - t * ab[d]) * (ap[d] - t * ab[d]);
    return r;
}

static double triangle_d2(const double p[3], const double (*v)[3]) {
    double e1[3], e2[3], w[3];
    for (int d = 0; d < 3; d++) {
        e1[d] = v[1][d] - v[0][d];
        e2[d] = v[2][d] - v[0][d];
        w[d] = p[d] - v[0][d];
    }
    const double a = jd_dot(e1, e1), bb = jd_dot(e1, e2), c = jd_dot(e2, e2);
    const double d1 = jd_dot(w, e1), d2 = jd_dot(w, e2), det = a * c - bb * bb;
    const double u = (c * d1 - bb * d2) / det, s = (a * d2 - bb * d1) / det;
    double best = fmin(segment_d2(p, v[0], v[1]), fmin(segment_d2(p, v[1], v[2]), segment_d2(p, v[2], v[0])));
    if (u >= 0 && s >= 0 && u + s <= 1) {
        double r = 0;
        for (int d = 0; d < 3; d++) {
            const double q = w[d] - u * e1[d] - s * e2[d];
            r += q * q;
        }
        best = fmin(best, r);
    }
    return best;
}

static void closest_feature_matches_brute_force(void **state) {
    (void)state;
    unsigned seed = 11;
    for (int trial = 0; trial < 5000; trial++) {
        double tri[1][3][3];
        for (int k = 0; k < 3; k++)
            for (int d = 0; d < 3; d++) tri[0][k][d] = 2.0 * urand(&seed) - 1.0;
        built *b = build(1, (const double(*)[3][3])tri);
        double p[3];
        for (int d = 0; d < 3; d++) p[d] = 3.0 * urand(&seed) - 1.5;
        jd_mesh_closest c;
        jd_mesh_closest_feature(&b->m, 0, p, &c);
        assert_rel(c.dist2, triangle_d2(p, (const double(*)[3])tri[0]), 1e-9);
        free(b);
    }
}

/* The contacts do not depend on the order of the candidate list. */
static void contacts_do_not_depend_on_candidate_order(void **state) {
    (void)state;
    double (*tri)[3][3] = malloc(32 * sizeof *tri);
    const size_t n = grid(4, tri);
    built *b = build(n, (const double(*)[3][3])tri);
    jd_mesh_closest c[32], rc[32];
    unsigned char contact[32], rcontact[32];
    double p[3];
    set3(p, 2.0, 2.0, 0.1); /* over an interior vertex: 6 or 8 triangles report it */
    contacts_of(&b->m, p, 0.3, c, contact);
    for (size_t k = 0; k < n; k++) rc[k] = c[n - 1 - k];
    assert_int_equal(jd_mesh_contacts(&b->m, n, rc, 0.3, rcontact), 1);
    for (size_t k = 0; k < n; k++) assert_int_equal(rcontact[k], contact[n - 1 - k]);
    free(b);
    free(tri);
}

static void degenerate_triangles_are_named(void **state) {
    (void)state;
    double tri[2][3][3] = {{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, {{0, 0, 0}, {1, 1, 0}, {2, 2, 0}}};
    built *b = calloc(1, sizeof *b);
    const jd_mesh_storage st = {b->vertex, b->tri_vertex, b->tri_edge, b->edge_vertex,
                                b->edge_valence, b->vertex_valence, b->scratch};
    size_t bad = 99;
    assert_int_equal(jd_mesh_build(2, (const double(*)[3][3])tri, &st, &b->m, &bad),
                     JD_MESH_DEGENERATE);
    assert_int_equal(bad, 1);
    free(b);
}

/* jd_mesh_sphere_contacts over a flat grid: one contact at the foot (delta = R - h, the normal
 * straight down), continuing the old slot whose normal it shares, whatever slot that was; and
 * jd_mesh_history_next moves that slot's record to slot 0 and empties the rest. */
static void sphere_contacts_continue_the_matching_slot(void **state) {
    (void)state;
    double (*tri)[3][3] = malloc(32 * sizeof *tri);
    const size_t n = grid(4, tri);
    built *b = build(n, (const double(*)[3][3])tri);
    int32_t cand[32];
    for (size_t k = 0; k < n; k++) cand[k] = (int32_t)(n - 1 - k);
    enum { STRIDE = 4 };
    double slots[JD_MESH_SLOTS * STRIDE] = {0}, next[JD_MESH_SLOTS * STRIDE];
    slots[2 * STRIDE + 2] = -1.0; /* slot 2: normal (0, 0, -1), record 7 */
    slots[2 * STRIDE + 3] = 7.0;
    slots[4 * STRIDE + 0] = 1.0;  /* slot 4: normal (1, 0, 0), record 5 */
    slots[4 * STRIDE + 3] = 5.0;
    jd_mesh_closest c[32];
    unsigned char contact[32];
    jd_mesh_sphere sc;
    const double p[3] = {1.5, 1.0, 0.1}; /* over an interior edge */
    assert_int_equal(jd_mesh_sphere_contacts(&b->m, n, cand, p, 0.3, slots, STRIDE, c, contact, &sc),
                     JD_MESH_OK);
    assert_int_equal(sc.n, 1);
    assert_rel(sc.geom[0].delta, 0.2, 1e-15);
    assert_rel(sc.geom[0].n[2], -1.0, 1e-15);
    assert_int_equal(sc.from[0], 2);
    jd_mesh_history_next(slots, STRIDE, &sc, next);
    const double want[STRIDE] = {0.0, 0.0, -1.0, 7.0};
    assert_memory_equal(next, want, sizeof want);
    for (size_t k = STRIDE; k < JD_MESH_SLOTS * STRIDE; k++) assert_true(next[k] == 0.0);
    free(b);
    free(tri);
}

/* A concave corner (a floor face and a wall face at 90 degrees): two contacts, each with its own
 * distance (R - h), each continuing the slot of its own normal. */
static void corner_contacts_keep_separate_slots(void **state) {
    (void)state;
    const double tri[2][3][3] = {{{0, 0, 0}, {2, 0, 0}, {0, 2, 0}}, {{0, 0, 0}, {0, 2, 0}, {0, 0, 2}}};
    built *b = build(2, tri);
    const int32_t cand[2] = {0, 1};
    enum { STRIDE = 4 };
    double slots[JD_MESH_SLOTS * STRIDE] = {0};
    slots[0 * STRIDE + 0] = -1.0; /* slot 0: the wall's normal (-1, 0, 0), record 5 */
    slots[0 * STRIDE + 3] = 5.0;
    slots[1 * STRIDE + 2] = -1.0; /* slot 1: the floor's normal (0, 0, -1), record 6 */
    slots[1 * STRIDE + 3] = 6.0;
    jd_mesh_closest c[2];
    unsigned char contact[2];
    jd_mesh_sphere sc;
    const double p[3] = {0.25, 0.5, 0.2};
    assert_int_equal(jd_mesh_sphere_contacts(&b->m, 2, cand, p, 0.3, slots, STRIDE, c, contact, &sc),
                     JD_MESH_OK);
    assert_int_equal(sc.n, 2);
    assert_int_equal(sc.feature[0]->tri, 0);
    assert_rel(sc.geom[0].delta, 0.3 - 0.2, 1e-15);
    assert_rel(sc.geom[1].delta, 0.3 - 0.25, 1e-15);
    assert_int_equal(sc.from[0], 1);
    assert_int_equal(sc.from[1], 0);
    double next[JD_MESH_SLOTS * STRIDE];
    jd_mesh_history_next(slots, STRIDE, &sc, next);
    assert_true(next[3] == 6.0 && next[STRIDE + 3] == 5.0 && next[STRIDE] == -1.0);
    free(b);
}

/* jd_geom_mesh: the normal towards the wall, the overlap, the lever arm. */
static void geometry_of_a_face_contact(void **state) {
    (void)state;
    const jd_mesh_closest c = {.tri = 0, .kind = JD_MESH_FACE, .feature = 0,
                               .point = {0.2, 0.3, 0.0}, .dist2 = 0.04 * 0.04};
    const double x[3] = {0.2, 0.3, 0.04};
    jd_contact_geom g;
    assert_int_equal(jd_geom_mesh(&c, x, 0.05, &g), 1);
    assert_rel(g.n[2], -1.0, 1e-15);
    assert_rel(g.delta, 0.01, 1e-12);
    assert_rel(g.ra[2], -0.04, 1e-12);
    assert_rel(g.r_roll, 0.05, 0.0);
    const jd_mesh_closest far = {.point = {0.2, 0.3, 0.0}, .dist2 = 0.06 * 0.06};
    assert_int_equal(jd_geom_mesh(&far, x, 0.05, &g), 0);
}

/* History slots: a normal turned by a small angle keeps its slot, the two faces of a concave
 * corner (90 degrees apart) keep theirs even listed in the other order, and a normal 60 degrees
 * or more from every slot starts afresh (cos 60 = JD_MESH_HISTORY_COS). */
static void history_follows_the_normal(void **state) {
    (void)state;
    const double a = 0.01;
    const double old_n[3][3] = {{0, 0, -1}, {-1, 0, 0}, {0, 0, 0}};
    const double new_n[3][3] = {{-1, 0, 0}, {sin(a), 0, -cos(a)}, {0, -1, 0}};
    int from[3];
    jd_mesh_match_history(3, old_n, 3, new_n, from);
    assert_int_equal(from[0], 1);
    assert_int_equal(from[1], 0);
    assert_int_equal(from[2], -1);
    const double at60[1][3] = {{sin((JD_TEST_PI / 3.0) + 1e-9), 0, -cos((JD_TEST_PI / 3.0) + 1e-9)}};
    const double at59[1][3] = {{sin((JD_TEST_PI / 3.0) - 1e-3), 0, -cos((JD_TEST_PI / 3.0) - 1e-3)}};
    jd_mesh_match_history(1, old_n, 1, at60, from);
    assert_int_equal(from[0], -1);
    jd_mesh_match_history(1, old_n, 1, at59, from);
    assert_int_equal(from[0], 0);
    /* one slot, two candidates: the closer normal takes it, whatever the order */
    const double two[2][3] = {{sin(0.3), 0, -cos(0.3)}, {sin(0.1), 0, -cos(0.1)}};
    jd_mesh_match_history(1, old_n, 2, two, from);
    assert_int_equal(from[0], -1);
    assert_int_equal(from[1], 0);
}

/* The wall velocity at a contact point: a translation exactly, a rigid rotation as omega x
 * (point - centre) of the closed form. */
static void wall_velocity_at_the_point(void **state) {
    (void)state;
    const double tri[1][3][3] = {{{0.1, 0.2, 0.3}, {1.3, 0.1, 0.5}, {0.4, 1.1, -0.2}}};
    built *b = build(1, tri);
    jd_mesh_closest c;
    const double p[3] = {0.6, 0.46, 0.25};
    jd_mesh_closest_feature(&b->m, 0, p, &c);
    assert_int_equal(c.kind, JD_MESH_FACE);
    const double u[3] = {0.3, -1.7, 2.9};
    const double same[3][3] = {{0.3, -1.7, 2.9}, {0.3, -1.7, 2.9}, {0.3, -1.7, 2.9}};
    double v[3];
    jd_mesh_point_velocity(&b->m, &c, same, v);
    for (int d = 0; d < 3; d++) assert_true(v[d] == u[d]);
    const double w[3] = {0.7, -0.2, 1.9}, o[3] = {-0.3, 0.8, 0.1};
    double vn[3][3], r[3], ref[3];
    for (int k = 0; k < 3; k++) {
        for (int d = 0; d < 3; d++) r[d] = tri[0][k][d] - o[d];
        jd_cross(w, r, vn[k]);
    }
    for (int d = 0; d < 3; d++) r[d] = c.point[d] - o[d];
    jd_cross(w, r, ref);
    jd_mesh_point_velocity(&b->m, &c, (const double(*)[3])vn, v);
    for (int d = 0; d < 3; d++) assert_true(fabs(v[d] - ref[d]) < 1e-14);
    free(b);
}

/* A centre a hair off a grid vertex, along a grid line: the distances to that line's edge and
 * to a diagonal edge through the vertex differ by far less than the rounding of the squared
 * height, yet the contact must be the foot of the perpendicular, exactly, as for a plane. */
static void near_vertex_the_contact_is_the_exact_foot(void **state) {
    (void)state;
    double(*tri)[3][3] = calloc(2 * 16, sizeof *tri);
    const size_t n = grid(4, tri);
    built *b = build(n, (const double(*)[3][3])tri);
    jd_mesh_closest c[32];
    unsigned char contact[32];
    const double off[4][2] = {{1e-9, 0}, {-1e-9, 0}, {0, 1e-9}, {0, -1e-9}};
    for (int k = 0; k < 4; k++) {
        const double p[3] = {2.0 + off[k][0], 2.0 + off[k][1], 0.4};
        assert_int_equal(contacts_of(&b->m, p, 0.5, c, contact), 1);
        for (size_t t = 0; t < n; t++)
            if (contact[t]) {
                assert_true(c[t].point[0] == p[0] && c[t].point[1] == p[1] && c[t].point[2] == 0.0);
                assert_true(c[t].dist2 == 0.4 * 0.4);
            }
    }
    free(b);
    free(tri);
}

int run_mesh_tests(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(cube_topology_obeys_euler),
        cmocka_unit_test(flat_grid_gives_one_contact_at_the_foot),
        cmocka_unit_test(convex_ridge_gives_one_contact),
        cmocka_unit_test(concave_corner_gives_one_contact_per_face),
        cmocka_unit_test(convex_corner_gives_one_vertex_contact),
        cmocka_unit_test(closest_feature_matches_brute_force),
        cmocka_unit_test(contacts_do_not_depend_on_candidate_order),
        cmocka_unit_test(degenerate_triangles_are_named),
        cmocka_unit_test(sphere_contacts_continue_the_matching_slot),
        cmocka_unit_test(corner_contacts_keep_separate_slots),
        cmocka_unit_test(geometry_of_a_face_contact),
        cmocka_unit_test(history_follows_the_normal),
        cmocka_unit_test(near_vertex_the_contact_is_the_exact_foot),
        cmocka_unit_test(wall_velocity_at_the_point),
    };
    return cmocka_run_group_tests_name("mesh", tests, NULL, NULL);
}
