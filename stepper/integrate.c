/*
 * integrate.c — one time step, written exactly as LIGGGHTS `fix nve/sphere` (initial_integrate,
 * neighbour check, force computation, final_integrate) so that one- and two-particle cases agree
 * with LIGGGHTS to round-off: same expressions, same evaluation order.
 */
#include "sim.h"

/* v += (0.5 dt/m) f; omega += (0.5 dt/0.4)/(r r m) torque.  dtfm and dtirot are precomputed per
 * particle with exactly LIGGGHTS' expressions, so the products are bit-identical. */
static void half_kick(jd_sim *s) {
    for (size_t i = 0; i < s->n; i++) {
        const double dtfm = s->dtfm[i], dtirot = s->dtirot[i];
        for (int d = 0; d < 3; d++) {
            s->v[3 * i + d] += dtfm * s->f[3 * i + d];
            s->omega[3 * i + d] += dtirot * s->torque[3 * i + d];
        }
    }
}

/* 1 when some a[k] is not finite: 0 * inf and 0 * NaN are NaN, so the sum is 0 or NaN (-O2
 * without -ffast-math keeps the multiply).  Run right after the loop that wrote a, while it is
 * in cache: the watchdog's non-finite check costs one pass and no branch per element. */
static int any_nonfinite(const double *a, size_t n) {
    double probe = 0.0;
    for (size_t k = 0; k < n; k++) probe += 0.0 * a[k];
    return probe != 0.0;
}

int sim_step(jd_sim *s, char *err, size_t errlen) {
    const double dt = s->dt;
    /* initial_integrate: half kick, then drift with the half-step velocity (per particle the
     * operations are independent, so two loops give LIGGGHTS' numbers exactly) */
    half_kick(s);
    for (size_t k = 0; k < 3 * s->n; k++) s->x[k] += dt * s->v[k];
    /* A non-finite position stops the step here, before the neighbour search bins it: the run
     * loop's watchdog reports it (sim_watchdog_step) and the run ends. */
    if (any_nonfinite(s->x, 3 * s->n)) {
        s->nonfinite = 1;
        s->step++;
        return 0;
    }
    sim_walls_move(s); /* fix move/mesh moves the walls in the same phase as the particles */
    if (sim_neighbour_stale(s) && sim_neighbour_build(s, err, errlen) != 0) return -1;
    sim_compute_forces(s);
    half_kick(s); /* final_integrate */
    s->nonfinite = any_nonfinite(s->v, 3 * s->n) || any_nonfinite(s->omega, 3 * s->n);
    s->step++;
    return 0;
}
