/*
 * geometry.h — contact geometry of one candidate for the force loops and the observables (so
 * both see the same contacts).  The shapes are the kernel's (kernel/jdem_geometry.h, shared with
 * the LIGGGHTS plugin); this adds the material fields.  a is the particle with the lower index
 * (or the particle of a wall contact); n points from a to b.
 */
#ifndef JDEM_GEOMETRY_H
#define JDEM_GEOMETRY_H

#include "jdem_geometry.h"
#include "sim.h"

/* The constants of pair (i, j) as jd_geom_pair_material and jd_geom_spheres compute them (the
 * force loops compute the same per lane, or read the scene's single set).  pcr may be NULL (no
 * rolling). */
static inline void sim_pair_constants(const jd_particles *ps, int32_t i, int32_t j, jd_pair_const *pc,
                                      jd_pair_const_roll *pcr) {
    jd_contact_geom g;
    jd_geom_pair_material(pcr ? JD_F_ROLLING : 0u, &g, ps->kp[i], ps->kp[j], ps->mass[i], ps->mass[j],
                          ps->inertia[i], ps->inertia[j]);
    pc->k_n = g.k_n;
    pc->m_eff = g.m_eff;
    if (pcr) {
        pcr->i_eff = g.i_eff;
        pcr->r_roll = jd_rolling_radius(ps->radius[i], ps->radius[j]);
    }
}

/* Do spheres i and j overlap (LIGGGHTS' test, rsq < radsum^2, as jd_geom_spheres_contact)? */
static inline int sim_pair_touching(const jd_particles *ps, int32_t i, int32_t j) {
    const double *xi = ps->x + 3 * (size_t)i, *xj = ps->x + 3 * (size_t)j;
    const double dx[3] = {xj[0] - xi[0], xj[1] - xi[1], xj[2] - xi[2]};
    const double radsum = ps->radius[i] + ps->radius[j];
    return jd_dot(dx, dx) < radsum * radsum;
}

/* Sphere–sphere for particles i and j: returns 1 and fills g when the spheres overlap
 * (rsq < radsum^2).  The material fields are the pair's constants (sim_pair_constants), or the
 * scene's single set when the particles are all alike; i_eff is only read by the rolling law
 * and r_roll by it and Mindlin's K_t, so they are filled only with JD_F_ROLLING and
 * JD_F_READS_R_STAR in features (a compile-time constant at the call sites). */
static inline int sim_pair_geom(const jd_particles *ps, const jd_fast_paths *fast,
                                const unsigned features, int32_t i, int32_t j,
                                jd_contact_geom *g) {
    if (!jd_geom_spheres_contact(ps->x + 3 * (size_t)i, ps->radius[i], ps->x + 3 * (size_t)j,
                                 ps->radius[j], g))
        return 0;
    jd_pair_const pc = fast->pc_alike;
    jd_pair_const_roll pcr = fast->pcr_alike;
    if (!fast->alike) sim_pair_constants(ps, i, j, &pc, &pcr);
    g->k_n = pc.k_n;
    g->m_eff = pc.m_eff;
    g->i_eff = (features & JD_F_ROLLING) ? pcr.i_eff : 0.0;
    g->r_roll = (features & JD_F_READS_R_STAR) ? pcr.r_roll : 0.0;
    return 1;
}

/* Particle i against wall w (the wall is body b; its current position is in w).  Edge and corner
 * contacts of a finite plane are not modelled (the kernel's plane test). */
static inline int sim_wall_geom(const jd_particles *ps, int32_t i, const jd_sim_wall *w,
                                jd_contact_geom *g) {
    const double *x = ps->x + 3 * (size_t)i;
    const double R = ps->radius[i];
    const int touch = w->type == JD_WALL_PLANE ? jd_geom_plane(&w->plane, x, R, g)
                                               : jd_geom_cylinder(&w->cyl, x, R, g);
    if (!touch) return 0;
    jd_geom_wall_material(JD_F_ROLLING, g, ps->kw[i], ps->mass[i], ps->inertia[i]);
    return 1;
}

/* The velocity vb [m/s] of wall w at the contact point x + ra [m] of a particle at x: its
 * translation, plus a cylinder's spin about its axis. */
static inline void wall_point_velocity(const jd_sim_wall *w, const double x[3], const double ra[3],
                                       double vb[3]) {
    if (w->type != JD_WALL_CYLINDER) {
        for (int d = 0; d < 3; d++) vb[d] = w->v[d];
        return;
    }
    jd_cylinder_surface_velocity(&w->cyl, w->v, w->spin, x, ra, vb);
}

#endif /* JDEM_GEOMETRY_H */
