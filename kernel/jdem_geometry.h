/*
 * jdem_geometry.h — contact geometry of a sphere against a sphere, a finite planar
 * quadrilateral and a finite cylinder, in the kernel's conventions (jdem_kernel.h): the single
 * source of the geometry that both engines feed to jd_contact().
 *
 * Pure C11. No I/O, no allocation, no globals.  Units SI (m).  The per-candidate tests are
 * `static inline` (they run in the force loops); set-up (plane normals) is in jdem_geometry.c.
 *
 * Each test fills the geometric fields of jd_contact_geom — n (unit normal from a to b), delta
 * (overlap > 0), ra = x_C - x_a, rb = x_C - x_b, r_roll — and leaves the material fields
 * (k_n, m_eff, i_eff) to the engine.  For a wall contact a is the particle and b the wall:
 * rb = 0 (the kernel ignores it since w_b = 0), r_roll = R, and the contact point is the wall
 * point nearest to the centre, x_C = x + (R - delta) n.
 *
 * Moving walls: the engine translates the wall (corners / axis end points) before the test.
 *
 * Both engines call these functions, so they open and close contacts at the same steps and
 * feed the kernel bit-identical geometry.
 */
#ifndef JDEM_KERNEL_GEOMETRY_H
#define JDEM_KERNEL_GEOMETRY_H

#include <math.h>

#include "jdem_kernel.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Results of the set-up functions. */
enum {
    JD_GEOM_OK = 0,
    JD_GEOM_DEGENERATE = 1, /* zero-area plane (P1, P2, P3 collinear) or zero-length axis */
    JD_GEOM_NOT_PLANAR = 2  /* P4 is off the plane of P1, P2, P3 by more than the tolerance */
};

/* ------------------------------------------------------------------------------------------ */
/* Sphere–sphere                                                                               */
/* ------------------------------------------------------------------------------------------ */

/* Rolling radius of two spheres R_a R_b/(R_a + R_b) [m]. */
static inline double jd_rolling_radius(double Ra, double Rb) { return Ra * Rb / (Ra + Rb); }

/* The geometric fields of spheres a (radius Ra [m]) and b (Rb) whose centres are dx = xb - xa
 * apart [m], rsq = |dx|^2 [m^2]: r = sqrt(rsq), n = dx * (1/r), delta = Ra + Rb - r,
 * ra = (Ra - delta/2) n (= x_C - xa), rb = ra - dx (= x_C - xb).  Returns 1 when delta > 0 and
 * r > 0; otherwise 0, and g holds finite values of no meaning.  No branches (an engine may
 * evaluate a batch of candidates in SIMD lanes). */
static inline int jd_geom_spheres_fill(const double dx[3], double rsq, double Ra, double Rb,
                                       jd_contact_geom *g) {
    const double d = sqrt(rsq);
    const double delta = (Ra + Rb) - d;
    const double rinv = 1.0 / (d != 0.0 ? d : 1.0);
    const double la = Ra - 0.5 * delta; /* |x_C - x_a| [m] */
    for (int k = 0; k < 3; k++) {
        g->n[k] = dx[k] * rinv;
        g->ra[k] = la * g->n[k];
        g->rb[k] = g->ra[k] - dx[k];
    }
    g->delta = delta;
    return (delta > 0.0) & (d != 0.0);
}

/* Sphere a (centre xa [m], radius Ra [m]) against sphere b (xb, Rb), the geometric fields
 * without r_roll (an engine that keeps r_roll per pair fills it from jd_rolling_radius).
 * Contact when rsq < (Ra + Rb)^2, rsq = |xb - xa|^2 (LIGGGHTS' test), with delta > 0 and r > 0
 * (jd_geom_spheres_fill); returns 1 with g filled, or 0 without contact. */
static inline int jd_geom_spheres_contact(const double xa[3], double Ra, const double xb[3],
                                          double Rb, jd_contact_geom *g) {
    const double dx[3] = {xb[0] - xa[0], xb[1] - xa[1], xb[2] - xa[2]};
    const double rsq = jd_dot(dx, dx);
    const double radsum = Ra + Rb;
    if (rsq >= radsum * radsum) return 0;
    return jd_geom_spheres_fill(dx, rsq, Ra, Rb, g);
}

/* jd_geom_spheres_contact plus r_roll = jd_rolling_radius(Ra, Rb) [m]. */
static inline int jd_geom_spheres(const double xa[3], double Ra, const double xb[3], double Rb,
                                  jd_contact_geom *g) {
    if (!jd_geom_spheres_contact(xa, Ra, xb, Rb, g)) return 0;
    g->r_roll = jd_rolling_radius(Ra, Rb);
    return 1;
}

/* ------------------------------------------------------------------------------------------ */
/* Finite planar quadrilateral (seed Sec. 2.7.1)                                               */
/* ------------------------------------------------------------------------------------------ */

typedef struct jd_plane {
    double p[4][3]; /* corners [m], counter-clockwise seen from the active side               */
    double n[3];    /* unit normal of the active side, (P2-P1) x (P3-P1) normalised [-]        */
} jd_plane;

/* Copy the corners and compute the unit normal.  tol [-]: P4 may be off the plane of P1..P3 by
 * at most tol times the longest corner-to-P1 distance.  Returns JD_GEOM_OK,
 * JD_GEOM_DEGENERATE or JD_GEOM_NOT_PLANAR. */
int jd_plane_init(jd_plane *w, const double corners[4][3], double tol);

/* 1 when the point xc [m], on the plane of w, lies inside the quadrilateral (edges included):
 * ((P_{k+1} - P_k) x (xc - P_k)).n_w >= 0 for the four edges; else 0. */
static inline int jd_plane_covers(const jd_plane *w, const double xc[3]) {
    for (int k = 0; k < 4; k++) {
        const double *p = w->p[k], *q = w->p[(k + 1) & 3];
        const double e[3] = {q[0] - p[0], q[1] - p[1], q[2] - p[2]};
        const double c[3] = {xc[0] - p[0], xc[1] - p[1], xc[2] - p[2]};
        double cr[3];
        jd_cross(e, c, cr);
        if (jd_dot(cr, w->n) < 0.0) return 0;
    }
    return 1;
}

/* Which side of plane w a point x [m] is on, among the points that project onto the
 * quadrilateral: +1 in front (n_w.(x - P1) > 0, the side the plane acts on), -1 behind, 0 on
 * the plane or projecting outside it. */
static inline int jd_plane_side(const jd_plane *w, const double x[3]) {
    const double rel[3] = {x[0] - w->p[0][0], x[1] - w->p[0][1], x[2] - w->p[0][2]};
    const double sd = jd_dot(w->n, rel);
    const double xc[3] = {x[0] - sd * w->n[0], x[1] - sd * w->n[1], x[2] - sd * w->n[2]};
    if (sd == 0.0 || !jd_plane_covers(w, xc)) return 0;
    return sd > 0.0 ? 1 : -1;
}

/* The set-up rule both engines apply to a plane, from the counts of particles over it in front
 * (jd_plane_side +1) and behind (-1): 1 when it is wound away from the particles (some behind,
 * none in front: every one would pass through it), else 0 (no particle over it says nothing). */
static inline int jd_plane_wound_away(double n_front, double n_behind) {
    return n_front == 0.0 && n_behind > 0.0;
}

/* Sphere (centre x [m], radius R [m]) against plane w.  s = n_w.(x - P1) is the signed
 * distance; contact when 0 < s < R and the projection x_C = x - s n_w lies inside the quad
 * (((P_{k+1} - P_k) x (x_C - P_k)).n_w >= 0 for the four edges; edge and corner contacts of a
 * centre projecting outside are not modelled).  Fills n = -n_w, delta = R - s,
 * ra = (R - delta) n, rb = 0, r_roll = R; returns 1, or 0 without contact. */
static inline int jd_geom_plane(const jd_plane *w, const double x[3], double R,
                                jd_contact_geom *g) {
    const double rel[3] = {x[0] - w->p[0][0], x[1] - w->p[0][1], x[2] - w->p[0][2]};
    const double sd = jd_dot(w->n, rel);
    if (!(sd > 0.0 && sd < R)) return 0;
    const double xc[3] = {x[0] - sd * w->n[0], x[1] - sd * w->n[1], x[2] - sd * w->n[2]};
    if (!jd_plane_covers(w, xc)) return 0;
    g->delta = R - sd;
    const double la = R - g->delta;
    for (int k = 0; k < 3; k++) {
        g->n[k] = -w->n[k];
        g->ra[k] = la * g->n[k];
        g->rb[k] = 0.0;
    }
    g->r_roll = R;
    return 1;
}

/* ------------------------------------------------------------------------------------------ */
/* Finite cylinder (lateral surface only, no end caps)                                         */
/* ------------------------------------------------------------------------------------------ */

typedef struct jd_cylinder {
    double a0[3], a1[3]; /* end points of the axis segment                              [m] */
    double rc;           /* cylinder radius                                             [m] */
    int inside;          /* 0: obstacle (outer surface); 1: container (inner surface)   [-] */
} jd_cylinder;

/* Sphere (x [m], R [m]) against cylinder c.  With u = (a1 - a0)/|a1 - a0| the centre projects
 * to t = (x - a0).u, which must satisfy 0 <= t <= |a1 - a0|; d > 0 is the distance from the
 * axis.  Obstacle: delta = R + rc - d, n towards the axis; container: delta = d + R - rc,
 * n away from the axis.  Fills n, delta, ra = (R - delta) n, rb = 0, r_roll = R; returns 1, or
 * 0 without contact (also for a zero-length axis or a centre on the axis). */
static inline int jd_geom_cylinder(const jd_cylinder *c, const double x[3], double R,
                                   jd_contact_geom *g) {
    const double ab[3] = {c->a1[0] - c->a0[0], c->a1[1] - c->a0[1], c->a1[2] - c->a0[2]};
    const double len = sqrt(jd_dot(ab, ab));
    if (!(len > 0.0)) return 0;
    const double u[3] = {ab[0] / len, ab[1] / len, ab[2] / len};
    const double rel[3] = {x[0] - c->a0[0], x[1] - c->a0[1], x[2] - c->a0[2]};
    const double t = jd_dot(rel, u);
    if (!(t >= 0.0 && t <= len)) return 0;
    const double r[3] = {rel[0] - t * u[0], rel[1] - t * u[1], rel[2] - t * u[2]};
    const double d = sqrt(jd_dot(r, r));
    if (d == 0.0) return 0;
    const double dl = c->inside ? d + R - c->rc : R + c->rc - d;
    if (!(dl > 0.0)) return 0;
    const double sgn = (c->inside ? 1.0 : -1.0) / d;
    g->delta = dl;
    const double la = R - dl;
    for (int k = 0; k < 3; k++) {
        g->n[k] = sgn * r[k];
        g->ra[k] = la * g->n[k];
        g->rb[k] = 0.0;
    }
    g->r_roll = R;
    return 1;
}

/* The velocity out [m/s] of cylinder c's surface at the contact point p = x + ra of a sphere
 * centred at x [m] (ra [m]: jd_geom_cylinder's, centre to contact point) when the cylinder
 * translates at v [m/s] and spins at omega [rad/s] about its axis (right-handed about a1 - a0;
 * the shape does not change, so the geometry above does not see the spin):
 * v + omega u x (p - a0), u = (a1 - a0)/|a1 - a0|; exactly v when omega = 0. */
static inline void jd_cylinder_surface_velocity(const jd_cylinder *c, const double v[3], double omega,
                                                const double x[3], const double ra[3],
                                                double out[3]) {
    if (omega == 0.0) {
        for (int k = 0; k < 3; k++) out[k] = v[k];
        return;
    }
    const double p[3] = {x[0] + ra[0], x[1] + ra[1], x[2] + ra[2]};
    const double ab[3] = {c->a1[0] - c->a0[0], c->a1[1] - c->a0[1], c->a1[2] - c->a0[2]};
    const double s = omega / sqrt(jd_dot(ab, ab));
    const double w[3] = {s * ab[0], s * ab[1], s * ab[2]};
    const double r[3] = {p[0] - c->a0[0], p[1] - c->a0[1], p[2] - c->a0[2]};
    out[0] = v[0] + (w[1] * r[2] - w[2] * r[1]);
    out[1] = v[1] + (w[2] * r[0] - w[0] * r[2]);
    out[2] = v[2] + (w[0] * r[1] - w[1] * r[0]);
}

/* ------------------------------------------------------------------------------------------ */
/* The material fields of a contact (docs/model.md §1-2)                                       */
/* ------------------------------------------------------------------------------------------ */

/* Sphere–sphere: k_n from the two per-particle Hertz prefactors kp_a, kp_b [N/m^1.5] (eq. 5),
 * effective mass from m_a, m_b [kg], and — only with JD_F_ROLLING in features, the one law that
 * uses it — effective moment of inertia from I_a, I_b [kg m^2]. */
static inline void jd_geom_pair_material(const unsigned features, jd_contact_geom *g, double kp_a,
                                         double kp_b, double m_a, double m_b, double I_a,
                                         double I_b) {
    g->k_n = jd_kn_pair(kp_a, kp_b);
    g->m_eff = m_a * m_b / (m_a + m_b);
    g->i_eff = (features & JD_F_ROLLING) ? I_a * I_b / (I_a + I_b) : 0.0;
}

/* Sphere–wall: the wall is rigid and immovable, so k_n is the wall rule's prefactor k_wall
 * (jd_kn_wall) [N/m^1.5] and the effective mass and inertia are the particle's m, I. */
static inline void jd_geom_wall_material(const unsigned features, jd_contact_geom *g,
                                         double k_wall, double m, double I) {
    g->k_n = k_wall;
    g->m_eff = m;
    g->i_eff = (features & JD_F_ROLLING) ? I : 0.0;
}

/* Candidate tests for wall contact lists: can a sphere (x [m], R [m]) touch the wall after the
 * sphere and the wall have moved by at most `margin` [m] relative to each other?  The contact
 * tests above (jd_geom_plane, jd_geom_cylinder) with every distance widened by the margin, so
 * they hold for every sphere that touches the wall now or can touch it within that motion.  Both
 * engines keep the spheres for which they hold at a neighbour rebuild (margin: the skin; the
 * stepper's, skin/2 + the particle's own half skin) and
 * evaluate only those until the next rebuild.  Return 1 or 0. */
static inline int jd_geom_plane_near(const jd_plane *w, const double x[3], double R,
                                     double margin) {
    const double rel[3] = {x[0] - w->p[0][0], x[1] - w->p[0][1], x[2] - w->p[0][2]};
    const double sd = jd_dot(w->n, rel);
    if (!(sd > -margin && sd < R + margin)) return 0;
    /* the centre's projection within margin of the quad: signed distance to each edge line */
    for (int k = 0; k < 4; k++) {
        const double *p = w->p[k], *q = w->p[(k + 1) & 3];
        const double e[3] = {q[0] - p[0], q[1] - p[1], q[2] - p[2]};
        const double c[3] = {x[0] - p[0], x[1] - p[1], x[2] - p[2]};
        double cr[3];
        jd_cross(e, c, cr);
        if (jd_dot(cr, w->n) < -margin * sqrt(jd_dot(e, e))) return 0;
    }
    return 1;
}

static inline int jd_geom_cylinder_near(const jd_cylinder *c, const double x[3], double R,
                                        double margin) {
    const double ab[3] = {c->a1[0] - c->a0[0], c->a1[1] - c->a0[1], c->a1[2] - c->a0[2]};
    const double len = sqrt(jd_dot(ab, ab));
    const double rel[3] = {x[0] - c->a0[0], x[1] - c->a0[1], x[2] - c->a0[2]};
    const double t = jd_dot(rel, ab) / len;
    if (!(t > -margin && t < len + margin)) return 0;
    const double d2 = jd_dot(rel, rel) - t * t;
    const double d = sqrt(d2 > 0.0 ? d2 : 0.0); /* distance from the axis */
    return c->inside ? d > c->rc - R - margin : d < c->rc + R + margin;
}

#ifdef __cplusplus
}
#endif
#endif /* JDEM_KERNEL_GEOMETRY_H */
