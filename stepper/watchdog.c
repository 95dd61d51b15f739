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

static long long id_of(const jd_sim *s, size_t i) { return sim_particle_id(s, i); }

static int overlap_message(const jd_sim *s, char *msg, size_t len) {
    const jd_overlap_trip *t = &s->overlap_trip;
    jd_watchdog_overlap_message(msg, len, (long long)s->step, t->fraction, id_of(s, (size_t)t->i),
                                t->j >= 0 ? id_of(s, (size_t)t->j) : -1,
                                t->j >= 0 ? "" : s->scene->walls[-t->j - 1].name, s->max_overlap);
    return JD_RUN_TRIPPED;
}

/* Name the first non-finite quantity, in the kernel's order (jd_watchdog_quantities). */
static int nonfinite_message(const jd_sim *s, char *msg, size_t len) {
    const double *q[JD_N_WATCHDOG_QUANTITIES] = {s->f, s->torque, s->x, s->v, s->omega};
    for (int k = 0; k < JD_N_WATCHDOG_QUANTITIES; k++)
        for (size_t c = 0; c < 3 * s->n; c++)
            if (!isfinite(q[k][c])) {
                jd_watchdog_nonfinite_message(msg, len, (long long)s->step, k, q[k][c],
                                              id_of(s, c / 3));
                return JD_RUN_TRIPPED;
            }
    /* the probe saw a NaN that is gone from the state: cannot happen, but never pass silently */
    snprintf(msg, len, "watchdog: step %lld: non-finite state", (long long)s->step);
    return JD_RUN_TRIPPED;
}

int sim_watchdog_step(const jd_sim *s, char *msg, size_t len) {
    /* a non-finite state stops the run even with the watchdog off: the writer could not write
     * it, and the next step could not bin it (the overlap limit is INFINITY when off) */
    if (s->nonfinite) return nonfinite_message(s, msg, len);
    if (s->overlap_trip.fraction > 0.0) return overlap_message(s, msg, len);
    return 0;
}

/* The balance's terms by the kernel's rule (jd_energy_terms_of). */
/* The energy the inlets brought in is booked as work done on the particles, so the balance
 * closes while the set grows. */
static void energy_terms(const jd_sim *s, const jd_observables *o, jd_energy_terms *e) {
    double v[JD_N_OBSERVABLES], b[JD_N_BOND_OBSERVABLES];
    sim_observables_values(o, v);
    sim_bond_observables_values(&o->bond, b);
    *e = jd_energy_terms_of(v, b);
    e->wall_work += sim_inlets_energy(s);
}

/* The particle with the largest kinetic energy: where a spurious energy gain usually sits. */
static size_t most_energetic(const jd_sim *s) {
    size_t best = 0;
    double e_best = -1.0;
    for (size_t i = 0; i < s->n; i++) {
        const double *v = s->v + 3 * i, e = s->mass[i] * jd_dot(v, v);
        if (e > e_best) {
            e_best = e;
            best = i;
        }
    }
    return best;
}

int sim_watchdog_energy(jd_sim *s, const jd_observables *o, char *msg, size_t len) {
    if (!s->scene->watchdog.enabled || !s->scene->energy) return 0; /* no energies to check */
    jd_energy_terms now;
    energy_terms(s, o, &now);
    const double limit = s->scene->watchdog.max_energy_jump;
    const double jump = s->has_energy_ref ? jd_energy_jump(&s->energy_ref, &now) : 0.0;
    if (!(jump <= limit)) { /* NaN trips too */
        jd_watchdog_energy_message(msg, len, (long long)s->step, jump, id_of(s, most_energetic(s)),
                                   limit, jd_energy_total(&s->energy_ref),
                                   (long long)s->energy_ref_step, jd_energy_total(&now));
        return JD_RUN_TRIPPED;
    }
    s->energy_ref = now;
    s->energy_ref_step = s->step;
    s->has_energy_ref = 1;
    return 0;
}
