/*
 * jdem_geometry.h — contact detection geometry shared by both engines: sphere–sphere, sphere vs
 * finite plane (the seed's four-corner walls, Sec. 2.7.1) and sphere vs finite cylinder.
 * Pure C11, no I/O, no allocation, no globals.  Fills the geometric part of jd_contact_geom
 * (n, delta, ra, rb, r_roll); the engine adds k_n, m_eff and i_eff, which depend on materials.
 * Conventions as in jdem_kernel.h: body a is the particle (or the first sphere), n points a -> b.
 */
#ifndef JDEM_GEOMETRY_H
#define JDEM_GEOMETRY_H

#include "jdem_kernel.h"

#ifdef __cplusplus
extern "C" {
#endif

/* A finite planar quadrilateral wall. */
typedef struct jd_plane {
    double p[4][3]; /* corners, counter-clockwise seen from the active side      [m] */
    double n[3];    /* unit normal of the active side: (P2-P1) x (P3-P1) / |..|  [-] */
} jd_plane;

/* A finite cylinder: axis segment a0 -> a1, radius rc. */
typedef struct jd_cylinder {
    double a0[3], a1[3]; /* axis end points                                       [m] */
    double rc;           /* radius                                                [m] */
    int inside;          /* 0: contact on the outer surface (an obstacle); 1: a container */
} jd_cylinder;

enum { JD_GEOM_OK = 0, JD_GEOM_DEGENERATE = 1, JD_GEOM_NOT_PLANAR = 2 };

/* Set up a plane from four corners: computes the unit normal and checks that the corners are
 * not collinear and lie in one plane (relative tolerance rel_tol of the wall size).
 * Returns JD_GEOM_OK, JD_GEOM_DEGENERATE or JD_GEOM_NOT_PLANAR. */
int jd_plane_init(jd_plane *w, const double corners[4][3], double rel_tol);

/* Translate a wall rigidly by d [m] (moving walls). */
void jd_plane_translate(jd_plane *w, const double d[3]);
void jd_cylinder_translate(jd_cylinder *c, const double d[3]);

/* Sphere a (centre xa, radius Ra) against sphere b.  Returns 1 and fills n, delta, ra, rb,
 * r_roll when they overlap (d^2 < (Ra+Rb)^2, the LIGGGHTS criterion), else 0. */
static inline int jd_geom_spheres(const double xa[3], double Ra, const double xb[3], double Rb,
                                  jd_contact_geom *g) {
    const double dx = xb[0] - xa[0], dy = xb[1] - xa[1], dz = xb[2] - xa[2];
    const double rsq = dx * dx + dy * dy + dz * dz;
    const double radsum = Ra + Rb;
    if (rsq >= radsum * radsum) return 0;
    const double r = sqrt(rsq);
    const double rinv = 1.0 / r;
    g->n[0] = dx * rinv;
    g->n[1] = dy * rinv;
    g->n[2] = dz * rinv;
    g->delta = radsum - r;
    const double la = Ra - 0.5 * g->delta; /* x_C = x_a + (R_a - delta/2) n */
    for (int d = 0; d < 3; d++) {
        g->ra[d] = la * g->n[d];
        g->rb[d] = g->ra[d] - (xb[d] - xa[d]);
    }
    g->r_roll = Ra * Rb / radsum;
    return 1;
}

/* Sphere (centre x, radius R) against a finite plane, active side only: contact when the signed
 * distance s = n_w.(x - P1) satisfies 0 < s < R and the projection x_C = x - s n_w lies inside the
 * quadrilateral (eq. 36 with a unit normal; the inside test uses cross products, erratum 11).
 * Contacts with the edges and corners of the quadrilateral are not modelled.  n = -n_w. */
static inline int jd_geom_plane(const jd_plane *w, const double x[3], double R, jd_contact_geom *g) {
    double rel[3] = {x[0] - w->p[0][0], x[1] - w->p[0][1], x[2] - w->p[0][2]};
    const double s = jd_dot(w->n, rel);
    if (!(s > 0.0 && s < R)) return 0;
    double xc[3];
    for (int d = 0; d < 3; d++) xc[d] = x[d] - s * w->n[d];
    for (int k = 0; k < 4; k++) {
        const double *p0 = w->p[k], *p1 = w->p[(k + 1) & 3];
        const double e[3] = {p1[0] - p0[0], p1[1] - p0[1], p1[2] - p0[2]};
        const double c[3] = {xc[0] - p0[0], xc[1] - p0[1], xc[2] - p0[2]};
        double cr[3];
        jd_cross(e, c, cr);
        if (jd_dot(cr, w->n) < 0.0) return 0;
    }
    for (int d = 0; d < 3; d++) {
        g->n[d] = -w->n[d];
        g->ra[d] = xc[d] - x[d];
        g->rb[d] = 0.0;
    }
    g->delta = R - s;
    g->r_roll = R;
    return 1;
}

/* Sphere against a finite cylinder: the centre's projection onto the axis must lie within the
 * segment.  Outside: delta = R + rc - d, n from the centre towards the axis.  Inside (container):
 * delta = d + R - rc, n from the axis through the centre.  The contact point is on the cylinder
 * surface along n. */
static inline int jd_geom_cylinder(const jd_cylinder *c, const double x[3], double R,
                                   jd_contact_geom *g) {
    const double ax[3] = {c->a1[0] - c->a0[0], c->a1[1] - c->a0[1], c->a1[2] - c->a0[2]};
    const double rel[3] = {x[0] - c->a0[0], x[1] - c->a0[1], x[2] - c->a0[2]};
    const double len2 = jd_dot(ax, ax);
    const double t = jd_dot(rel, ax);
    if (t < 0.0 || t > len2) return 0;
    const double f = t / len2;
    double radial[3]; /* from the axis to the centre */
    for (int d = 0; d < 3; d++) radial[d] = rel[d] - f * ax[d];
    const double dist = sqrt(jd_dot(radial, radial));
    double delta;
    if (c->inside) {
        delta = dist + R - c->rc;
        if (!(delta > 0.0) || dist == 0.0) return 0;
        for (int d = 0; d < 3; d++) g->n[d] = radial[d] / dist;
    } else {
        delta = R + c->rc - dist;
        if (!(delta > 0.0) || dist == 0.0) return 0;
        for (int d = 0; d < 3; d++) g->n[d] = -radial[d] / dist;
    }
    g->delta = delta;
    for (int d = 0; d < 3; d++) {
        g->ra[d] = (R - delta) * g->n[d];
        g->rb[d] = 0.0;
    }
    g->r_roll = R;
    return 1;
}

#ifdef __cplusplus
}
#endif
#endif /* JDEM_GEOMETRY_H */
