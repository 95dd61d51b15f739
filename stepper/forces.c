/*
 * forces.c — force loops.  The scene's law set (JD_F_* bits, kernel/jdem_laws.h) is fixed for a
 * run; the loop body is instantiated once per compiled law set of the kernel's list
 * (JD_LAW_LOOPS) with the bits as a constant, so that jd_contact() compiles away every law the
 * scene does not use (a scene pays only for what it uses).  A run with a run-time law
 * (JD_F_RUN_TIME: Mindlin's K_t) takes the reference loops, which keep its bit as a value: a
 * branch in the compiled copies would be a select in every SIMD lane of every run.  The sets
 * with energy bookkeeping are compiled in forces_energy.c.  Order as LIGGGHTS: pair forces in
 * list order (the candidates that touched at the build, then the others: sim.h,
 * jd_contact_list), wall forces, mesh walls, gravity.
 *
 * Threads (sim.h, "Threads"): each thread zeroes the forces of the particles it owns, evaluates
 * their entries and adds into f and torque, and into its overflow buffer for partners beyond its
 * particles; after one barrier each thread adds the earlier threads' overflow into its particles
 * in thread order and zeroes it for the next evaluation (then gravity, for all).  No atomics;
 * with one thread this is exactly the serial loop.
 */
#include <math.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#ifdef _OPENMP
#include <omp.h>
#endif

#if defined(__GNUC__)
#define JD_NOINLINE __attribute__((noinline))
#else
#define JD_NOINLINE
#endif

#include "geometry.h"
#include "sim.h"

#ifndef JD_FORCE_LOOPS_ENERGY
double sim_clock(void) {
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}
#endif


/* Where a thread adds its forces and torques: f and torque for particles below hi, its
 * overflow buffer (of, ot: index j - hi) for the partners j >= hi; span: how far beyond its
 * rows i its partners j reach (jd_thread_share, prefetch_particles). */
typedef struct acc {
    double *f, *t, *of, *ot;
    size_t hi, span;
} acc;

static acc acc_of(const jd_particles *ps, const jd_thread_layout *threads, int tid) {
    const jd_thread_share *h = &threads->shares[tid];
    return (acc){ps->f, ps->torque, h->ovf, h->ovf + 3 * h->cap, h->p_hi, h->span};
}

/* History widths of a law set (the kernel's records, jdem_laws.h), compile-time constants in the
 * specialised loops. */
#define HW(F) jd_contact_record_len(F)
#define RW(F) jd_rolling_record_len(F)

/* Entry c's history as the kernel's structs, and back (sim_hist_get/set with the widths known
 * at compile time). */
static JD_ALWAYS_INLINE void hist_load(const jd_contact_list *L, const unsigned F, size_t c,
                                       jd_contact_state *st, jd_rolling_state *rs) {
    jd_record_load(L->hist + (size_t)HW(F) * c, HW(F), L->rhist + (size_t)RW(F) * c, RW(F), st, rs);
}
static JD_ALWAYS_INLINE void hist_store(jd_contact_list *L, const unsigned F, size_t c,
                                        const jd_contact_state *st, const jd_rolling_state *rs) {
    jd_record_store(L->hist + (size_t)HW(F) * c, HW(F), L->rhist + (size_t)RW(F) * c, RW(F), st, rs);
}

/* The pair or wall entry c no longer overlaps: its history as jd_contact_separate leaves it
 * (jd_record_separate; test_kernel checks the kernel keeps exactly the accumulators), written in
 * place: the list holds many such entries every step. */
static JD_ALWAYS_INLINE void hist_separate(jd_contact_list *L, const unsigned F, size_t c) {
    jd_record_separate(L->hist + (size_t)HW(F) * c, HW(F), L->rhist + (size_t)RW(F) * c, RW(F));
}

/* Entry c of a wall that has vanished: its contact ends; returns the work the wall did on it
 * leaving (jd_wall_vanish_work; with energy bookkeeping, else 0) [J]. */
static JD_ALWAYS_INLINE double gone_wall_work(jd_contact_list *L, const unsigned F, size_t c) {
    double work = 0.0;
    if (F & JD_F_ENERGY) {
        jd_contact_state st;
        jd_rolling_state rs;
        hist_load(L, F, c, &st, &rs);
        work = jd_wall_vanish_work(&st);
    }
    hist_separate(L, F, c);
    return work;
}

/* Is entry c's history already as hist_separate leaves it (bit for bit: +0, not -0)?  Most
 * candidates that did not touch at the build never do: checking spares their history the
 * writes. */
static JD_ALWAYS_INLINE int hist_separated(const jd_contact_list *L, const unsigned F, size_t c) {
    const double *h = L->hist + (size_t)HW(F) * c, *r = L->rhist + (size_t)RW(F) * c;
    uint64_t bits = 0, u;
    for (int k = 0; k < HW(F); k++)
        if (k != JD_AT(jd_contact_state, e_damp) && k != JD_AT(jd_contact_state, e_fric)) {
            memcpy(&u, h + k, sizeof u);
            bits |= u;
        }
    for (int k = 0; k < RW(F); k++) {
        memcpy(&u, r + k, sizeof u);
        bits |= u;
    }
    return bits == 0;
}

/* Contacts per batch of the pair loop: a multiple of the widest SIMD vector, few enough that
 * the batch's lanes stay in L1. */
#define JD_BATCH 32

/* One batch of overlapping candidates, one lane each, in structure-of-arrays form: which entry
 * and particles, and what the law returns. */
struct jd_batch {
    int32_t c[JD_BATCH], i[JD_BATCH], j[JD_BATCH]; /* list entry and its particles */
    /* results: force on j, torques on i and j, history after the step */
    double f[3][JD_BATCH], ta[3][JD_BATCH], tb[3][JD_BATCH];
    double xi[3][JD_BATCH], flags[JD_BATCH], theta[3][JD_BATCH];
    double f_prev[3][JD_BATCH], fd_prev[JD_BATCH], u_prev[JD_BATCH], e_damp[JD_BATCH],
        e_fric[JD_BATCH], m_prev[3][JD_BATCH], ts_prev[3][JD_BATCH], td_prev[3][JD_BATCH];
    double delta[JD_BATCH];
    int carries[JD_BATCH], excessive[JD_BATCH];
    /* wall batches: the geometry from the wall's test, the wall's velocity, the coefficients'
     * row, and (energy bookkeeping) the force on the wall before the step */
    double n[3][JD_BATCH], ra[3][JD_BATCH], vw[3][JD_BATCH], f_before[3][JD_BATCH];
    int32_t k_co[JD_BATCH];
    /* packed pair batches, per list entry of the batch: whether its spheres touch
     * (rsq < radsum^2) and then its lane */
    int32_t touch[JD_BATCH], lane[JD_BATCH];
};
typedef struct jd_batch batch;

/* Lane b of a batch: the law on geometry g (touch: the bodies overlap; if not, the history is
 * reset as by jd_contact_separate), kinematics k and coefficients co, starting from the history
 * of list entry c (hist, rhist: the list's arrays); history, force and torques into the lanes. */
static JD_ALWAYS_INLINE void lane_law(const unsigned F, batch *restrict B, int b,
                                      const double *restrict hist, const double *restrict rhist,
                                      int32_t c, const jd_contact_geom *g, const jd_kinematics *k,
                                      const jd_pair_coeffs *co, int touch, double dt) {
    jd_contact_state st;
    jd_rolling_state rs;
    jd_record_load(hist + HW(F) * c, HW(F), rhist + RW(F) * c, RW(F), &st, &rs);
    const double e_damp_in = st.e_damp, e_fric_in = st.e_fric;
    if (F & JD_F_ENERGY)
        for (int d = 0; d < 3; d++) B->f_before[d][b] = st.f_prev[d];
    jd_contact_result out;
    const int carries = jd_contact(F, co, g, k, dt, &st, (F & JD_F_ROLLING) ? &rs : NULL, &out);
    for (int d = 0; d < 3; d++) {
        B->xi[d][b] = touch ? st.xi[d] : 0.0;
        if (F & JD_F_ENERGY) {
            B->f_prev[d][b] = touch ? st.f_prev[d] : 0.0;
            B->ts_prev[d][b] = touch ? st.ts_prev[d] : 0.0;
            B->td_prev[d][b] = touch ? st.td_prev[d] : 0.0;
        }
        if (F & JD_F_ROLLING) B->theta[d][b] = touch ? rs.theta[d] : 0.0;
        if ((F & JD_F_ROLLING) && (F & JD_F_ENERGY)) B->m_prev[d][b] = touch ? rs.m_prev[d] : 0.0;
        B->f[d][b] = out.f[d];
        B->ta[d][b] = out.ta[d];
        B->tb[d][b] = out.tb[d];
    }
    B->flags[b] = touch ? st.flags : 0.0;
    if (F & JD_F_ENERGY) {
        B->fd_prev[b] = touch ? st.fd_prev : 0.0;
        B->u_prev[b] = touch ? st.u_prev : 0.0;
        B->e_damp[b] = touch ? st.e_damp : e_damp_in;
        B->e_fric[b] = touch ? st.e_fric : e_fric_in;
    }
    B->carries[b] = touch & carries;
}

/* Lane b's history into entry c of a list's history arrays. */
static JD_ALWAYS_INLINE void lane_history_write(const unsigned F, const batch *B, int b,
                                                double *hist, double *rhist, size_t c) {
    double *h = hist + (size_t)HW(F) * c, *r = rhist + (size_t)RW(F) * c;
    for (int d = 0; d < 3; d++) h[JD_AT(jd_contact_state, xi) + d] = B->xi[d][b];
    h[JD_AT(jd_contact_state, flags)] = B->flags[b];
    if (F & JD_F_ENERGY) {
        for (int d = 0; d < 3; d++) {
            h[JD_AT(jd_contact_state, f_prev) + d] = B->f_prev[d][b];
            h[JD_AT(jd_contact_state, ts_prev) + d] = B->ts_prev[d][b];
            h[JD_AT(jd_contact_state, td_prev) + d] = B->td_prev[d][b];
        }
        h[JD_AT(jd_contact_state, fd_prev)] = B->fd_prev[b];
        h[JD_AT(jd_contact_state, u_prev)] = B->u_prev[b];
        h[JD_AT(jd_contact_state, e_damp)] = B->e_damp[b];
        h[JD_AT(jd_contact_state, e_fric)] = B->e_fric[b];
    }
    if (F & JD_F_ROLLING)
        for (int d = 0; d < 3; d++) {
            r[JD_AT(jd_rolling_state, theta) + d] = B->theta[d][b];
            if (F & JD_F_ENERGY) r[JD_AT(jd_rolling_state, m_prev) + d] = B->m_prev[d][b];
        }
}

#ifndef JD_FORCE_LOOPS_ENERGY
/* The force loops' per-thread state (sim_init). */
int sim_forces_init(jd_thread_layout *threads) {
    threads->shares = calloc((size_t)threads->n, sizeof *threads->shares);
    threads->trips = calloc((size_t)threads->n, sizeof *threads->trips);
    return !threads->shares || !threads->trips ? -1 : 0;
}

void sim_forces_free(jd_thread_layout *threads) {
    for (int t = 0; threads->shares && t < threads->n; t++) free(threads->shares[t].ovf);
    free(threads->shares);
    free(threads->trips);
}

/* First entry in [lo, hi) of list l with i >= p (a sorted run of the list). */
static size_t first_entry_of(const jd_contact_list *l, size_t lo, size_t hi, size_t p) {
    while (lo < hi) {
        const size_t mid = lo + (hi - lo) / 2;
        if ((size_t)l->i[mid] < p)
            lo = mid + 1;
        else
            hi = mid;
    }
    return lo;
}

/* The estimated cost of a list entry, for splitting the work between the threads, in quarters
 * of a pair entry that touched at the build (one SIMD lane of the law and its scatter): the
 * sphere test of one that did not, and a wall entry (its test, then a lane). */
enum { COST_TOUCH = 4, COST_NEAR = 2, COST_WALL = 7 };

/* The threads' shares of the current lists (sim.h, "Threads"): contiguous particle ranges of
 * about equal estimated cost, the entries of their particles in each sorted run of the lists,
 * and overflow buffers large enough for the partners past each range. */
int sim_forces_partition(jd_thread_layout *threads, const jd_neighbour_lists *lists, size_t n) {
    const int nt = threads->n;
    const jd_contact_list *P = &lists->pairs, *W = &lists->wall_pairs;
    const size_t total = COST_TOUCH * P->n_touch + COST_NEAR * (P->n - P->n_touch) + COST_WALL * W->n;
    /* thread t begins after the particle where the running cost passes t / nt of the total */
    size_t a = 0, q = P->n_touch, w = 0, cost = 0;
    int t = 1;
    threads->shares[0].p_lo = 0;
    for (size_t p = 0; p < n && t < nt; p++) {
        for (; a < P->n_touch && (size_t)P->i[a] == p; a++) cost += COST_TOUCH;
        for (; q < P->n && (size_t)P->i[q] == p; q++) cost += COST_NEAR;
        for (; w < W->n && (size_t)W->i[w] == p; w++) cost += COST_WALL;
        for (; t < nt && cost * (size_t)nt >= total * (size_t)t; t++) threads->shares[t].p_lo = p + 1;
    }
    for (; t < nt; t++) threads->shares[t].p_lo = n;
    for (t = 0; t < nt; t++) {
        jd_thread_share *h = &threads->shares[t];
        h->p_hi = t + 1 < nt ? threads->shares[t + 1].p_lo : n;
        h->pair_lo = first_entry_of(P, 0, P->n_touch, h->p_lo);
        h->pair_hi = first_entry_of(P, h->pair_lo, P->n_touch, h->p_hi);
        h->near_lo = first_entry_of(P, P->n_touch, P->n, h->p_lo);
        h->near_hi = first_entry_of(P, h->near_lo, P->n, h->p_hi);
        h->wall_lo = first_entry_of(W, 0, W->n, h->p_lo);
        h->wall_hi = first_entry_of(W, h->wall_lo, W->n, h->p_hi);
        size_t reach = h->p_hi, span = 0;
        for (size_t c = h->pair_lo; c < h->pair_hi; c++) {
            if ((size_t)P->j[c] + 1 > reach) reach = (size_t)P->j[c] + 1;
            if ((size_t)(P->j[c] - P->i[c]) > span) span = (size_t)(P->j[c] - P->i[c]);
        }
        for (size_t c = h->near_lo; c < h->near_hi; c++) {
            if ((size_t)P->j[c] + 1 > reach) reach = (size_t)P->j[c] + 1;
            if ((size_t)(P->j[c] - P->i[c]) > span) span = (size_t)(P->j[c] - P->i[c]);
        }
        h->win = reach - h->p_hi;
        h->span = span;
        if (h->win > h->cap) {
            double *o = calloc(6 * h->win, sizeof *o);
            if (!o) return -1;
            free(h->ovf);
            h->ovf = o;
            h->cap = h->win;
        }
    }
    return 0;
}

#endif

/* How alike the particles of a scene are (sim.h: pair_row, alike), a compile-time constant of the
 * pair loops: any mix; one material (one coefficient row); one material and one radius (the
 * same constants for every pair). */
enum { JD_KINDS_ANY, JD_KINDS_ONE_MATERIAL, JD_KINDS_ALIKE };

/* B->touch[b] for the pair entries b < nb of indices li, lj: whether the spheres touch
 * (rsq < radsum^2, LIGGGHTS' test).  alike (a literal): every pair's radius sum is radsum, and
 * rad is not read. */
static JD_ALWAYS_INLINE void sphere_test(const double *restrict x, const double *restrict rad,
                                         double radsum, const int alike,
                                         const int32_t *restrict li, const int32_t *restrict lj,
                                         batch *restrict B, int nb) {
    for (int b = 0; b < nb; b++) {
        const int32_t i = li[b], j = lj[b];
        const double dx[3] = {x[3 * j] - x[3 * i], x[3 * j + 1] - x[3 * i + 1], x[3 * j + 2] - x[3 * i + 2]};
        const double rs = alike ? radsum : rad[i] + rad[j];
        B->touch[b] = jd_dot(dx, dx) < rs * rs;
    }
}

/* Whether GCC vectorises a lane loop that reads the history records at a constant stride: it
 * can for a group of 1, 2, 4, ... or 3 doubles. */
static JD_ALWAYS_INLINE int record_widths_vectorise(const unsigned F) {
    const int hw = HW(F), rw = RW(F);
    return (hw == 3 || (hw & (hw - 1)) == 0) && (rw == 3 || (rw & (rw - 1)) == 0);
}

/* Geometry and law for the pair entries [c0, c0 + nb), one SIMD lane per candidate; returns
 * the number of lanes.  Entries that touched at the build (packed = 0): every entry is a lane,
 * the sphere test (LIGGGHTS' rsq < radsum^2, then jd_geom_spheres_fill's) a lane mask rather
 * than a branch; a lane that no longer touches computes the law on a meaningless geometry, then
 * keeps what jd_contact_separate leaves and carries no force.  Entries that did not (packed = 1,
 * sim.h: jd_contact_list): the sphere test runs first over the entries (SIMD), only the
 * touching ones are packed into lanes (without a branch), and the others are separated (left
 * alone when their history already is).  Either way every entry's history is exactly the plain
 * loop's.  The SIMD loops write only the batch (stores to the list there would be stores the
 * compiler cannot tell apart from the particle arrays it gathers from); the history goes to the
 * list in a loop of its own.  The kernel's geometry and law have no data-dependent branches. */
static JD_ALWAYS_INLINE int batch_evaluate(const jd_particles *ps, const jd_run_constants *run,
                                           const jd_fast_paths *fast, jd_contact_list *L,
                                           const unsigned F, const int kinds, const int packed,
                                           batch *restrict B, size_t c0, int nb) {
    const double *restrict x = ps->x, *restrict v = ps->v, *restrict w = ps->omega,
                           *restrict rad = ps->radius;
    double *hist = L->hist, *rhist = L->rhist;
    const int32_t *restrict li = L->i + c0, *restrict lj = L->j + c0;
    const double *restrict kp = ps->kp, *restrict mass = ps->mass, *restrict inertia = ps->inertia;
    const size_t nm = run->n_materials;
    const jd_pair_coeffs *restrict coeffs = run->coeffs;
    const int32_t *restrict species = ps->species;
    const double dt = run->dt, max_overlap = run->max_overlap;
    /* what is the same for every lane, loaded once: saves gathers and the per-pair reads */
    const int one_row = kinds != JD_KINDS_ANY, alike = kinds == JD_KINDS_ALIKE;
    const jd_pair_const pc1 = fast->pc_alike;
    const jd_pair_const_roll pcr1 = fast->pcr_alike;
    const double r1 = fast->r_alike;
    int m = nb;
    /* Records of an odd width (the energy sets': 17 and 6 doubles) are no group of loads the
     * vectoriser can permute, and it does not fall back to one load per lane for a constant
     * stride: read through an index instead, which it gathers. */
    const int indexed = packed || !record_widths_vectorise(F);
    if (indexed && !packed)
        for (int b = 0; b < nb; b++) B->c[b] = b;
    if (packed) {
        /* this copy serves any particles; a bed of alike ones still takes the radius sum from
         * the scene rather than from two gathers per entry */
        if (fast->alike)
            sphere_test(x, NULL, fast->r_alike + fast->r_alike, 1, li, lj, B, nb);
        else
            sphere_test(x, rad, 0.0, 0, li, lj, B, nb);
        m = 0;
        for (int b = 0; b < nb; b++) {
            B->c[m] = b;
            B->lane[b] = m;
            m += B->touch[b];
        }
    }
    for (int q = 0; q < m; q++) {
        /* int indices (vectorisable arithmetic; 3 n < 2^31 is checked at set-up) */
        const int32_t b = indexed ? B->c[q] : q, c = (int32_t)c0 + b, i = li[b], j = lj[b];
        const double dx[3] = {x[3 * j] - x[3 * i], x[3 * j + 1] - x[3 * i + 1], x[3 * j + 2] - x[3 * i + 2]};
        const double ri = alike ? r1 : rad[i], rj = alike ? r1 : rad[j];
        const double rsq = jd_dot(dx, dx), radsum = ri + rj;
        jd_contact_geom g;
        const int touch = (rsq < radsum * radsum) & jd_geom_spheres_fill(dx, rsq, ri, rj, &g);
        if (alike) {
            g.k_n = pc1.k_n;
            g.m_eff = pc1.m_eff;
            g.i_eff = (F & JD_F_ROLLING) ? pcr1.i_eff : 0.0;
            g.r_roll = (F & JD_F_READS_R_STAR) ? pcr1.r_roll : 0.0;
        } else { /* the pair's constants from the particles' (sim_pair_constants) */
            jd_geom_pair_material(F, &g, kp[i], kp[j], mass[i], mass[j], inertia[i], inertia[j]);
            g.r_roll = (F & JD_F_READS_R_STAR) ? jd_rolling_radius(ri, rj) : 0.0;
        }
        const int32_t k_co = one_row ? fast->pair_row : species[i] * (int32_t)nm + species[j];
        const jd_pair_coeffs co = coeffs[k_co];
        jd_kinematics k;
        for (int d = 0; d < 3; d++) {
            k.va[d] = v[3 * i + d];
            k.wa[d] = w[3 * i + d];
            k.vb[d] = v[3 * j + d];
            k.wb[d] = w[3 * j + d];
        }
        lane_law(F, B, q, hist, rhist, c, &g, &k, &co, touch, dt);
        B->i[q] = i;
        B->j[q] = j;
        B->delta[q] = g.delta;
        B->excessive[q] = touch & jd_overlap_excessive(g.delta, ri, rj, max_overlap);
    }
    if (!packed)
        for (int b = 0; b < nb; b++) lane_history_write(F, B, b, hist, rhist, c0 + (size_t)b);
    else
        for (int b = 0; b < nb; b++) {
            if (B->touch[b])
                lane_history_write(F, B, B->lane[b], hist, rhist, c0 + (size_t)b);
            else if (!hist_separated(L, F, c0 + (size_t)b))
                hist_separate(L, F, c0 + (size_t)b);
        }
    return m;
}

/* Lanes [0, nb) back: overlaps beyond the watchdog's limit, and the forces and torques of the
 * lanes that carry one added, first on the j particles, then on the i particles, each pass in
 * list order.  That is exactly the order of a plain loop over the list, one contact at a time,
 * for every particle p: p is j only in entries of particles i < p, all listed before p's own
 * run as i, so its sums as j all precede those as i in the list, and each pass keeps their
 * order.  Without the interleaving, neither pass has a data-dependent branch.  The lanes that
 * carry no force are dropped first, also without a branch (a third of the candidates of a
 * settled bed do not touch, in no predictable pattern).  One copy for every law set, not
 * inlined: on its own the loop keeps its pointers in registers. */
static JD_NOINLINE void batch_scatter(const double *radius, const batch *restrict B, int nb,
                                      double *restrict f, double *restrict t, double *restrict of,
                                      double *restrict ot, size_t hi, jd_overlap_trip *trip) {
    int32_t live[JD_BATCH];
    int m = 0;
    for (int b = 0; b < nb; b++) {
        live[m] = b;
        m += B->carries[b];
        if (B->excessive[b]) {
            const int32_t i = B->i[b], j = B->j[b];
            sim_watchdog_overlap(trip, i, j, B->delta[b], fmin(radius[i], radius[j]));
        }
    }
    for (int q = 0; q < m; q++) {
        const int b = live[q];
        const size_t j = (size_t)B->j[b];
        double *fb = j < hi ? f + 3 * j : of + 3 * (j - hi), *tb = j < hi ? t + 3 * j : ot + 3 * (j - hi);
        for (int d = 0; d < 3; d++) {
            fb[d] += B->f[d][b];
            tb[d] += B->tb[d][b];
        }
    }
    for (int q = 0; q < m; q++) {
        const int b = live[q];
        double *fa = f + 3 * (size_t)B->i[b], *ta = t + 3 * (size_t)B->i[b];
        for (int d = 0; d < 3; d++) {
            fa[d] -= B->f[d][b];
            ta[d] += B->ta[d][b];
        }
    }
}

/* Software prefetch of the particles at the front of the pair loop's window.  In cell order a
 * row i's partners j reach up to a.span (the largest j - i of the thread's entries) beyond i,
 * about one slab of cells (neighbour.c, cell_axes), so a particle's x, v, omega, f and torque
 * are first touched, as a partner, span particles ahead of the rows being evaluated, at
 * scattered j the hardware prefetchers do not follow.  The loop fetches every cache line of the five arrays once,
 * JD_PREFETCH_AHEAD particles ahead of that front.  It pays in the large beds only; at 5k and
 * 20k, whose particles stay in cache, the prefetches cost a little, hence only from
 * JD_PREFETCH_MIN_N particles (the five arrays then hold 7.9 MB; docs/performance.md). */
#define JD_PREFETCH_AHEAD 128
#define JD_PREFETCH_MIN_N 65536
/* The list's own streams (indices and history, read and written back) cross a 4 KiB page every
 * 100 entries or so, where the hardware prefetchers stop; the pair loop fetches them
 * JD_ENTRIES_AHEAD entries ahead (docs/performance.md, "list prefetch"). */
#define JD_ENTRIES_AHEAD 512

/* Prefetch the five arrays' lines of particles [*done, upto) (x, v, omega to read, f and torque
 * to write), and advance *done.  packed (a literal; the entries that did not touch at the
 * build): x alone, which the sphere test reads for every entry; the few entries that pass it
 * are not worth four more lines per particle (docs/performance.md). */
static JD_ALWAYS_INLINE void prefetch_particles(const jd_particles *ps, const int packed, size_t *done,
                                                size_t upto) {
    if (upto > ps->n) upto = ps->n;
    if (upto <= *done) return;
    for (size_t k = (3 * *done) & ~(size_t)7; k < 3 * upto; k += 8) {
        __builtin_prefetch(ps->x + k, 0, 3);
        if (packed) continue;
        __builtin_prefetch(ps->v + k, 0, 3);
        __builtin_prefetch(ps->omega + k, 0, 3);
        __builtin_prefetch(ps->f + k, 1, 3);
        __builtin_prefetch(ps->torque + k, 1, 3);
    }
    *done = upto;
}

/* Prefetch the list's entries [c, c + JD_BATCH): indices to read, history to write. */
static JD_ALWAYS_INLINE void prefetch_entries(const jd_contact_list *L, const unsigned F, size_t c) {
    const char *h = (const char *)(L->hist + (size_t)HW(F) * c);
    for (size_t o = 0; o < (size_t)HW(F) * JD_BATCH * sizeof(double); o += 64)
        __builtin_prefetch(h + o, 1, 3);
    if (F & JD_F_ROLLING) {
        const char *r = (const char *)(L->rhist + (size_t)RW(F) * c);
        for (size_t o = 0; o < (size_t)RW(F) * JD_BATCH * sizeof(double); o += 64)
            __builtin_prefetch(r + o, 1, 3);
    }
    for (size_t o = 0; o < JD_BATCH; o += 16) {
        __builtin_prefetch(L->i + c + o, 0, 3);
        __builtin_prefetch(L->j + c + o, 0, 3);
    }
}

/* The pair loop over list entries [c0, c1), in batches of consecutive entries: each batch is
 * evaluated (SIMD) and scattered back.  kinds: a literal JD_KINDS_*; packed: a literal, 1 for
 * the entries that did not touch at the build (batch_evaluate).  Each contact's arithmetic is exactly that of a plain loop over
 * the list calling jd_geom_spheres_contact and jd_contact. */
static JD_ALWAYS_INLINE void pair_loop(const jd_particles *ps, const jd_run_constants *run,
                                       const jd_fast_paths *fast, jd_contact_list *L,
                                       const unsigned F, const int kinds, const int packed,
                                       size_t c0, size_t c1, acc a, jd_overlap_trip *trip) {
    batch lanes; /* on the stack: the compiler then knows that no list or particle array aliases it */
    size_t pf = c0 < c1 ? (size_t)L->i[c0] : 0;
    for (size_t c = c0; c < c1; c += JD_BATCH) {
        const int nb = c1 - c < JD_BATCH ? (int)(c1 - c) : JD_BATCH;
        if (ps->n >= JD_PREFETCH_MIN_N)
            prefetch_particles(ps, packed, &pf,
                               (size_t)L->i[c + (size_t)nb - 1] + a.span + JD_PREFETCH_AHEAD);
        if (c + JD_ENTRIES_AHEAD + JD_BATCH <= c1) prefetch_entries(L, F, c + JD_ENTRIES_AHEAD);
        const int m = batch_evaluate(ps, run, fast, L, F, kinds, packed, &lanes, c, nb);
        batch_scatter(ps->radius, &lanes, m, a.f, a.t, a.of, a.ot, a.hi, trip);
    }
}

/* The wall loop fetches the particle data of its entries this many entries ahead.  Along a
 * side wall a wall entry's particle is one of a few per row of cells, so in a large bed its
 * lines (ten arrays) have left the cache when the wall loop reaches it (docs/performance.md). */
#define JD_WALL_AHEAD 16

/* Prefetch what the wall loop reads and writes of particle i. */
static JD_ALWAYS_INLINE void prefetch_wall_particle(const jd_particles *ps, size_t i) {
    __builtin_prefetch(ps->x + 3 * i, 0, 3);
    __builtin_prefetch(ps->v + 3 * i, 0, 3);
    __builtin_prefetch(ps->omega + 3 * i, 0, 3);
    __builtin_prefetch(ps->f + 3 * i, 1, 3);
    __builtin_prefetch(ps->torque + 3 * i, 1, 3);
    __builtin_prefetch(ps->radius + i, 0, 3);
    __builtin_prefetch(ps->kw + i, 0, 3);
    __builtin_prefetch(ps->mass + i, 0, 3);
    __builtin_prefetch(ps->inertia + i, 0, 3);
    __builtin_prefetch(ps->species + i, 0, 3);
}

/* Geometry lanes of a wall batch: the law for lanes [0, nb), vectorised like the pairs'. */
static JD_ALWAYS_INLINE void wall_batch_evaluate(const jd_particles *ps,
                                                 const jd_run_constants *run,
                                                 const jd_contact_list *L, const unsigned F,
                                                 batch *restrict B, int nb) {
    const double *restrict v = ps->v, *restrict w = ps->omega, *restrict rad = ps->radius;
    const double *restrict kw = ps->kw, *restrict mass = ps->mass, *restrict inertia = ps->inertia;
    const double *restrict hist = L->hist, *restrict rhist = L->rhist;
    const jd_pair_coeffs *restrict coeffs = run->coeffs;
    const double dt = run->dt;
    for (int b = 0; b < nb; b++) {
        const int32_t c = B->c[b], i = B->i[b];
        jd_contact_geom g;
        for (int d = 0; d < 3; d++) {
            g.n[d] = B->n[d][b];
            g.ra[d] = B->ra[d][b];
            g.rb[d] = 0.0;
        }
        g.delta = B->delta[b];
        g.r_roll = rad[i];
        jd_geom_wall_material(F, &g, kw[i], mass[i], inertia[i]);
        const int32_t k_co = B->k_co[b];
        const jd_pair_coeffs co = jd_wall_coeffs(&coeffs[k_co]);
        jd_kinematics k;
        for (int d = 0; d < 3; d++) {
            k.va[d] = v[3 * i + d];
            k.wa[d] = w[3 * i + d];
            k.vb[d] = B->vw[d][b];
            k.wb[d] = 0.0;
        }
        lane_law(F, B, b, hist, rhist, c, &g, &k, &co, 1, dt);
    }
}

/* Wall-list entry c (particle i) carries force f [N] on the wall at x_i + ra [m] (sim.h,
 * wall_forces). */
static JD_ALWAYS_INLINE void record_wall_force(jd_walls *walls, const double *x, size_t c, int32_t i,
                                               const double f[3], const double ra[3]) {
    for (int d = 0; d < 3; d++) {
        walls->f[3 * c + d] = f[d];
        walls->x[3 * c + d] = x[3 * (size_t)i + d] + ra[d];
    }
}

/* Lanes [0, nb) of a wall batch back: history, watchdog, the walls' work (energy bookkeeping:
 * also over the step a contact ends; added to *work one contact at a time, the plain loop's
 * order) and the forces on the particles, in list order. */
static JD_ALWAYS_INLINE void wall_batch_scatter(const jd_particles *ps, const jd_run_constants *run,
                                                jd_walls *walls, jd_contact_list *L,
                                                const unsigned F, const batch *B, int nb, acc a,
                                                jd_overlap_trip *trip, double *work) {
    for (int b = 0; b < nb; b++) {
        const size_t c = (size_t)B->c[b];
        const int32_t i = B->i[b];
        lane_history_write(F, B, b, L->hist, L->rhist, c);
        if (jd_overlap_excessive(B->delta[b], ps->radius[i], INFINITY, run->max_overlap))
            sim_watchdog_overlap(trip, i, -1 - B->j[b], B->delta[b], ps->radius[i]);
        if (F & JD_F_ENERGY) {
            const double f_before[3] = {B->f_before[0][b], B->f_before[1][b], B->f_before[2][b]};
            const double f[3] = {B->f[0][b], B->f[1][b], B->f[2][b]};
            const double vw[3] = {B->vw[0][b], B->vw[1][b], B->vw[2][b]};
            *work += jd_wall_work(f_before, f, vw, run->dt);
        }
        if (!B->carries[b]) continue;
        double *fa = a.f + 3 * (size_t)i, *ta = a.t + 3 * (size_t)i;
        for (int d = 0; d < 3; d++) {
            fa[d] -= B->f[d][b];
            ta[d] += B->ta[d][b];
        }
        if (walls->forces) {
            const double f[3] = {B->f[0][b], B->f[1][b], B->f[2][b]};
            const double ra[3] = {B->ra[0][b], B->ra[1][b], B->ra[2][b]};
            record_wall_force(walls, ps->x, c, i, f, ra);
        }
    }
}

/* The wall loop over entries [c0, c1), in batches like the pair loop: the wall's own test
 * (plane or cylinder) decides the touching entries and fills their geometry lanes.  Returns
 * the work the walls did on the particles of the chunk. */
static JD_ALWAYS_INLINE double wall_loop(const jd_particles *ps, const jd_run_constants *run,
                                         jd_walls *walls, jd_contact_list *L, const unsigned F,
                                         size_t c0, size_t c1, acc a, jd_overlap_trip *trip) {
    const int32_t nm = (int32_t)run->n_materials;
    batch lanes;
    batch *B = &lanes;
    double work = 0.0;
    int nb = 0;
    for (size_t c = c0; c < c1; c++) {
        if (c + JD_WALL_AHEAD < c1) prefetch_wall_particle(ps, (size_t)L->i[c + JD_WALL_AHEAD]);
        const int32_t i = L->i[c];
        const jd_sim_wall *w = &walls->wall[L->j[c]];
        jd_contact_geom g;
        if (w->gone) {
            work += gone_wall_work(L, F, c);
            continue;
        }
        if (!sim_wall_geom(ps, i, w, &g)) {
            hist_separate(L, F, c);
            continue;
        }
        B->c[nb] = (int32_t)c;
        B->i[nb] = i;
        B->j[nb] = L->j[c];
        B->delta[nb] = g.delta;
        B->k_co[nb] = ps->species[i] * nm + (int32_t)w->material;
        double vw[3];
        wall_point_velocity(w, ps->x + 3 * (size_t)i, g.ra, vw);
        for (int d = 0; d < 3; d++) {
            B->n[d][nb] = g.n[d];
            B->ra[d][nb] = g.ra[d];
            B->vw[d][nb] = vw[d];
        }
        if (++nb == JD_BATCH) {
            wall_batch_evaluate(ps, run, L, F, B, nb);
            wall_batch_scatter(ps, run, walls, L, F, B, nb, a, trip, &work);
            nb = 0;
        }
    }
    wall_batch_evaluate(ps, run, L, F, B, nb);
    wall_batch_scatter(ps, run, walls, L, F, B, nb, a, trip, &work);
    return work;
}

#ifndef JD_FORCE_LOOPS_ENERGY
/* The reference path (--plain-loops): one contact at a time, as the loops were before they
 * were batched, with the features as a run-time value.  The batched loops must give the same
 * bits (tests/engine/test_fastpaths.py). */
static void plain_pair_loop(const jd_particles *ps, const jd_run_constants *run,
                            const jd_fast_paths *fast, jd_contact_list *L, const unsigned F,
                            size_t c0, size_t c1, acc a, jd_overlap_trip *trip) {
    const size_t nm = run->n_materials;
    for (size_t c = c0; c < c1; c++) {
        const int32_t i = L->i[c], j = L->j[c];
        jd_contact_geom g;
        if (!sim_pair_geom(ps, fast, F, i, j, &g)) {
            hist_separate(L, F, c);
            continue;
        }
        if (jd_overlap_excessive(g.delta, ps->radius[i], ps->radius[j], run->max_overlap))
            sim_watchdog_overlap(trip, i, j, g.delta, fmin(ps->radius[i], ps->radius[j]));
        jd_kinematics k;
        for (int d = 0; d < 3; d++) {
            k.va[d] = ps->v[3 * (size_t)i + d];
            k.wa[d] = ps->omega[3 * (size_t)i + d];
            k.vb[d] = ps->v[3 * (size_t)j + d];
            k.wb[d] = ps->omega[3 * (size_t)j + d];
        }
        const jd_pair_coeffs *co = &run->coeffs[(size_t)ps->species[i] * nm + (size_t)ps->species[j]];
        jd_contact_state st;
        jd_rolling_state rs;
        hist_load(L, F, c, &st, &rs);
        jd_contact_result out;
        const int carries = jd_contact(F, co, &g, &k, run->dt, &st, (F & JD_F_ROLLING) ? &rs : NULL, &out);
        hist_store(L, F, c, &st, &rs);
        if (!carries) continue;
        const int own = (size_t)j < a.hi;
        double *fa = a.f + 3 * (size_t)i, *fb = own ? a.f + 3 * (size_t)j : a.of + 3 * ((size_t)j - a.hi);
        double *ta = a.t + 3 * (size_t)i, *tb = own ? a.t + 3 * (size_t)j : a.ot + 3 * ((size_t)j - a.hi);
        for (int d = 0; d < 3; d++) {
            fa[d] -= out.f[d];
            fb[d] += out.f[d];
            ta[d] += out.ta[d];
            tb[d] += out.tb[d];
        }
    }
}

static double plain_wall_loop(const jd_particles *ps, const jd_run_constants *run, jd_walls *walls,
                              jd_contact_list *L, const unsigned F, size_t c0, size_t c1, acc a,
                              jd_overlap_trip *trip) {
    const size_t nm = run->n_materials;
    double work = 0.0;
    for (size_t c = c0; c < c1; c++) {
        const int32_t i = L->i[c];
        const jd_sim_wall *w = &walls->wall[L->j[c]];
        jd_contact_geom g;
        if (w->gone) {
            work += gone_wall_work(L, F, c);
            continue;
        }
        if (!sim_wall_geom(ps, i, w, &g)) {
            hist_separate(L, F, c);
            continue;
        }
        if (jd_overlap_excessive(g.delta, ps->radius[i], INFINITY, run->max_overlap))
            sim_watchdog_overlap(trip, i, -1 - L->j[c], g.delta, ps->radius[i]);
        jd_kinematics k;
        wall_point_velocity(w, ps->x + 3 * (size_t)i, g.ra, k.vb);
        for (int d = 0; d < 3; d++) {
            k.va[d] = ps->v[3 * (size_t)i + d];
            k.wa[d] = ps->omega[3 * (size_t)i + d];
            k.wb[d] = 0.0;
        }
        const jd_pair_coeffs co =
            jd_wall_coeffs(&run->coeffs[(size_t)ps->species[i] * nm + (size_t)w->material]);
        jd_contact_state st;
        jd_rolling_state rs;
        hist_load(L, F, c, &st, &rs);
        jd_contact_result out;
        const double f_prev[3] = {st.f_prev[0], st.f_prev[1], st.f_prev[2]};
        const int carries = jd_contact(F, &co, &g, &k, run->dt, &st, (F & JD_F_ROLLING) ? &rs : NULL, &out);
        hist_store(L, F, c, &st, &rs);
        if (F & JD_F_ENERGY) work += jd_wall_work(f_prev, out.f, k.vb, run->dt);
        if (!carries) continue;
        for (int d = 0; d < 3; d++) {
            a.f[3 * (size_t)i + d] -= out.f[d];
            a.t[3 * (size_t)i + d] += out.ta[d];
        }
        if (walls->forces) record_wall_force(walls, ps->x, c, i, out.f, g.ra);
    }
    return work;
}

/* contact_loops on the reference path, compiled once (the features a run-time value). */
static double plain_contact_loops(jd_sim *s, int tid, double *t_pairs_end) {
    const unsigned F = s->run.features;
    const jd_particles *ps = &s->particles;
    const acc a = acc_of(ps, &s->threads, tid);
    const jd_thread_share *h = &s->threads.shares[tid];
    jd_overlap_trip *trip = &s->threads.trips[tid];
    jd_contact_list *P = &s->lists.pairs, *W = &s->lists.wall_pairs;
    plain_pair_loop(ps, &s->run, &s->fast, P, F, h->pair_lo, h->pair_hi, a, trip);
    plain_pair_loop(ps, &s->run, &s->fast, P, F, h->near_lo, h->near_hi, a, trip);
    if (tid == 0) *t_pairs_end = sim_clock();
    return plain_wall_loop(ps, &s->run, &s->walls, W, F, h->wall_lo, h->wall_hi, a, trip);
}

#endif

/* This thread's share of the contact loops under the constant law set F; returns its wall
 * work.  *t_pairs_end: when thread 0 finished its share of the pairs (with threads, the split
 * of the timing is thread 0's). */
static JD_ALWAYS_INLINE double contact_loops(jd_sim *s, const unsigned F, int tid,
                                             double *t_pairs_end) {
    const jd_particles *ps = &s->particles;
    const jd_run_constants *run = &s->run;
    const jd_fast_paths *fast = &s->fast;
    const acc a = acc_of(ps, &s->threads, tid);
    const jd_thread_share *h = &s->threads.shares[tid];
    jd_overlap_trip *trip = &s->threads.trips[tid];
    jd_contact_list *P = &s->lists.pairs, *W = &s->lists.wall_pairs;
    /* the entries that touched at the build, then those that did not: their few touching
     * lanes packed, whatever the particles (one copy: compile time) */
    if (fast->alike)
        pair_loop(ps, run, fast, P, F, JD_KINDS_ALIKE, 0, h->pair_lo, h->pair_hi, a, trip);
    else if (fast->pair_row >= 0)
        pair_loop(ps, run, fast, P, F, JD_KINDS_ONE_MATERIAL, 0, h->pair_lo, h->pair_hi, a, trip);
    else
        pair_loop(ps, run, fast, P, F, JD_KINDS_ANY, 0, h->pair_lo, h->pair_hi, a, trip);
    pair_loop(ps, run, fast, P, F, JD_KINDS_ANY, 1, h->near_lo, h->near_hi, a, trip);
    if (tid == 0) *t_pairs_end = sim_clock();
    return wall_loop(ps, run, &s->walls, W, F, h->wall_lo, h->wall_hi, a, trip);
}

/* One instantiation per compiled law set (the kernel's list, jdem_laws.h: JD_LAW_LOOPS): the
 * switch maps the run's bits to a constant law set.  Bits with a run-time law match no case. */
#define JD_FORCE_CASE(loop)                                                                   \
    case (loop):                                                                              \
        *work = contact_loops(s, (loop), tid, t_pairs_end);                                   \
        return 1;

/* The compiled law sets with energy bookkeeping are instantiated in a translation unit of their
 * own (forces_energy.c includes this file with JD_FORCE_LOOPS_ENERGY; the rest of this file is
 * compiled here only), the others here, so that a parallel make compiles the two halves side by
 * side.  Each returns 0, without evaluating, when the run's law set is not one of its half. */
int sim_force_loops_energy(jd_sim *s, int tid, double *work, double *t_pairs_end);
#ifdef JD_FORCE_LOOPS_ENERGY
int sim_force_loops_energy(jd_sim *s, int tid, double *work, double *t_pairs_end) {
    switch (s->run.features) {
        JD_LAW_SETS_WITH(JD_FORCE_CASE, JD_F_ENERGY)
    default:
        return 0;
    }
}
#else
#ifndef JD_ONE_FORCE_LOOP
static int force_loops_without_energy(jd_sim *s, int tid, double *work, double *t_pairs_end) {
    switch (s->run.features) {
        JD_LAW_SETS_WITH(JD_FORCE_CASE, 0u)
    default:
        return 0;
    }
}
#endif

static double dispatch(jd_sim *s, int tid, double *t_pairs_end_out) {
    double work = 0.0, t_pairs_end = 0.0;
    if (s->opt.plain_loops) {
        work = plain_contact_loops(s, tid, &t_pairs_end);
        if (tid == 0) *t_pairs_end_out = t_pairs_end;
        return work;
    }
#ifdef JD_ONE_FORCE_LOOP
    /* one copy of the loops, with the features as a run-time value: the sanitizer build
     * (Makefile), which checks the code rather than its speed, compiles the law once instead of
     * once per law set; the same source, hence the same checks */
    work = contact_loops(s, s->run.features & JD_F_ALL, tid, &t_pairs_end);
#else
    if (!force_loops_without_energy(s, tid, &work, &t_pairs_end) &&
        !sim_force_loops_energy(s, tid, &work, &t_pairs_end))
        /* a run-time law (Mindlin's K_t): the reference path */
        work = plain_contact_loops(s, tid, &t_pairs_end);
#endif
    if (tid == 0) *t_pairs_end_out = t_pairs_end;
    return work;
}

/* With threads: thread tid adds the earlier threads' overflow into the particles it owns, in
 * thread order, and zeroes it for the next evaluation. */
static void reduce(jd_particles *ps, const jd_thread_layout *threads, int tid) {
    const jd_thread_share *me = &threads->shares[tid];
    for (int u = 0; u < tid; u++) {
        const jd_thread_share *h = &threads->shares[u];
        const size_t lo = h->p_hi > me->p_lo ? h->p_hi : me->p_lo;
        const size_t hi = h->p_hi + h->win < me->p_hi ? h->p_hi + h->win : me->p_hi;
        double *of = h->ovf, *ot = h->ovf + 3 * h->cap;
        for (size_t k = 3 * lo; k < 3 * hi; k++) {
            const size_t o = k - 3 * h->p_hi;
            ps->f[k] += of[o];
            ps->torque[k] += ot[o];
            of[o] = ot[o] = 0.0;
        }
    }
}

void sim_gravity(jd_particles *ps, const jd_run_constants *run, const jd_thread_layout *threads) {
    const double *g = run->g;
    if (g[0] == 0.0 && g[1] == 0.0 && g[2] == 0.0) return;
    const long n = (long)ps->n;
    double *f = ps->f;
    const double *mass = ps->mass;
#pragma omp parallel for schedule(static) num_threads(threads->n) if (threads->n > 1)
    for (long i = 0; i < n; i++)
        for (int d = 0; d < 3; d++) f[3 * i + d] += mass[i] * g[d];
}

void sim_compute_forces(jd_sim *s) {
    const int nt = s->threads.n;
    sim_walls_retire(&s->walls, s->step + (s->in_setup ? 0 : 1)); /* the step whose forces these are */
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
        /* only this thread writes its particles' f and torque directly (the others' overflow) */
        const jd_thread_share *h = &s->threads.shares[tid];
        memset(s->particles.f + 3 * h->p_lo, 0, 3 * (h->p_hi - h->p_lo) * sizeof *s->particles.f);
        memset(s->particles.torque + 3 * h->p_lo, 0, 3 * (h->p_hi - h->p_lo) * sizeof *s->particles.torque);
        s->threads.trips[tid].fraction = 0.0;
        work[tid] = dispatch(s, tid, &t_pairs_end);
        if (nt > 1) {
#pragma omp barrier
            reduce(&s->particles, &s->threads, tid);
        }
        if (tid == 0) t_walls_end = sim_clock();
    }
    /* the worst overlap of this evaluation (the first thread's on a tie, as in serial order) */
    s->watch.overlap_trip.fraction = 0.0;
    for (int t = 0; t < nt; t++) {
        if (s->threads.trips[t].fraction > s->watch.overlap_trip.fraction) s->watch.overlap_trip = s->threads.trips[t];
        s->accounts.wall_work += work[t];
    }
    /* then in LIGGGHTS' order: bonds (in parallel with the contacts, bonds.c), gravity, and the
     * post-force loads (loads.c); without loads, the weight is added by the half kick that
     * follows (integrate.c), which reads f anyway: the same sums, one pass less (sim.h,
     * weight_in_kick) */
    double t_mesh = 0.0;
    if (s->meshes) { /* serial: the same bits for any thread count */
        const double t_mesh0 = sim_clock();
        sim_mesh_walls_forces(s);
        t_mesh = sim_clock() - t_mesh0;
    }
    if (s->walls.forces) sim_walls_sum(&s->walls, &s->lists.wall_pairs);
    if (s->bonds)
        sim_bonds_forces(s->bonds, &s->particles, &s->run, &s->threads, s->step, s->in_setup);
    if (s->in_setup || !s->fast.weight_in_kick) sim_gravity(&s->particles, &s->run, &s->threads);
    if (s->loads) sim_loads_apply(s->loads, &s->particles, &s->run, &s->accounts, s->in_setup);
    const double t1 = sim_clock();
    s->accounts.timing.pairs += (t_pairs_end - t0) + (t1 - t_walls_end) - t_mesh;
    s->accounts.timing.walls += t_walls_end - t_pairs_end + t_mesh;
}
#endif /* JD_FORCE_LOOPS_ENERGY */
