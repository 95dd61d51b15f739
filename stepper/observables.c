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

void sim_observables(const jd_particles *ps, const jd_run_constants *run,
                     const jd_neighbour_lists *lists, const jd_walls *walls,
                     const jd_accounts *accounts, jd_observables *o) {
    *o = (jd_observables){0};
    for (size_t i = 0; i < ps->n; i++) {
        const double *v = ps->v + 3 * i, *w = ps->omega + 3 * i, *x = ps->x + 3 * i;
        o->kinetic_energy += 0.5 * ps->mass[i] * jd_dot(v, v);
        o->rotational_energy += 0.5 * ps->inertia[i] * jd_dot(w, w);
        o->gravitational_energy -= ps->mass[i] * jd_dot(run->g, x);
    }
    /* Stored energy comes from the contact state (zero for separated and ended contacts); the
     * geometry decides which contacts count. */
    for (size_t c = 0; c < lists->pairs.n; c++) {
        jd_contact_geom g;
        jd_contact_state st;
        sim_hist_get(&lists->pairs, c, &st, NULL);
        o->elastic_energy += jd_contact_elastic_energy(&st);
        const int32_t i = lists->pairs.i[c], j = lists->pairs.j[c];
        if (carries_force(&st) &&
            jd_geom_spheres_contact(ps->x + 3 * (size_t)i, ps->radius[i], ps->x + 3 * (size_t)j,
                                    ps->radius[j], &g))
            o->contacts += 1.0;
    }
    for (size_t c = 0; c < lists->wall_pairs.n; c++) {
        jd_contact_geom g;
        jd_contact_state st;
        sim_hist_get(&lists->wall_pairs, c, &st, NULL);
        o->elastic_energy += jd_contact_elastic_energy(&st);
        const jd_sim_wall *w = &walls->wall[lists->wall_pairs.j[c]];
        if (!w->gone && carries_force(&st) && sim_wall_geom(ps, lists->wall_pairs.i[c], w, &g))
            o->wall_contacts += 1.0;
    }
    o->damping_dissipation = accounts->e_damp_dropped;
    o->friction_dissipation = accounts->e_fric_dropped;
    list_energies(&lists->pairs, &o->damping_dissipation, &o->friction_dissipation);
    list_energies(&lists->wall_pairs, &o->damping_dissipation, &o->friction_dissipation);
    o->wall_work = accounts->wall_work;
}
