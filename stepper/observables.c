/*
 * observables.c — the /observables of docs/scenes.md.  Called after the final half kick, so
 * velocities are full-step values; positions (and hence contact geometry) are those the step's
 * forces were computed at, so the elastic energy matches the contact states.
 */
#include "geometry.h"
#include "sim.h"

void sim_observables_values(const jd_observables *o, double out[JD_N_OBSERVABLES]) {
    const double v[JD_N_OBSERVABLES] = {o->kinetic_energy,      o->rotational_energy,
                                        o->elastic_energy,      o->gravitational_energy,
                                        o->damping_dissipation, o->friction_dissipation,
                                        o->wall_work,           o->contacts,
                                        o->wall_contacts};
    for (int k = 0; k < JD_N_OBSERVABLES; k++) out[k] = v[k];
}

/* Dissipation of every listed entry, including separated pairs still in the list (their
 * accumulators survive jd_contact_separate). */
static void list_energies(const jd_contact_list *l, double *damp, double *fric) {
    for (size_t c = 0; c < l->n; c++) {
        jd_contact_state st;
        sim_hist_get(l, c, &st, NULL);
        jd_contact_harvest(&st, 1.0, damp, fric); /* from a copy: the entry keeps its own */
    }
}

static int carries_force(const jd_contact_state *st) {
    return st->flags != (double)JD_S_ENDED;
}

void sim_observables(const jd_sim *s, jd_observables *o) {
    *o = (jd_observables){0};
    for (size_t i = 0; i < s->n; i++) {
        const double *v = s->v + 3 * i, *w = s->omega + 3 * i, *x = s->x + 3 * i;
        o->kinetic_energy += 0.5 * s->mass[i] * jd_dot(v, v);
        o->rotational_energy += 0.5 * s->inertia[i] * jd_dot(w, w);
        o->gravitational_energy -= s->mass[i] * jd_dot(s->g, x);
    }
    /* Stored energy comes from the contact state (zero for separated and ended contacts); the
     * geometry decides which contacts count. */
    for (size_t c = 0; c < s->pairs.n; c++) {
        jd_contact_geom g;
        jd_contact_state st;
        sim_hist_get(&s->pairs, c, &st, NULL);
        o->elastic_energy += jd_contact_elastic_energy(&st);
        const int32_t i = s->pairs.i[c], j = s->pairs.j[c];
        if (carries_force(&st) &&
            jd_geom_spheres_contact(s->x + 3 * (size_t)i, s->radius[i], s->x + 3 * (size_t)j,
                                    s->radius[j], &g))
            o->contacts += 1.0;
    }
    for (size_t c = 0; c < s->wall_pairs.n; c++) {
        jd_contact_geom g;
        jd_contact_state st;
        sim_hist_get(&s->wall_pairs, c, &st, NULL);
        o->elastic_energy += jd_contact_elastic_energy(&st);
        if (carries_force(&st) && sim_wall_geom(s, s->wall_pairs.i[c], &s->walls[s->wall_pairs.j[c]], &g))
            o->wall_contacts += 1.0;
    }
    o->damping_dissipation = s->e_damp_dropped;
    o->friction_dissipation = s->e_fric_dropped;
    list_energies(&s->pairs, &o->damping_dissipation, &o->friction_dissipation);
    list_energies(&s->wall_pairs, &o->damping_dissipation, &o->friction_dissipation);
    o->wall_work = s->wall_work;
    if (s->bonds) sim_bonds_observables(s, &o->bond);
}
