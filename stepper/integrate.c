/*
 * integrate.c — one time step, written exactly as LIGGGHTS `fix nve/sphere` (initial_integrate,
 * neighbour check, force computation, final_integrate) so that one- and two-particle cases agree
 * with LIGGGHTS to round-off: same expressions, same evaluation order.  When nothing looks at
 * the state between two steps (no frame, no observables), the first step's final_integrate is
 * done in the second step's first pass, which gives the same numbers and streams the particle
 * arrays once per step instead of twice (docs/performance.md); the kick after a force
 * evaluation also adds the weight m g when the evaluation left it out (sim.h, weight_in_kick),
 * which saves gravity's pass over f (the same sums).  The loops are split by
 * particle over the threads (each particle's update is independent, so the result does not
 * depend on the thread count at all).
 */
#ifdef _OPENMP
#include <omp.h>
#endif

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include "mesh_walls.h"
#include "sim.h"

/* Whether a double is not finite, as arithmetic (x - x is 0 for every finite x, NaN for inf
 * and NaN), so that the integration loops stay vectorisable: the watchdog's non-finite probe
 * costs no branch per element. */
static inline int not_finite(double x) { return x - x != 0.0; }

/* What the passes take besides the arrays, as plain values (only the arrays carry restrict). */
typedef struct pass_consts {
    double dt;                 /* [s] */
    double g[3];               /* gravity [m/s^2], for the weight m g (s->fast.weight_in_kick) */
    double dtfm, dtirot, mass; /* every particle's, when they are uniform (s->fast.uniform_mass) */
} pass_consts;

/* The literal flags of a pass's compiled copies: twice, the last step's final half kick first
 * (s->kick_pending); weight, add m g to the force the kicks use (s->fast.weight_in_kick); uniform,
 * take dtfm, dtirot and m from pass_consts rather than streaming their arrays; check, compare
 * each new position with x_build (the rebuild check) rather than only find the largest speed
 * (s->lists.drift_bound). */
enum { P_TWICE = 1, P_WEIGHT = 2, P_UNIFORM = 4, P_CHECK = 8 };

/* The rebuild check of particle i: 1 when it moved more than its half skin hs[i] since the
 * last neighbour build (!(<=) so that a NaN position counts as moved). */
static JD_ALWAYS_INLINE int
moved_far(const double *restrict x, const double *restrict x0, const double *restrict hs, long i) {
    const double d[3] = {x[3 * i] - x0[3 * i], x[3 * i + 1] - x0[3 * i + 1],
                         x[3 * i + 2] - x0[3 * i + 2]};
    return !(jd_dot(d, d) <= hs[i] * hs[i]);
}

/* The particles [lo, hi) of initial_integrate, and with twice first the last step's
 * final_integrate, in the same pass: nothing looked at the state in between (sim_step).
 * Each half kick is rounded as in its own pass (C11 contracts no multiply-add), so the numbers
 * are those of kick then the single kick and drift, bit for bit; so is the weight, f + m g,
 * the sum the force evaluation would have stored (forces.c, sim_gravity).  The force with its
 * weight is not stored: nothing looks at it before the next evaluation zeroes it.  Returns
 * bit 0: some new x is not finite; bit 1 (check): some particle moved more than its half skin
 * since the last neighbour build; bit 2 (twice): some v or omega after the first half kick, the
 * last step's state, is not finite.  Without check, *vmax2 is the largest squared speed of the
 * drift instead (NaN if some speed is NaN). */
static JD_ALWAYS_INLINE int
kick_drift_pass(long lo, long hi, double *restrict x, double *restrict v, double *restrict w,
                const double *restrict x0, const double *restrict hs, const double *restrict f,
                const double *restrict t, const double *restrict dtfm, const double *restrict dtirot,
                const double *restrict mass, const pass_consts *c, double *vmax2,
                const int twice, const int weight, const int uniform, const int check) {
    const double dt = c->dt, g[3] = {c->g[0], c->g[1], c->g[2]};
    int bad = 0, was_bad = 0, far = 0;
    int64_t vm = 0; /* the largest u2 below, as its bits: see there */
    for (long i = lo; i < hi; i++) {
        const double a = uniform ? c->dtfm : dtfm[i], b = uniform ? c->dtirot : dtirot[i];
        const double m = uniform ? c->mass : weight ? mass[i] : 0.0;
        double u[3];
        for (int k = 0; k < 3; k++) {
            const double fk = weight ? f[3 * i + k] + m * g[k] : f[3 * i + k];
            const double dv = a * fk, dw = b * t[3 * i + k];
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
            u[k] = vn;
        }
        if (check) {
            far |= moved_far(x, x0, hs, i);
        } else {
            /* u2 >= +0 (or NaN), whose bits order as the numbers do: an integer maximum, which
             * GCC vectorises (a floating-point one only with -ffinite-math-only;
             * docs/performance.md) */
            const double u2 = jd_dot(u, u);
            int64_t ub;
            memcpy(&ub, &u2, sizeof ub);
            vm = ub > vm ? ub : vm;
        }
    }
    if (!check) memcpy(vmax2, &vm, sizeof *vmax2);
    return bad | (far << 1) | (was_bad << 2);
}

/* The particles [lo, hi) of final_integrate; with weight the force gets its weight first, and
 * keeps it (the state is looked at).  Returns 1 when some new v or omega is not finite. */
static JD_ALWAYS_INLINE int
kick_pass(long lo, long hi, double *restrict v, double *restrict w, double *restrict f,
          const double *restrict t, const double *restrict dtfm, const double *restrict dtirot,
          const double *restrict mass, const pass_consts *c, const int weight, const int uniform) {
    const double g[3] = {c->g[0], c->g[1], c->g[2]};
    int bad = 0;
    for (long i = lo; i < hi; i++) {
        const double a = uniform ? c->dtfm : dtfm[i], b = uniform ? c->dtirot : dtirot[i];
        const double m = uniform ? c->mass : weight ? mass[i] : 0.0;
        for (int d = 0; d < 3; d++) {
            const double fd = weight ? f[3 * i + d] + m * g[d] : f[3 * i + d];
            if (weight) f[3 * i + d] = fd;
            v[3 * i + d] += a * fd;
            w[3 * i + d] += b * t[3 * i + d];
            bad |= not_finite(v[3 * i + d]) | not_finite(w[3 * i + d]);
        }
    }
    return bad;
}

/* The compiled copies, one per set of flags (a literal each): a run-time flag inside the loop
 * made GCC give up the vectorisation (docs/performance.md).  Separate
 * functions with restrict arrays: inside an OpenMP region the arrays reach the loop through the
 * region's shared data, and their independence is lost. */
static int kick_drift(int flags, long lo, long hi, double *restrict x, double *restrict v,
                      double *restrict w, const double *restrict x0, const double *restrict hs,
                      const double *restrict f, const double *restrict t, const double *restrict dtfm,
                      const double *restrict dtirot, const double *restrict mass,
                      const pass_consts *c, double *vmax2) {
#define JD_KICK_DRIFT(tw, we, un, ch) \
    kick_drift_pass(lo, hi, x, v, w, x0, hs, f, t, dtfm, dtirot, mass, c, vmax2, tw, we, un, ch)
    switch (flags) {
    case 0: return JD_KICK_DRIFT(0, 0, 0, 0);
    case P_UNIFORM: return JD_KICK_DRIFT(0, 0, 1, 0);
    case P_TWICE: return JD_KICK_DRIFT(1, 0, 0, 0);
    case P_TWICE | P_UNIFORM: return JD_KICK_DRIFT(1, 0, 1, 0);
    case P_TWICE | P_WEIGHT: return JD_KICK_DRIFT(1, 1, 0, 0);
    case P_TWICE | P_WEIGHT | P_UNIFORM: return JD_KICK_DRIFT(1, 1, 1, 0);
    case P_CHECK: return JD_KICK_DRIFT(0, 0, 0, 1);
    case P_CHECK | P_UNIFORM: return JD_KICK_DRIFT(0, 0, 1, 1);
    case P_CHECK | P_TWICE: return JD_KICK_DRIFT(1, 0, 0, 1);
    case P_CHECK | P_TWICE | P_UNIFORM: return JD_KICK_DRIFT(1, 0, 1, 1);
    case P_CHECK | P_TWICE | P_WEIGHT: return JD_KICK_DRIFT(1, 1, 0, 1);
    default: return JD_KICK_DRIFT(1, 1, 1, 1); /* P_CHECK | P_TWICE | P_WEIGHT | P_UNIFORM */
    }
#undef JD_KICK_DRIFT
}

/* The rebuild check alone over [lo, hi): 1 when some particle moved more than its half skin
 * since the last neighbour build. */
static int far_check(long lo, long hi, const double *restrict x, const double *restrict x0,
                     const double *restrict hs) {
    int far = 0;
    for (long i = lo; i < hi; i++) far |= moved_far(x, x0, hs, i);
    return far;
}

static int kick(int flags, long lo, long hi, double *restrict v, double *restrict w,
                double *restrict f, const double *restrict t, const double *restrict dtfm,
                const double *restrict dtirot, const double *restrict mass, const pass_consts *c) {
#define JD_KICK(we, un) kick_pass(lo, hi, v, w, f, t, dtfm, dtirot, mass, c, we, un)
    switch (flags) {
    case 0: return JD_KICK(0, 0);
    case P_UNIFORM: return JD_KICK(0, 1);
    case P_WEIGHT: return JD_KICK(1, 0);
    default: return JD_KICK(1, 1); /* P_WEIGHT | P_UNIFORM */
    }
#undef JD_KICK
}

static pass_consts consts_of(const jd_particles *ps, const jd_run_constants *run,
                             const jd_fast_paths *fast) {
    pass_consts c = {.dt = run->dt, .g = {run->g[0], run->g[1], run->g[2]}};
    if (fast->uniform_mass) {
        c.dtfm = ps->dtfm[0];
        c.dtirot = ps->dtirot[0];
        c.mass = ps->mass[0];
    }
    return c;
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

/* While s->lists.drift_bound is at most this fraction of half the common skin, no particle can
 * have moved its own half skin (never less, neighbour.c half_skin_of) since the last build,
 * and the passes need not read x_build. */
#define JD_DRIFT_SAFE 0.5

/* initial_integrate: v += (0.5 dt/m) f; omega += (0.5 dt/0.4)/(r r m) torque; x += dt v.
 * dtfm and dtirot are precomputed per particle with exactly LIGGGHTS' expressions, so the
 * products are bit-identical; each particle's update is independent, so doing the kick and the
 * drift in one pass gives LIGGGHTS' numbers exactly.  With s->kick_pending the pass first
 * applies the last step's final half kick (kick_drift with P_TWICE), with the weight if the
 * force evaluation left it out.
 *
 * The rebuild check (LIGGGHTS' `neigh_modify check yes`, each particle against its own half
 * skin, lists.half_skin): *moved when some particle moved more than its half skin since the
 * last neighbour build.  Exactly that test decides, but it reads x_build, a stream as large as
 * x; so while the sum over the steps of dt times the largest speed (s->lists.drift_bound, which
 * no particle's displacement can exceed) stays within JD_DRIFT_SAFE of half the common skin
 * (no half skin is smaller), the pass only finds the largest speed, and on the step the
 * sum passes that mark the exact test runs on its own (far_check), then in the pass until the
 * next build.  The rebuilds come at the same steps either way: in a settled bed the sum stays
 * far below the mark, in a pour it passes it a few steps after each build.
 *
 * pending: the last step's final half kick is still to do; plain: the reference path (the exact
 * check at every step).  Returns bit 0: some new x is not finite; bit 2: the pending kick left
 * some v or omega not finite. */
static int initial_integrate(jd_particles *ps, jd_neighbour_lists *lists,
                             const jd_run_constants *run, const jd_fast_paths *fast,
                             const jd_thread_layout *threads, int pending, int plain,
                             int *moved) {
    const pass_consts c = consts_of(ps, run, fast);
    const double safe = JD_DRIFT_SAFE * 0.5 * lists->skin;
    const int check = plain || !(lists->drift_bound <= safe); /* plain: the reference */
    const int flags = (pending ? P_TWICE : 0) | (pending && fast->weight_in_kick ? P_WEIGHT : 0) |
                      (fast->uniform_mass ? P_UNIFORM : 0) | (check ? P_CHECK : 0);
    int bits = 0;
    double vmax2 = 0.0;
#pragma omp parallel num_threads(threads->n) if (threads->n > 1) reduction(| : bits) reduction(max : vmax2)
    {
        long lo, hi;
        double vm = 0.0;
        share((long)ps->n, &lo, &hi);
        bits |= kick_drift(flags, lo, hi, ps->x, ps->v, ps->omega, lists->x_build, lists->half_skin,
                           ps->f, ps->torque, ps->dtfm, ps->dtirot, ps->mass, &c, &vm);
        if (vm > vmax2) vmax2 = vm;
    }
    if (!check) {
        lists->drift_bound += run->dt * sqrt(vmax2);
        if (!(lists->drift_bound <= safe)) {
            int far = 0;
#pragma omp parallel num_threads(threads->n) if (threads->n > 1) reduction(| : far)
            {
                long lo, hi;
                share((long)ps->n, &lo, &hi);
                far |= far_check(lo, hi, ps->x, lists->x_build, lists->half_skin);
            }
            bits |= far << 1;
        }
    }
    *moved = (bits & 2) != 0;
    return bits & 5;
}

/* final_integrate: the same half kick, returning 1 when some new v or omega is not finite.  The
 * force it follows is always a fresh evaluation's (sim_step, sim_finish_step): with
 * s->fast.weight_in_kick the weight is added to it here, and kept. */
static int final_integrate(jd_particles *ps, const jd_run_constants *run,
                           const jd_fast_paths *fast, const jd_thread_layout *threads) {
    const pass_consts c = consts_of(ps, run, fast);
    const int flags = (fast->weight_in_kick ? P_WEIGHT : 0) | (fast->uniform_mass ? P_UNIFORM : 0);
    int bad = 0;
#pragma omp parallel num_threads(threads->n) if (threads->n > 1) reduction(| : bad)
    {
        long lo, hi;
        share((long)ps->n, &lo, &hi);
        bad |= kick(flags, lo, hi, ps->v, ps->omega, ps->f, ps->torque, ps->dtfm, ps->dtirot, ps->mass,
                    &c);
    }
    return bad;
}

void sim_finish_step(jd_sim *s) {
    if (!s->kick_pending) return;
    const double t0 = sim_clock();
    s->watch.nonfinite |= final_integrate(&s->particles, &s->run, &s->fast, &s->threads);
    s->kick_pending = 0;
    s->accounts.timing.integration += sim_clock() - t0;
}

int sim_step(jd_sim *s, int seen, char *err, size_t errlen) {
    const double t0 = sim_clock();
    int moved;
    const int bad = initial_integrate(&s->particles, &s->lists, &s->run, &s->fast, &s->threads,
                                      s->kick_pending, s->opt.plain_loops, &moved);
    s->kick_pending = 0;
    if (bad & 4) {
        /* the last step's forces gave a non-finite v or omega: that step's state is the one to
         * report (as without the deferred kick); the watchdog names the force or torque, which
         * gets its weight as final_integrate would have given it */
        if (s->fast.weight_in_kick) sim_gravity(&s->particles, &s->run, &s->threads);
        s->watch.nonfinite = 1;
        return 0;
    }
    /* A non-finite position stops the step here, before the neighbour search bins it: the run
     * loop's watchdog reports it (sim_watchdog_step) and the run ends. */
    if (bad) {
        s->watch.nonfinite = 1;
        s->step++;
        return 0;
    }
    /* fix move/mesh moves the walls in the same phase as the particles */
    sim_walls_move(&s->walls, s->run.dt);
    if (s->meshes) sim_mesh_walls_move(s->meshes, s->run.dt, s->lists.skin);
    const double t1 = sim_clock();
    if ((moved || sim_neighbour_walls_moved(&s->walls, s->lists.skin)) &&
        (sim_domain_delete(s, 1, err, errlen) != 0 || sim_neighbour_build(s, err, errlen) != 0))
        return -1;
    const double t2 = sim_clock();
    sim_compute_forces(s);
    if (s->meshes && s->meshes->error[0]) {
        snprintf(err, errlen, "%s", s->meshes->error);
        return -1;
    }
    const double t3 = sim_clock();
    if (seen)
        s->watch.nonfinite = final_integrate(&s->particles, &s->run, &s->fast, &s->threads);
    else
        s->kick_pending = 1;
    s->step++;
    const double t4 = sim_clock();
    s->accounts.timing.integration += (t1 - t0) + (t4 - t3);
    s->accounts.timing.neighbour += t2 - t1;
    return 0;
}
