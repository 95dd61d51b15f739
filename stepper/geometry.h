/*
 * geometry.h — contact geometry of one candidate for the force loops and the observables (so
 * both see the same contacts).  The shapes are the kernel's (kernel/jdem_geometry.h, shared with
 * the LIGGGHTS plugin); this adds the material fields from the per-particle constants.  a is the
 * particle with the lower index (or the particle of a wall contact); n points from a to b.
 */
#ifndef JDEM_GEOMETRY_H
#define JDEM_GEOMETRY_H

#include "jdem_geometry.h"
#include "sim.h"

/* Sphere–sphere: returns 1 and fills g when the spheres overlap (rsq < radsum^2).  i_eff is
 * only needed by the rolling law, so it is computed only with JD_F_ROLLING in features (a
 * compile-time constant at the call sites). */
static inline int sim_pair_geom(const jd_sim *s, const unsigned features, int32_t i, int32_t j,
                                jd_contact_geom *g) {
    if (!jd_geom_spheres(s->x + 3 * (size_t)i, s->radius[i], s->x + 3 * (size_t)j, s->radius[j], g))
        return 0;
    jd_geom_pair_material(features, g, s->kp[i], s->kp[j], s->mass[i], s->mass[j], s->inertia[i],
                          s->inertia[j]);
    return 1;
}

/* Particle i against wall w (the wall is body b; its current position is in w).  Edge and corner
 * contacts of a finite plane are not modelled (the kernel's plane test). */
static inline int sim_wall_geom(const jd_sim *s, int32_t i, const jd_sim_wall *w,
                                jd_contact_geom *g) {
    const double *x = s->x + 3 * (size_t)i;
    const double R = s->radius[i];
    const int touch = w->type == JD_WALL_PLANE ? jd_geom_plane(&w->plane, x, R, g)
                                               : jd_geom_cylinder(&w->cyl, x, R, g);
    if (!touch) return 0;
    jd_geom_wall_material(JD_F_ROLLING, g, s->kw[i], s->mass[i], s->inertia[i]);
    return 1;
}

#endif /* JDEM_GEOMETRY_H */
