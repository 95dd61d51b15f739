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

/* Keep the worst offender of this force evaluation (sim_compute_forces resets it). */
void sim_watchdog_overlap(jd_sim *s, int32_t i, int32_t j, double delta, double rmin) {
    const double fraction = delta / rmin;
    if (fraction > s->overlap_trip.fraction)
        s->overlap_trip = (jd_overlap_trip){.fraction = fraction, .i = i, .j = j};
}

static long long id_of(const jd_sim *s, size_t i) { return (long long)s->scene->id[i]; }

static int overlap_message(const jd_sim *s, char *msg, size_t len) {
    const jd_overlap_trip *t = &s->overlap_trip;
    char with[JD_NAME_MAX + 64];
    if (t->j >= 0)
        snprintf(with, sizeof with, ", %lld", id_of(s, (size_t)t->j));
    else
        snprintf(with, sizeof with, " against wall '%s'", s->scene->walls[-t->j - 1].name);
    snprintf(msg, len, "watchdog: step %lld: overlap fraction %.6g for particle(s) %lld%s exceeds "
             "%g", (long long)s->step, t->fraction, id_of(s, (size_t)t->i), with, s->max_overlap);
    return JD_RUN_TRIPPED;
}

/* Name the first non-finite quantity, forces first: a non-finite force is the cause of the
 * non-finite velocity it produces. */
static int nonfinite_message(const jd_sim *s, char *msg, size_t len) {
    const struct {
        const char *name;
        const double *v;
    } q[] = {{"force", s->f}, {"torque", s->torque}, {"position", s->x},
             {"velocity", s->v}, {"angular velocity", s->omega}};
    for (size_t k = 0; k < sizeof q / sizeof *q; k++)
        for (size_t c = 0; c < 3 * s->n; c++)
            if (!isfinite(q[k].v[c])) {
                snprintf(msg, len, "watchdog: step %lld: %s %g for particle(s) %lld is not finite",
                         (long long)s->step, q[k].name, q[k].v[c], id_of(s, c / 3));
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

/* Bonds enter the balance as stored (elastic) and dissipated (damping) energy. */
static void energy_terms(const jd_observables *o, jd_energy_terms *e) {
    const jd_bond_observables *b = &o->bond;
    *e = (jd_energy_terms){.kinetic = o->kinetic_energy, .rotational = o->rotational_energy,
                           .elastic = o->elastic_energy + b->elastic_energy,
                           .gravitational = o->gravitational_energy,
                           .damping = o->damping_dissipation + b->damping_dissipation +
                                      b->breakage_energy,
                           .friction = o->friction_dissipation, .wall_work = o->wall_work};
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
    if (!s->scene->watchdog.enabled) return 0;
    jd_energy_terms now;
    energy_terms(o, &now);
    const double limit = s->scene->watchdog.max_energy_jump;
    const double jump = s->has_energy_ref ? jd_energy_jump(&s->energy_ref, &now) : 0.0;
    if (!(jump <= limit)) { /* NaN trips too */
        snprintf(msg, len, "watchdog: step %lld: energy jump %.6g for particle(s) %lld exceeds %g "
                 "(total energy %.9g J at step %lld, %.9g J now; the particle named has the "
                 "largest kinetic energy)", (long long)s->step, jump,
                 id_of(s, most_energetic(s)), limit, jd_energy_total(&s->energy_ref),
                 (long long)s->energy_ref_step, jd_energy_total(&now));
        return JD_RUN_TRIPPED;
    }
    s->energy_ref = now;
    s->energy_ref_step = s->step;
    s->has_energy_ref = 1;
    return 0;
}
