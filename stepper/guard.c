/*
 * guard.c — is the scene's time step safe?  Two bounds (spec/jiang_model.md §10):
 *   (a) 20 % of the Rayleigh step of the smallest sphere of each species (the seed's rule);
 *   (b) the shortest Hertz contact (any species pair, any species against a wall, at the
 *       smallest radii and the scene's max_impact_speed) must span at least 50 steps
 *       (erratum 18: 3-4 steps per contact, the seed's rule of thumb, is far too coarse).
 *   (c) with bonds, the fastest bond mode must span at least 20 steps (sim_bonds_guard, bonds.c).
 * The contact time scales like R (m ~ R^3, k ~ R^0.5, t ~ (m/k)^0.4), so the smallest radii
 * give the shortest contact.
 */
#include <math.h>
#include <stdlib.h>

#include "sim.h"

typedef struct species_info {
    size_t count;
    double rmin;
} species_info;

static void tighten(jd_guard *g, double bound, const char *what) {
    if (g->violated && g->violated_value <= bound) return;
    g->violated = what;
    g->violated_value = bound;
}

void sim_guard(const jd_scene *sc, jd_guard *g) {
    *g = (jd_guard){.rayleigh_bound = INFINITY, .contact_time = INFINITY, .contact_bound = INFINITY,
                    .bond_bound = INFINITY};
    species_info *sp = calloc(sc->n_materials ? sc->n_materials : 1, sizeof *sp);
    if (!sp) { /* cannot assess: report as unsafe rather than silently safe */
        g->safe_dt = 0.0;
        g->violated = "the time-step guard (out of memory)";
        return;
    }
    for (size_t i = 0; i < sc->n_particles; i++) {
        species_info *p = &sp[sc->material[i]];
        p->rmin = p->count ? fmin(p->rmin, sc->radius[i]) : sc->radius[i];
        p->count++;
    }
    const double v = sc->max_impact_speed;
    for (size_t a = 0; a < sc->n_materials; a++) {
        if (!sp[a].count) continue;
        const jd_material *ma = &sc->materials[a];
        const double Ra = sp[a].rmin;
        g->rayleigh_bound = fmin(g->rayleigh_bound,
                                 JD_GUARD_RAYLEIGH_FRACTION *
                                     jd_rayleigh_step(Ra, ma->density, ma->youngs_modulus, ma->poisson_ratio));
        if (!(v > 0.0)) continue; /* nothing moves: no impact to resolve */
        const double m_a = jd_sphere_mass(Ra, ma->density);
        const double kp_a = jd_hertz_prefactor(ma->youngs_modulus, ma->poisson_ratio, Ra);
        for (size_t b = a; b < sc->n_materials; b++) {
            if (!sp[b].count || (b == a && sp[a].count < 2)) continue;
            const jd_material *mb = &sc->materials[b];
            const double m_b = jd_sphere_mass(sp[b].rmin, mb->density);
            const double kp_b = jd_hertz_prefactor(mb->youngs_modulus, mb->poisson_ratio, sp[b].rmin);
            g->contact_time = fmin(g->contact_time,
                                   jd_hertz_contact_time(m_a * m_b / (m_a + m_b), jd_kn_pair(kp_a, kp_b), v));
        }
        if (sc->n_walls > 0) {
            const double kw = jd_kn_wall(sc->wall_rule, ma->youngs_modulus, ma->poisson_ratio, Ra);
            g->contact_time = fmin(g->contact_time, jd_hertz_contact_time(m_a, kw, v));
        }
    }
    free(sp);
    g->contact_bound = g->contact_time / JD_GUARD_STEPS_PER_CONTACT;
    g->bond_bound = sim_bonds_guard(sc);
    g->safe_dt = fmin(fmin(g->rayleigh_bound, g->contact_bound), g->bond_bound);
    if (sc->dt > g->rayleigh_bound) tighten(g, g->rayleigh_bound, "20 % of the Rayleigh time step");
    if (sc->dt > g->contact_bound)
        tighten(g, g->contact_bound, "1/50 of the shortest Hertz contact time");
    if (sc->dt > g->bond_bound) tighten(g, g->bond_bound, "1/20 of the fastest bond period");
}
