/*
 * jdem_mesh.h — a sphere against a triangle mesh wall (an STL surface), in the kernel's
 * conventions (jdem_geometry.h): the mesh's topology, the closest feature of one triangle, and
 * the rule that turns a sphere's candidate triangles into contacts without double counting.
 * Both engines call these, so they open the same contacts at the same steps.
 *
 * Pure C11.  No I/O, no allocation (the caller supplies every array), no globals.  Units SI (m).
 *
 * The contact rule.  A mesh is two-sided (as LIGGGHTS' meshes are).  For a sphere centre p each
 * triangle reports its closest feature: its open face (p projects strictly inside it), one of its
 * open edges, or one of its vertices, found with the edge and vertex data of the mesh's tables, so
 * that every triangle sharing an edge or a vertex computes it from the same numbers in the same
 * order (the same bits).  A feature is a contact of the sphere when its distance is below R and
 * every triangle that holds the feature reports it as its closest one: that is, when the
 * feature's point is a local minimum of the distance from p over the surface.  A face has one
 * triangle; an edge has its valence (2 inside a manifold, 1 on the boundary); a vertex its
 * valence.  So a sphere resting on a flat or convex region gets exactly one contact, at its
 * nearest point, wherever it lies (face, edge, vertex), and a sphere in a concave corner gets one
 * contact per face it touches, as it should.  The caller's candidate list must hold every
 * triangle within R of p (a neighbour list with a skin does); an edge or vertex contact then
 * belongs to the lowest-numbered triangle that holds it.
 *
 * Known limit: two faces meeting at a slightly concave crease both count when the sphere touches
 * both, as they would for two plane walls.
 */
#ifndef JDEM_KERNEL_MESH_H
#define JDEM_KERNEL_MESH_H

#include <math.h>
#include <stddef.h>
#include <stdint.h>

#include "jdem_kernel.h"

#ifdef __cplusplus
extern "C" {
#endif

/* The topology of a mesh of ntri triangles: the corners welded into vertices (corners with
 * bitwise-identical coordinates are one vertex) and the edges between them.  Vertex and edge
 * ids follow the lexicographic order of the coordinates and of the vertex-id pairs, so they do
 * not depend on the order in which an engine stores the triangles' corners. */
typedef struct jd_mesh {
    size_t ntri, nvert, nedge;
    double (*vertex)[3];      /* [nvert] vertex coordinates                               [m] */
    int32_t (*tri_vertex)[3]; /* [ntri] the triangle's corners k = 0, 1, 2 as vertex ids      */
    int32_t (*tri_edge)[3];   /* [ntri] edge k joins corners k and (k + 1) % 3               */
    int32_t (*edge_vertex)[2]; /* [nedge] the edge's vertex ids, lower first                  */
    int32_t *edge_valence;    /* [nedge] triangles that hold the edge                         */
    int32_t *vertex_valence;  /* [nvert] triangles that hold the vertex                       */
} jd_mesh;

/* The arrays jd_mesh_build fills, each sized for ntri triangles: vertex[3 ntri],
 * tri_vertex[ntri], tri_edge[ntri], edge_vertex[3 ntri], edge_valence[3 ntri],
 * vertex_valence[3 ntri], and scratch[3 ntri] (int64_t, for the sort). */
typedef struct jd_mesh_storage {
    double (*vertex)[3];
    int32_t (*tri_vertex)[3];
    int32_t (*tri_edge)[3];
    int32_t (*edge_vertex)[2];
    int32_t *edge_valence;
    int32_t *vertex_valence;
    int64_t *scratch;
} jd_mesh_storage;

/* Builds m from the corners of ntri triangles (corner[t][k] [m]) into the arrays of st.
 * Returns JD_MESH_OK, or JD_MESH_DEGENERATE with *bad the first triangle with two welded
 * corners (zero-length edge) or zero area, or JD_MESH_TOO_LARGE when 3 ntri does not fit in
 * int32_t. */
enum { JD_MESH_OK = 0, JD_MESH_DEGENERATE = 1, JD_MESH_TOO_LARGE = 2 };
int jd_mesh_build(size_t ntri, const double (*corner)[3][3], const jd_mesh_storage *st, jd_mesh *m,
                  size_t *bad);

/* The closest feature of one triangle to a point. */
enum { JD_MESH_FACE = 0, JD_MESH_EDGE = 1, JD_MESH_VERTEX = 2 };
typedef struct jd_mesh_closest {
    int32_t tri;      /* the triangle                                                        */
    int kind;         /* JD_MESH_FACE, JD_MESH_EDGE or JD_MESH_VERTEX                         */
    int32_t feature;  /* the triangle's id, the edge id or the vertex id                     */
    double point[3];  /* the closest point of the triangle                                [m] */
    double dist2;     /* squared distance from the point queried                        [m^2] */
} jd_mesh_closest;

/* The closest feature of triangle t of m to p [m].  Face when p projects strictly inside the
 * triangle (the three edge tests > 0); otherwise the edges are tried from their tables (the
 * parameter along edge (lo, hi) from the lower vertex): a vertex is the closest feature only when
 * both of the triangle's edges through it end there, else the open edge whose point is nearest
 * (ties to the lower edge id). */
void jd_mesh_closest_feature(const jd_mesh *m, int32_t t, const double p[3], jd_mesh_closest *c);

/* The contacts among n candidates of one sphere of radius R [m] (c[k] from
 * jd_mesh_closest_feature for every triangle within R of the centre, in any order):
 * contact[k] = 1 when c[k]'s feature is a contact by the rule above and c[k].tri is the
 * lowest-numbered triangle among the candidates reporting it, else 0 (so the result does not
 * depend on the order of the list).  Returns the number of contacts.  O(n^2); n is small. */
size_t jd_mesh_contacts(const jd_mesh *m, size_t n, const jd_mesh_closest *c, double R,
                        unsigned char *contact);

/* Contact history across triangles.  A sphere's contacts with one mesh keep their history in a
 * few slots per sphere (JD_MESH_SLOTS), each holding the contact's normal at its last
 * evaluation next to the law's state.  The contact point moves continuously over a flat or
 * convex region (face -> edge -> face of the next triangle: the feature changes, the normal
 * turns by little per step), so a slot is keyed by its normal, not by a triangle: a contact
 * found now takes the slot whose normal is closest to its own, provided the two normals make
 * less than 60 degrees (cosine above JD_MESH_HISTORY_COS); the pairs are taken in decreasing
 * cosine (ties: lower new index, then lower slot), each slot and each contact at most once.  A
 * concave corner's contacts (normals 60 degrees or more apart) keep separate slots. */
#define JD_MESH_SLOTS 6
#define JD_MESH_HISTORY_COS 0.5

/* from[k] (k < nnew) = the slot j < nold whose normal old_n[j] continues new_n[k] (unit
 * vectors), or -1 (a new contact: fresh history).  Requires nold, nnew <= JD_MESH_SLOTS;
 * an empty slot has normal (0, 0, 0) and is never chosen. */
void jd_mesh_match_history(size_t nold, const double (*old_n)[3], size_t nnew,
                           const double (*new_n)[3], int *from);

/* One sphere's contacts with one mesh, the procedure both engines run per sphere and mesh:
 * each candidate triangle's closest feature (jd_mesh_closest_feature), the contacts among them
 * (jd_mesh_contacts), their geometry (jd_geom_mesh; contacts whose centre lies on the surface
 * are dropped), and the history slot each continues (jd_mesh_match_history).
 *
 * History slots.  A sphere's history with one mesh is JD_MESH_SLOTS slots of `stride` doubles
 * each: the contact's unit normal at its last evaluation (3 doubles; (0, 0, 0): empty slot),
 * then the engine's record of the law's state (stride - 3 doubles). */
typedef struct jd_mesh_sphere {
    size_t n;                                      /* contacts found (<= JD_MESH_SLOTS)     */
    const jd_mesh_closest *feature[JD_MESH_SLOTS]; /* contact c's feature (in closest[])     */
    jd_contact_geom geom[JD_MESH_SLOTS];           /* its geometry; no material fields yet  */
    int from[JD_MESH_SLOTS];                       /* the old slot it continues, or -1      */
} jd_mesh_sphere;

/* The sphere of centre x [m] and radius R [m] against the n candidate triangles tri[] of m
 * (every triangle within R of x, any order), with its history slots `slots` (JD_MESH_SLOTS x
 * stride doubles, layout above).  closest[n] and is_contact[n] are the caller's scratch.
 * Contacts are numbered in the candidates' order.  Returns JD_MESH_OK, or JD_MESH_TOO_MANY when
 * the sphere has more than JD_MESH_SLOTS contacts (out->n then JD_MESH_SLOTS). */
enum { JD_MESH_TOO_MANY = 3 };
int jd_mesh_sphere_contacts(const jd_mesh *m, size_t n, const int32_t *tri, const double x[3],
                            double R, const double *slots, size_t stride, jd_mesh_closest *closest,
                            unsigned char *is_contact, jd_mesh_sphere *out);

/* The sphere's slots after this evaluation, into next (JD_MESH_SLOTS x stride doubles): slot c
 * (c < s->n) holds contact c's normal and the record of the slot it continues (zero for a new
 * contact); the other slots are empty (zero).  The engine then evaluates contact c's law on the
 * record of slot c of next. */
void jd_mesh_history_next(const double *slots, size_t stride, const jd_mesh_sphere *s, double *next);

/* The wall's velocity [m/s] at c's point: the velocities vnode[k] [m/s] of the corners k of
 * triangle c->tri (the order of its corners given to jd_mesh_build) interpolated linearly,
 * v = v0 + b1 (v1 - v0) + b2 (v2 - v0) with (b1, b2) the point's barycentric coordinates, so a
 * translating mesh (three equal corner velocities) gives that velocity exactly and a rigid
 * rotation the rotation's velocity at the point. */
void jd_mesh_point_velocity(const jd_mesh *m, const jd_mesh_closest *c, const double vnode[3][3],
                            double v[3]);

/* The geometric fields of jd_contact_geom (jdem_geometry.h conventions: a the particle, b the
 * wall) for a contact of a sphere of centre x [m] and radius R [m] with feature c: n from the
 * centre towards the point, delta = R - |point - x|, ra = (R - delta) n, rb = 0, r_roll = R.
 * Returns 1, or 0 when the centre lies on the surface (no normal) or there is no overlap. */
static inline int jd_geom_mesh(const jd_mesh_closest *c, const double x[3], double R,
                               jd_contact_geom *g) {
    const double d = sqrt(c->dist2);
    const double dl = R - d;
    if (!(d > 0.0) || !(dl > 0.0)) return 0;
    g->delta = dl;
    const double la = R - dl;
    for (int k = 0; k < 3; k++) {
        g->n[k] = (c->point[k] - x[k]) / d;
        g->ra[k] = la * g->n[k];
        g->rb[k] = 0.0;
    }
    g->r_roll = R;
    return 1;
}

#ifdef __cplusplus
}
#endif

#endif
