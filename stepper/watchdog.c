/*
 * watchdog.c — the run-time watchdog (docs/scenes.md "Watchdog"): stop a run that has gone wrong
 * with a message naming the step, the particles and the quantity, instead of writing garbage
 * for the rest of the run.  The limits themselves are kernel/jdem_watchdog.h (LIGGGHTS' `fix
 * jdem/watchdog` applies the same ones).
 *
 * Cost: the overlap test rides in the force loops (one multiply and compare per contact), the
 * non-finite test in the integration step (integrate.c); this file only formats what they
 * found, and the energy test runs at the observable samples, where the energies exist anyway.
 */
#include <math.h>
#include <stdio.h>

#include "sim.h"

/* Keep the worst offender of this force evaluation in t, the trip of the calling thread
 * (sim_compute_forces resets them and keeps the worst). */
void sim_watchdog_overlap(jd_overlap_trip *t, int32_t i, int32_t j, double delta, double rmin) {
    const double fraction = delta / rmin;
    if (fraction > t->fraction) *t = (jd_overlap_trip){.fraction = fraction, .i = i, .j = j};
}

/* The name of wall -j - 1 of a trip: the plane and cylinder walls, then the mesh walls. */
static const char *trip_wall_name(const jd_scene *sc, int32_t j) {
    const size_t w = (size_t)(-(int64_t)j - 1);
    return w < sc->n_walls ? sc->walls[w].name : sc->mesh_walls[w - sc->n_walls].name;
}

static int overlap_message(const jd_overlap_trip *t, const jd_particles *ps,
                           const jd_run_constants *run, int64_t step, char *msg, size_t len) {
    jd_watchdog_overlap_message(msg, len, (long long)step, t->fraction, sim_particle_id(ps, (size_t)t->i),
                                t->j >= 0 ? sim_particle_id(ps, (size_t)t->j) : -1,
                                t->j >= 0 ? "" : trip_wall_name(run->scene, t->j), run->max_overlap);
    return JD_RUN_TRIPPED;
}

/* Name the first non-finite quantity, in the kernel's order (jd_watchdog_quantities). */
static int nonfinite_message(const jd_particles *ps, int64_t step, char *msg, size_t len) {
    const double *q[JD_N_WATCHDOG_QUANTITIES] = {ps->f, ps->torque, ps->x, ps->v, ps->omega};
    for (int k = 0; k < JD_N_WATCHDOG_QUANTITIES; k++)
        for (size_t c = 0; c < 3 * ps->n; c++)
            if (!isfinite(q[k][c])) {
                jd_watchdog_nonfinite_message(msg, len, (long long)step, k, q[k][c],
                                              sim_particle_id(ps, c / 3));
                return JD_RUN_TRIPPED;
            }
    /* the probe saw a NaN that is gone from the state: cannot happen, but never pass silently */
    snprintf(msg, len, "watchdog: step %lld: non-finite state", (long long)step);
    return JD_RUN_TRIPPED;
}

int sim_watchdog_step(const jd_watch *watch, const jd_particles *ps, const jd_run_constants *run,
                      int64_t step, char *msg, size_t len) {
    /* a non-finite state stops the run even with the watchdog off: the writer could not write
     * it, and the next step could not bin it (the overlap limit is INFINITY when off) */
    if (watch->nonfinite) return nonfinite_message(ps, step, msg, len);
    if (watch->overlap_trip.fraction > 0.0)
        return overlap_message(&watch->overlap_trip, ps, run, step, msg, len);
    return 0;
}

/* The balance's terms by the kernel's rule (jd_energy_terms_of). */
/* The net energy the particle set gained at its boundary (what the inlets brought in, less what
 * the particles deleted outside the domain took) is booked as work done on the particles, so
 * the balance closes while the set grows and shrinks. */
static void energy_terms(double inlet_energy, const jd_observables *o, jd_energy_terms *e) {
    double v[JD_N_OBSERVABLES], b[JD_N_BOND_OBSERVABLES];
    sim_observables_values(o, v);
    sim_bond_observables_values(&o->bond, b);
    *e = jd_energy_terms_of(v, b);
    e->wall_work += inlet_energy;
}

/* The particle with the largest kinetic energy: where a spurious energy gain usually sits. */
static size_t most_energetic(const jd_particles *ps) {
    size_t best = 0;
    double e_best = -1.0;
    for (size_t i = 0; i < ps->n; i++) {
        const double *v = ps->v + 3 * i, e = ps->mass[i] * jd_dot(v, v);
        if (e > e_best) {
            e_best = e;
            best = i;
        }
    }
    return best;
}

int sim_watchdog_energy(jd_watch *watch, const jd_particles *ps, const jd_run_constants *run,
                        int64_t step, double inlet_energy, const jd_observables *o, char *msg,
                        size_t len) {
    if (!run->scene->watchdog.enabled || !run->scene->energy) return 0; /* no energies to check */
    jd_energy_terms now;
    energy_terms(inlet_energy, o, &now);
    const double limit = run->scene->watchdog.max_energy_jump;
    const double jump = watch->has_energy_ref ? jd_energy_jump(&watch->energy_ref, &now) : 0.0;
    if (!(jump <= limit)) { /* NaN trips too */
        jd_watchdog_energy_message(msg, len, (long long)step, jump, sim_particle_id(ps, most_energetic(ps)),
                                   limit, jd_energy_total(&watch->energy_ref),
                                   (long long)watch->energy_ref_step, jd_energy_total(&now));
        return JD_RUN_TRIPPED;
    }
    watch->energy_ref = now;
    watch->energy_ref_step = step;
    watch->has_energy_ref = 1;
    return 0;
}
