/*
 * integrate.c — one time step, written exactly as LIGGGHTS `fix nve/sphere` (initial_integrate,
 * neighbour check, force computation, final_integrate) so that one- and two-particle cases agree
 * with LIGGGHTS to round-off: same expressions, same evaluation order.  The loops are split by
 * particle over the threads (each particle's update is independent, so the result does not
 * depend on the thread count at all).
 */
#ifdef _OPENMP
#include <omp.h>
#endif

#include "sim.h"

/* Whether a double is not finite, as arithmetic (x - x is 0 for every finite x, NaN for inf
 * and NaN), so that the integration loops stay vectorisable: the watchdog's non-finite probe
 * costs no branch per element. */
static inline int not_finite(double x) { return x - x != 0.0; }

/* The particles [lo, hi) of initial_integrate; returns bit 0: some new x is not finite, bit 1:
 * some particle moved more than half the skin.  A separate function with restrict arrays, so
 * that the compiler vectorises it (inside an OpenMP region the arrays reach the loop through
 * the region's shared data, and their independence is lost). */
static int kick_drift(long lo, long hi, double *restrict x, double *restrict v, double *restrict w,
                      const double *restrict x0, const double *restrict f,
                      const double *restrict t, const double *restrict dtfm,
                      const double *restrict dtirot, double dt, double lim) {
    int bad = 0, far = 0;
    for (long i = lo; i < hi; i++) {
        double d[3];
        for (int k = 0; k < 3; k++) {
            v[3 * i + k] += dtfm[i] * f[3 * i + k];
            w[3 * i + k] += dtirot[i] * t[3 * i + k];
            x[3 * i + k] += dt * v[3 * i + k];
            bad |= not_finite(x[3 * i + k]);
            d[k] = x[3 * i + k] - x0[3 * i + k];
        }
        far |= !(jd_dot(d, d) <= lim);
    }
    return bad | (far << 1);
}

/* The particles [lo, hi) of final_integrate; returns 1 when some new v or omega is not finite. */
static int kick(long lo, long hi, double *restrict v, double *restrict w, const double *restrict f,
                const double *restrict t, const double *restrict dtfm,
                const double *restrict dtirot) {
    int bad = 0;
    for (long i = lo; i < hi; i++)
        for (int d = 0; d < 3; d++) {
            v[3 * i + d] += dtfm[i] * f[3 * i + d];
            w[3 * i + d] += dtirot[i] * t[3 * i + d];
            bad |= not_finite(v[3 * i + d]) | not_finite(w[3 * i + d]);
        }
    return bad;
}

/* [lo, hi) of thread tid's share of n particles (the same split as schedule(static)). */
static void share(long n, long *lo, long *hi) {
#ifdef _OPENMP
    const long tid = omp_get_thread_num(), nt = omp_get_num_threads();
#else
    const long tid = 0, nt = 1;
#endif
    *lo = n * tid / nt;
    *hi = n * (tid + 1) / nt;
}

/* initial_integrate: v += (0.5 dt/m) f; omega += (0.5 dt/0.4)/(r r m) torque; x += dt v.
 * dtfm and dtirot are precomputed per particle with exactly LIGGGHTS' expressions, so the
 * products are bit-identical; each particle's update is independent, so doing the kick and the
 * drift in one pass gives LIGGGHTS' numbers exactly.  The same pass checks whether some
 * particle moved more than half the skin since the last neighbour build (*moved; !(<=) so that a
 * NaN position forces a rebuild, which reports it) and returns 1 when some new x is not
 * finite. */
static int initial_integrate(jd_sim *s, int *moved) {
    const double lim = 0.25 * s->skin * s->skin; /* (skin/2)^2 */
    int bits = 0;
#pragma omp parallel num_threads(s->threads) if (s->threads > 1) reduction(| : bits)
    {
        long lo, hi;
        share((long)s->n, &lo, &hi);
        bits |= kick_drift(lo, hi, s->x, s->v, s->omega, s->x_build, s->f, s->torque, s->dtfm,
                           s->dtirot, s->dt, lim);
    }
    *moved = (bits & 2) != 0;
    return bits & 1;
}

/* final_integrate: the same half kick, returning 1 when some new v or omega is not finite. */
static int final_integrate(jd_sim *s) {
    int bad = 0;
#pragma omp parallel num_threads(s->threads) if (s->threads > 1) reduction(| : bad)
    {
        long lo, hi;
        share((long)s->n, &lo, &hi);
        bad |= kick(lo, hi, s->v, s->omega, s->f, s->torque, s->dtfm, s->dtirot);
    }
    return bad;
}

int sim_step(jd_sim *s, char *err, size_t errlen) {
    const double t0 = sim_clock();
    int moved;
    /* A non-finite position stops the step here, before the neighbour search bins it: the run
     * loop's watchdog reports it (sim_watchdog_step) and the run ends. */
    if (initial_integrate(s, &moved)) {
        s->nonfinite = 1;
        s->step++;
        return 0;
    }
    sim_walls_move(s); /* fix move/mesh moves the walls in the same phase as the particles */
    const double t1 = sim_clock();
    if ((moved || sim_neighbour_walls_moved(s)) && sim_neighbour_build(s, err, errlen) != 0) return -1;
    const double t2 = sim_clock();
    sim_compute_forces(s);
    const double t3 = sim_clock();
    s->nonfinite = final_integrate(s);
    s->step++;
    const double t4 = sim_clock();
    s->timing.integration += (t1 - t0) + (t4 - t3);
    s->timing.neighbour += t2 - t1;
    return 0;
}
