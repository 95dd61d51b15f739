/*
 * guard.c — is the scene's time step safe?  The bounds are the kernel's (kernel/jdem_guard.h,
 * shared with LIGGGHTS' `fix jdem/guard`); this file only gathers what they need from the scene:
 * the smallest radius of each species, the walls, the impact speed, the expected coordination
 * number, the strongest damping of any pair of materials and the bonds' frequencies.
 */
#include <math.h>
#include <stdlib.h>

#include "sim.h"

/* The guard's damping ratio (jd_guard_damping_ratio, the rule LIGGGHTS' fix jdem/guard applies to
 * its atom types). */
static double damping_ratio(const jd_scene *sc, const jd_guard_species *sp) {
    const size_t nn = sc->n_materials * sc->n_materials;
    double *e = malloc((nn ? nn : 1) * sizeof *e);
    if (!e) return INFINITY; /* cannot assess: report as unsafe */
    for (size_t k = 0; k < nn; k++) e[k] = sc->interactions[k].restitution;
    const double z = jd_guard_damping_ratio(sp, sc->n_materials, e, sc->damping_map);
    free(e);
    return z;
}

static void add_particle(jd_guard_species *p, double radius) {
    p->rmin = p->count ? fmin(p->rmin, radius) : radius;
    p->count++;
}

int sim_guard(const jd_scene *sc, jd_guard_input *in, jd_guard_species **species,
              jd_guard_result *r) {
    jd_guard_species *sp = calloc(sc->n_materials ? sc->n_materials : 1, sizeof *sp);
    if (!sp) return -1;
    for (size_t a = 0; a < sc->n_materials; a++) {
        const jd_material *m = &sc->materials[a];
        sp[a] = (jd_guard_species){.density = m->density, .E = m->youngs_modulus,
                                   .nu = m->poisson_ratio, .mepa_k1 = m->loading_stiffness,
                                   .mepa_k2 = m->unloading_stiffness};
    }
    for (size_t i = 0; i < sc->n_particles; i++) add_particle(&sp[sc->material[i]], sc->radius[i]);
    for (size_t k = 0; k < sc->n_inlets; k++) /* the sections' particles take part once inserted */
        for (size_t p = 0; p < sc->inlets[k].n; p++)
            add_particle(&sp[sc->inlets[k].material[p]], sc->inlets[k].radius[p]);
    *in = (jd_guard_input){.species = sp, .n_species = sc->n_materials,
                           .has_walls = sc->n_walls > 0, .wall_rule = sc->wall_rule,
                           .tangential_rule = sc->tangential_rule,
                           .normal_law = sc->normal_law, .mepa_n = sc->mepa_exponent,
                           .max_impact_speed = sc->max_impact_speed,
                           .coordination = sc->coordination_number,
                           .damping_ratio = damping_ratio(sc, sp),
                           .bond_omega2 = sim_bonds_omega2(sc), .dt = sc->dt};
    jd_guard_assess(in, r);
    *species = sp;
    return 0;
}
