/*
 * forces.c — force loops.  The scene's feature set (JD_F_* bits) is fixed for a run; the loop
 * body is instantiated once per combination with the bits as a literal constant, so that
 * jd_contact() compiles away every law the scene does not use (DESIGN.md: "leave out what a
 * scene does not need").  Order as LIGGGHTS: pair forces in list order, wall forces, gravity.
 *
 * Threads (sim.h, "Threads"): each list is cut into one contiguous chunk per thread (the same
 * cut for a given list length and thread count); each thread adds into its own buffer of forces
 * and torques, and the reduction sets f and torque per particle to the sum of the buffers in
 * thread order (plus gravity) and zeroes them for the next evaluation: one barrier per
 * evaluation, no atomics.  With one thread the loops add into f and torque directly: exactly
 * the serial loop.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#ifdef _OPENMP
#include <omp.h>
#endif

#if defined(__GNUC__)
#define JD_ALWAYS_INLINE inline __attribute__((always_inline))
#else
#define JD_ALWAYS_INLINE inline
#endif
/* one copy of the law per specialised loop (kernel/jdem_kernel.h, JD_CONTACT_INLINE) */
#define JD_CONTACT_INLINE static JD_ALWAYS_INLINE

#include "geometry.h"
#include "sim.h"

double sim_clock(void) {
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

int sim_forces_init(jd_sim *s) {
    const size_t nb = s->threads > 1 ? (size_t)s->threads * 6 * s->n : 0;
    s->tbuf = nb ? calloc(nb, sizeof *s->tbuf) : NULL;
    s->trips = calloc((size_t)s->threads, sizeof *s->trips);
    return (nb && !s->tbuf) || !s->trips ? -1 : 0;
}

/* Where thread `tid` adds its forces and torques. */
typedef struct acc {
    double *f, *t;
} acc;

static acc acc_of(const jd_sim *s, int tid) {
    if (s->threads == 1) return (acc){s->f, s->torque};
    double *b = s->tbuf + (size_t)tid * 6 * s->n;
    return (acc){b, b + 3 * s->n};
}

/* [lo, hi) of thread tid's chunk of n items. */
static void chunk(size_t n, int tid, int nt, size_t *lo, size_t *hi) {
    *lo = n * (size_t)tid / (size_t)nt;
    *hi = n * (size_t)(tid + 1) / (size_t)nt;
}

static JD_ALWAYS_INLINE void pair_loop(jd_sim *s, const unsigned F, size_t c0, size_t c1, acc a,
                                       jd_overlap_trip *trip) {
    const jd_contact_list *L = &s->pairs;
    const size_t nm = s->n_materials;
    const double *x_v = s->v, *x_w = s->omega;
    const jd_pair_coeffs *co1 = nm == 1 ? s->coeffs : NULL; /* one material: no lookup */
    for (size_t c = c0; c < c1; c++) {
        const int32_t i = L->i[c], j = L->j[c];
        jd_contact_state *st = &L->state[c];
        jd_rolling_state *rs = (F & JD_F_ROLLING) ? &L->roll[c] : NULL;
        jd_contact_geom g;
        if (!sim_pair_geom(s, F, c, i, j, &g)) {
            jd_contact_separate(st, rs);
            continue;
        }
        if (jd_overlap_excessive(g.delta, s->radius[i], s->radius[j], s->max_overlap))
            sim_watchdog_overlap(trip, i, j, g.delta, fmin(s->radius[i], s->radius[j]));
        jd_kinematics k;
        const double *va = x_v + 3 * (size_t)i, *wa = x_w + 3 * (size_t)i;
        const double *vb = x_v + 3 * (size_t)j, *wb = x_w + 3 * (size_t)j;
        for (int d = 0; d < 3; d++) {
            k.va[d] = va[d];
            k.wa[d] = wa[d];
            k.vb[d] = vb[d];
            k.wb[d] = wb[d];
        }
        const jd_pair_coeffs *co =
            co1 ? co1 : &s->coeffs[(size_t)s->species[i] * nm + (size_t)s->species[j]];
        jd_contact_result out;
        if (!jd_contact(F, co, &g, &k, s->dt, st, rs, &out)) continue;
        double *fa = a.f + 3 * (size_t)i, *fb = a.f + 3 * (size_t)j;
        double *ta = a.t + 3 * (size_t)i, *tb = a.t + 3 * (size_t)j;
        for (int d = 0; d < 3; d++) {
            fa[d] -= out.f[d];
            fb[d] += out.f[d];
            ta[d] += out.ta[d];
            tb[d] += out.tb[d];
        }
    }
}

/* Returns the work the walls did on the particles of the chunk. */
static JD_ALWAYS_INLINE double wall_loop(jd_sim *s, const unsigned F, size_t c0, size_t c1, acc a,
                                         jd_overlap_trip *trip) {
    const jd_contact_list *L = &s->wall_pairs;
    const size_t nm = s->n_materials;
    double work = 0.0;
    for (size_t c = c0; c < c1; c++) {
        const int32_t i = L->i[c];
        const jd_sim_wall *w = &s->walls[L->j[c]];
        jd_contact_state *st = &L->state[c];
        jd_rolling_state *rs = (F & JD_F_ROLLING) ? &L->roll[c] : NULL;
        jd_contact_geom g;
        if (!sim_wall_geom(s, i, w, &g)) {
            jd_contact_separate(st, rs);
            continue;
        }
        if (jd_overlap_excessive(g.delta, s->radius[i], INFINITY, s->max_overlap))
            sim_watchdog_overlap(trip, i, -1 - L->j[c], g.delta, s->radius[i]);
        jd_kinematics k;
        for (int d = 0; d < 3; d++) {
            k.va[d] = s->v[3 * (size_t)i + d];
            k.wa[d] = s->omega[3 * (size_t)i + d];
            k.vb[d] = w->v[d];
            k.wb[d] = 0.0;
        }
        const jd_pair_coeffs *co = &s->coeffs[(size_t)s->species[i] * nm + (size_t)w->material];
        jd_contact_result out;
        const double f_prev[3] = {st->f_prev[0], st->f_prev[1], st->f_prev[2]};
        const int carries = jd_contact(F, co, &g, &k, s->dt, st, rs, &out);
        if (F & JD_F_ENERGY) /* also over the step a contact ends */
            work += jd_wall_work(f_prev, out.f, w->v, s->dt);
        if (!carries) continue;
        double *fa = a.f + 3 * (size_t)i, *ta = a.t + 3 * (size_t)i;
        for (int d = 0; d < 3; d++) {
            fa[d] -= out.f[d];
            ta[d] += out.ta[d];
        }
    }
    return work;
}

/* This thread's share of the contact loops; returns its wall work.  *t_pairs_end: when thread 0
 * finished its share of the pairs (with threads, the split of the timing is thread 0's). */
static JD_ALWAYS_INLINE double contact_loops(jd_sim *s, const unsigned F, int tid, int nt,
                                             double *t_pairs_end) {
    const acc a = acc_of(s, tid);
    jd_overlap_trip *trip = &s->trips[tid];
    size_t lo, hi;
    chunk(s->pairs.n, tid, nt, &lo, &hi);
    pair_loop(s, F, lo, hi, a, trip);
    if (tid == 0) *t_pairs_end = sim_clock();
    chunk(s->wall_pairs.n, tid, nt, &lo, &hi);
    return wall_loop(s, F, lo, hi, a, trip);
}

/* One instantiation per combination of the four optional laws and the energy bookkeeping
 * (output.energy).  The switch maps the run-time bits to a literal constant. */
#define JD_FORCE_CASE(bits)                                                     \
    case (bits):                                                                \
        work = contact_loops(s, (bits), tid, nt, &t_pairs_end);                 \
        break;
#define JD_FORCE_CASES(e)                                                                     \
    JD_FORCE_CASE((e) | 0) JD_FORCE_CASE((e) | 1) JD_FORCE_CASE((e) | 2) JD_FORCE_CASE((e) | 3)     \
    JD_FORCE_CASE((e) | 4) JD_FORCE_CASE((e) | 5) JD_FORCE_CASE((e) | 6) JD_FORCE_CASE((e) | 7)     \
    JD_FORCE_CASE((e) | 8) JD_FORCE_CASE((e) | 9) JD_FORCE_CASE((e) | 10) JD_FORCE_CASE((e) | 11)   \
    JD_FORCE_CASE((e) | 12) JD_FORCE_CASE((e) | 13) JD_FORCE_CASE((e) | 14) JD_FORCE_CASE((e) | 15)

static double dispatch(jd_sim *s, int tid, int nt, double *t_pairs_end_out) {
    double work = 0.0, t_pairs_end = 0.0;
    _Static_assert(JD_F_DAMPING == 1 && JD_F_FRICTION == 2 && JD_F_ROLLING == 4 && JD_F_MU_R == 8 &&
                       JD_F_ENERGY == 16,
                   "the dispatch below enumerates the four optional laws as bits 0-3, energy as 4");
    switch (s->features & 31u) {
        JD_FORCE_CASES(0)
        JD_FORCE_CASES(16)
    }
    if (tid == 0) *t_pairs_end_out = t_pairs_end;
    return work;
}

/* With threads: f = the sum of the threads' buffers in thread order (zeroing them), for
 * particles [lo, hi). */
static void reduce(jd_sim *s, size_t lo, size_t hi) {
    const size_t n = s->n;
    for (int t = 0; t < s->threads; t++) {
        double *bf = s->tbuf + (size_t)t * 6 * n, *bt = bf + 3 * n;
        for (size_t k = 3 * lo; k < 3 * hi; k++) {
            s->f[k] = t ? s->f[k] + bf[k] : bf[k];
            s->torque[k] = t ? s->torque[k] + bt[k] : bt[k];
            bf[k] = bt[k] = 0.0;
        }
    }
}

static void gravity(jd_sim *s) {
    const double *g = s->g;
    if (g[0] == 0.0 && g[1] == 0.0 && g[2] == 0.0) return;
    const long n = (long)s->n;
    double *f = s->f;
    const double *mass = s->mass;
#pragma omp parallel for schedule(static) num_threads(s->threads) if (s->threads > 1)
    for (long i = 0; i < n; i++)
        for (int d = 0; d < 3; d++) f[3 * i + d] += mass[i] * g[d];
}

void sim_compute_forces(jd_sim *s) {
    const int nt = s->threads;
    double work[nt > 0 ? nt : 1];
    double t_pairs_end = 0.0, t_walls_end = 0.0;
    const double t0 = sim_clock();
#pragma omp parallel num_threads(nt) if (nt > 1)
    {
#ifdef _OPENMP
        const int tid = omp_get_thread_num();
#else
        const int tid = 0;
#endif
        if (nt == 1) { /* the loops add into f and torque directly */
            memset(s->f, 0, 3 * s->n * sizeof *s->f);
            memset(s->torque, 0, 3 * s->n * sizeof *s->torque);
        }
        s->trips[tid].fraction = 0.0;
        work[tid] = dispatch(s, tid, nt, &t_pairs_end);
        if (nt > 1) {
#pragma omp barrier
            size_t lo, hi;
            chunk(s->n, tid, nt, &lo, &hi);
            reduce(s, lo, hi);
        }
        if (tid == 0) t_walls_end = sim_clock();
    }
    /* the worst overlap of this evaluation (the first thread's on a tie, as in serial order) */
    s->overlap_trip.fraction = 0.0;
    for (int t = 0; t < nt; t++) {
        if (s->trips[t].fraction > s->overlap_trip.fraction) s->overlap_trip = s->trips[t];
        s->wall_work += work[t];
    }
    /* then in LIGGGHTS' order: bonds (in parallel with the contacts, bonds.c), gravity, and the
     * post-force loads (loads.c) */
    if (s->bonds) sim_bonds_forces(s);
    gravity(s);
    if (s->loads) sim_loads_apply(s);
    const double t1 = sim_clock();
    s->timing.pairs += (t_pairs_end - t0) + (t1 - t_walls_end);
    s->timing.walls += t_walls_end - t_pairs_end;
}
