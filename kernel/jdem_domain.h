/*
 * jdem_domain.h — the scene's domain (docs/scenes.md "Domain"): one rule for both engines of
 * which particles leave the run and what they take with them.
 *
 * Pure C11: inline functions only.  No I/O, no allocation, no globals.
 *
 * A particle whose centre lies outside the half-open box [lo, hi) along some axis at a neighbour
 * build is deleted.  That is what LIGGGHTS does with `boundary f f f` at a reneighbouring step
 * (LAMMPS' Comm::exchange drops an atom that leaves the box through a non-periodic side; the
 * deck says `thermo_modify lost ignore` so the run goes on): the stepper deletes at its own
 * neighbour builds (stepper/domain.c), the plugin's fix at pre_exchange, which LIGGGHTS calls
 * at its reneighbouring steps.  A particle fast enough to trigger a build every step (in
 * LIGGGHTS, more than skin/2 a step) is deleted in both the step its centre crosses a face
 * (the stepper's half skins never reach past the domain's faces, stepper/neighbour.c); a
 * slower one when the next build comes, which may differ by a few steps between the engines.
 * A non-finite position counts as outside.
 *
 * The energy that leaves with a particle, jd_lost_energy, is booked on the output side of the
 * balance, as the inlets' energy is booked on the input side (jd_obs_lost_energy).
 */
#ifndef JDEM_KERNEL_DOMAIN_H
#define JDEM_KERNEL_DOMAIN_H

#include "jdem_kernel.h"

#ifdef __cplusplus
extern "C" {
#endif

/* 1 when lo[k] <= x[k] < hi[k] along every axis k (x in m); 0 otherwise, and for NaN. */
static inline int jd_inside_domain(const double lo[3], const double hi[3], const double x[3]) {
    return x[0] >= lo[0] && x[0] < hi[0] && x[1] >= lo[1] && x[1] < hi[1] && x[2] >= lo[2] &&
           x[2] < hi[2];
}

/* The energy a deleted particle takes out of the run [J]: 1/2 m v.v + 1/2 I w.w - m g.x, with
 * mass m [kg], moment of inertia I [kg m^2], position x [m], velocity v [m/s], angular velocity
 * w [rad/s] and gravity g [m/s^2] (the gravitational energy is the one of the observables,
 * -m g.x, zero at the origin). */
static inline double jd_lost_energy(double m, double I, const double x[3], const double v[3],
                                    const double w[3], const double g[3]) {
    return 0.5 * m * jd_dot(v, v) + 0.5 * I * jd_dot(w, w) - m * jd_dot(g, x);
}

#ifdef __cplusplus
}
#endif
#endif /* JDEM_KERNEL_DOMAIN_H */
