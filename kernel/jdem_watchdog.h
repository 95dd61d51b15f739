/*
 * jdem_watchdog.h — the limits of the run-time watchdog, shared by both engines (the stepper's
 * stepper/watchdog.c and LIGGGHTS' `fix jdem/watchdog`), so that both stop a run on exactly the
 * same condition, and the messages both print when it trips (jdem_watchdog.c).  Pure C11: no
 * I/O, no allocation, no globals.
 */
#ifndef JDEM_KERNEL_WATCHDOG_H
#define JDEM_KERNEL_WATCHDOG_H

#include <math.h>
#include <stddef.h>

#include "jdem_observable_names.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Overlap delta [m] of spheres Ra, Rb [m] (Rb = INFINITY for a wall) beyond frac of the smaller
 * radius.  A limit of INFINITY never trips (the engines use it for "watchdog off", so that the
 * force loops need no branch on it); a NaN delta does not trip here (the non-finite check
 * reports it with the right quantity).  The radii are positive (the scene reader's rule), so the
 * smaller one is a plain comparison (fmin is a library call that force loops cannot vectorise). */
static inline int jd_overlap_excessive(double delta, double Ra, double Rb, double frac) {
    return delta > frac * (Ra < Rb ? Ra : Rb);
}

/* The terms of the energy balance of docs/scenes.md [J]. */
typedef struct jd_energy_terms {
    double kinetic, rotational, elastic, gravitational, damping, friction, wall_work;
} jd_energy_terms;

/* The terms from the observables (kernel/jdem_observables.h) [J]: bonds enter as stored
 * (elastic) energy and as dissipation (their dashpots' and what broken bonds released). */
static inline jd_energy_terms jd_energy_terms_of(const double obs[], const double bond_obs[]) {
    const jd_energy_terms e = {
        .kinetic = obs[JD_OBS_KINETIC],
        .rotational = obs[JD_OBS_ROTATIONAL],
        .elastic = obs[JD_OBS_ELASTIC] + bond_obs[JD_OBS_BOND_ELASTIC],
        .gravitational = obs[JD_OBS_GRAVITATIONAL],
        .damping = obs[JD_OBS_DAMPING] + bond_obs[JD_OBS_BOND_DAMPING] +
                   bond_obs[JD_OBS_BOND_BREAKAGE],
        .friction = obs[JD_OBS_FRICTION],
        .wall_work = obs[JD_OBS_WALL_WORK]};
    return e;
}

/* KE + RE + elastic + gravitational + dissipated - wall work: constant in an exact run. */
static inline double jd_energy_total(const jd_energy_terms *e) {
    return e->kinetic + e->rotational + e->elastic + e->gravitational + e->damping + e->friction -
           e->wall_work;
}

/* The energy in play: the terms that do not depend on where the origin of height is.  The
 * gravitational energy enters only through its round-off (1e-12 of it), so that a run with a
 * distant origin and nothing moving yet cannot trip on the last bits of -sum m g.x. */
static inline double jd_energy_scale(const jd_energy_terms *e) {
    return e->kinetic + e->rotational + e->elastic + e->damping + e->friction +
           fabs(e->wall_work) + 1e-12 * fabs(e->gravitational);
}

/* Relative jump of the total energy from sample a to sample b [-]: |E_b - E_a| over the larger
 * energy in play of the two.  0 when nothing changed (also when nothing is in play); INFINITY
 * when energy appears from nothing; NaN when a term is not finite. */
static inline double jd_energy_jump(const jd_energy_terms *a, const jd_energy_terms *b) {
    const double d = fabs(jd_energy_total(b) - jd_energy_total(a));
    const double scale = fmax(jd_energy_scale(a), jd_energy_scale(b));
    return d == 0.0 ? 0.0 : d / scale;
}

/* The messages of a trip, into msg (len bytes), as both engines print them (LIGGGHTS adds
 * "jdem: " in front).  Particles are named by their ids. */
/* The quantities the non-finite check names, in the order it searches them (forces first: a
 * non-finite force is the cause of the non-finite velocity it produces). */
#define JD_N_WATCHDOG_QUANTITIES 5
extern const char *const jd_watchdog_quantities[JD_N_WATCHDOG_QUANTITIES];
void jd_watchdog_nonfinite_message(char *msg, size_t len, long long step, int quantity,
                                   double value, long long id);
/* id_b < 0: the contact is with the wall named wall. */
void jd_watchdog_overlap_message(char *msg, size_t len, long long step, double fraction,
                                 long long id_a, long long id_b, const char *wall, double limit);
void jd_watchdog_energy_message(char *msg, size_t len, long long step, double jump, long long id,
                                double limit, double total_ref, long long ref_step,
                                double total_now);

#ifdef __cplusplus
}
#endif
#endif /* JDEM_KERNEL_WATCHDOG_H */
