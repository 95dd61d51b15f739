/*
 * integrate.c — one time step, written exactly as LIGGGHTS `fix nve/sphere` (initial_integrate,
 * neighbour check, force computation, final_integrate) so that one- and two-particle cases agree
 * with LIGGGHTS to round-off: same expressions, same evaluation order.  When nothing looks at
 * the state between two steps (no frame, no observables), the first step's final_integrate is
 * done in the second step's first pass, which gives the same numbers and streams the particle
 * arrays once per step instead of twice (docs/performance.md).  The loops are split by
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

/* The particles [lo, hi) of initial_integrate, and with twice (s->kick_pending) first the last
 * step's final_integrate, in the same pass: nothing looked at the state in between (sim_step).
 * Each half kick is rounded as in its own pass (C11 contracts no multiply-add), so the numbers
 * are those of kick then the single kick and drift, bit for bit.  Returns bit 0: some new x is
 * not finite; bit 1: some particle moved more than half the skin; bit 2 (twice): some v or
 * omega after the first half kick, the last step's state, is not finite.  Called through
 * separate functions with restrict arrays, so that the compiler vectorises it (inside an OpenMP
 * region the arrays reach the loop through the region's shared data, and their independence is
 * lost). */
static inline __attribute__((always_inline)) int
kick_drift_pass(long lo, long hi, double *restrict x, double *restrict v, double *restrict w,
                const double *restrict x0, const double *restrict f, const double *restrict t,
                const double *restrict dtfm, const double *restrict dtirot, double dt, double lim,
                const int twice) {
    int bad = 0, was_bad = 0, far = 0;
    for (long i = lo; i < hi; i++) {
        double d[3];
        for (int k = 0; k < 3; k++) {
            const double dv = dtfm[i] * f[3 * i + k], dw = dtirot[i] * t[3 * i + k];
            double vn = v[3 * i + k] + dv, wn = w[3 * i + k] + dw;
            if (twice) {
                was_bad |= not_finite(vn) | not_finite(wn);
                vn += dv;
                wn += dw;
            }
            v[3 * i + k] = vn;
            w[3 * i + k] = wn;
            x[3 * i + k] += dt * vn;
            bad |= not_finite(x[3 * i + k]);
            d[k] = x[3 * i + k] - x0[3 * i + k];
        }
        far |= !(jd_dot(d, d) <= lim);
    }
    return bad | (far << 1) | (was_bad << 2);
}

/* One compiled copy each (twice a literal): a run-time twice made GCC give up the
 * vectorisation (20k integration 0.069 s against 0.026 s). */
static int kick_drift(long lo, long hi, double *restrict x, double *restrict v, double *restrict w,
                      const double *restrict x0, const double *restrict f,
                      const double *restrict t, const double *restrict dtfm,
                      const double *restrict dtirot, double dt, double lim) {
    return kick_drift_pass(lo, hi, x, v, w, x0, f, t, dtfm, dtirot, dt, lim, 0);
}
static int kick_kick_drift(long lo, long hi, double *restrict x, double *restrict v,
                           double *restrict w, const double *restrict x0, const double *restrict f,
                           const double *restrict t, const double *restrict dtfm,
                           const double *restrict dtirot, double dt, double lim) {
    return kick_drift_pass(lo, hi, x, v, w, x0, f, t, dtfm, dtirot, dt, lim, 1);
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
 * drift in one pass gives LIGGGHTS' numbers exactly.  With s->kick_pending the pass first
 * applies the last step's final half kick (kick_kick_drift).  The same pass checks whether some
 * particle moved more than half the skin since the last neighbour build (*moved; !(<=) so that a
 * NaN position forces a rebuild, which reports it).  Returns bit 0: some new x is not finite;
 * bit 2: the pending kick left some v or omega not finite. */
static int initial_integrate(jd_sim *s, int *moved) {
    const double lim = 0.25 * s->skin * s->skin; /* (skin/2)^2 */
    const int pending = s->kick_pending;
    int bits = 0;
#pragma omp parallel num_threads(s->threads) if (s->threads > 1) reduction(| : bits)
    {
        long lo, hi;
        share((long)s->n, &lo, &hi);
        if (pending)
            bits |= kick_kick_drift(lo, hi, s->x, s->v, s->omega, s->x_build, s->f, s->torque,
                                    s->dtfm, s->dtirot, s->dt, lim);
        else
            bits |= kick_drift(lo, hi, s->x, s->v, s->omega, s->x_build, s->f, s->torque,
                               s->dtfm, s->dtirot, s->dt, lim);
    }
    s->kick_pending = 0;
    *moved = (bits & 2) != 0;
    return bits & 5;
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

void sim_finish_step(jd_sim *s) {
    if (!s->kick_pending) return;
    const double t0 = sim_clock();
    s->nonfinite |= final_integrate(s);
    s->kick_pending = 0;
    s->timing.integration += sim_clock() - t0;
}

int sim_step(jd_sim *s, int seen, char *err, size_t errlen) {
    const double t0 = sim_clock();
    int moved;
    const int bad = initial_integrate(s, &moved);
    if (bad & 4) {
        /* the last step's forces gave a non-finite v or omega: that step's state is the one to
         * report (as without the deferred kick); the watchdog names the force or torque */
        s->nonfinite = 1;
        return 0;
    }
    /* A non-finite position stops the step here, before the neighbour search bins it: the run
     * loop's watchdog reports it (sim_watchdog_step) and the run ends. */
    if (bad) {
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
    if (seen)
        s->nonfinite = final_integrate(s);
    else
        s->kick_pending = 1;
    s->step++;
    const double t4 = sim_clock();
    s->timing.integration += (t1 - t0) + (t4 - t3);
    s->timing.neighbour += t2 - t1;
    return 0;
}
