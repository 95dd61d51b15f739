/*
 * bonds.c — the bond list of the standalone engine (bonds.h): set-up from the scene, rules
 * during the run, the bond loop (specialised for its JD_B_* features like the contact loops),
 * broken-bond events, /connectivity output, observables, the guard's bond bound.
 */
#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "bonds.h"
#include "checkpoint.h"
#include "jdem_inlet.h"
#include "sim.h"

/* The pragmas are guarded: the scene checker and the fuzzer link this file (for the guard's
 * bond bound) without OpenMP. */
#ifdef _OPENMP
#include <omp.h>
#endif


void sim_bond_observables_values(const jd_bond_observables *o, double out[JD_N_BOND_OBSERVABLES]) {
    const double v[JD_N_BOND_OBSERVABLES] = {o->bonds, o->fragments, o->elastic_energy,
                                             o->damping_dissipation, o->breakage_energy};
    for (int k = 0; k < JD_N_BOND_OBSERVABLES; k++) out[k] = v[k];
}

/* ---------------------------------------------------------------------------------------- */
/* Growing arrays                                                                            */

static int grow(void **p, size_t *cap, size_t need, size_t size) {
    if (need <= *cap) return 0;
    size_t c = *cap ? *cap : 64;
    while (c < need) c *= 2;
    void *q = realloc(*p, c * size);
    if (!q) return -1;
    *p = q;
    *cap = c;
    return 0;
}

/* Give the bond arrays capacity c (>= b->n). */
static int resize(jd_bonds *b, size_t c) {
#define RE(p, per)                                             \
    do {                                                       \
        void *q = realloc((p), c * (per) * sizeof *(p));       \
        if (!q) return -1;                                     \
        (p) = q;                                               \
    } while (0)
    RE(b->i, 1);
    RE(b->j, 1);
    RE(b->type, 1);
    RE(b->state, (size_t)b->sw);
#undef RE
    b->cap = c;
    return 0;
}

static int reserve(jd_bonds *b, size_t need) {
    if (need <= b->cap) return 0;
    size_t c = b->cap ? b->cap : 64;
    while (c < need) c *= 2;
    return resize(b, c);
}

int sim_bonds_reserve(jd_bonds *b, size_t need) { return reserve(b, need); }

/* Bonds form only at step 0 and when a rule applies, and afterwards only break: give back the
 * room the doubling left once they have formed.  Every array then holds at least cap bonds:
 * shrunk, or as it was if its shrink failed. */
static void fit(jd_bonds *b) {
    const size_t c = b->n + 64;
    if (b->cap <= c) return;
    (void)resize(b, c);
    b->cap = c;
}

/* The state of bond k as the kernel's struct and back (its record, jd_bond_record_load/store);
 * sw is b->sw, a compile-time constant in the bond loop. */
static JD_ALWAYS_INLINE jd_bond_state state_get(const jd_bonds *b, const int sw, size_t k) {
    return jd_bond_record_load(b->state + (size_t)sw * k, sw);
}

static JD_ALWAYS_INLINE void state_set(jd_bonds *b, const int sw, size_t k, const jd_bond_state *st) {
    jd_bond_record_store(b->state + (size_t)sw * k, sw, st);
}

/* Room for b->n results of the threaded bond loop (allocated only when it runs). */
static int out_reserve(jd_bonds *b) {
    if (b->out_cap >= b->n) return 0;
    jd_bond_out *o = realloc(b->out, b->cap * sizeof *o);
    if (!o) return -1;
    b->out = o;
    b->out_cap = b->cap;
    return 0;
}

/* Append an intact bond between particle indices i and j (a = the smaller id). */
static int add_bond(jd_bonds *b, const jd_particles *ps, int32_t i, int32_t j, int32_t type,
                    int64_t step) {
    if (sim_particle_id(ps, (size_t)j) < sim_particle_id(ps, (size_t)i)) {
        const int32_t t = i;
        i = j;
        j = t;
    }
    if (reserve(b, b->n + 1) ||
        grow((void **)&b->formed, &b->formed_cap, b->n_formed + 1, sizeof *b->formed))
        return -1;
    const size_t k = b->n++;
    b->i[k] = i;
    b->j[k] = j;
    b->type[k] = type;
    jd_bond_state fresh;
    jd_bond_form(&fresh);
    state_set(b, b->sw, k, &fresh);
    b->ever[i] = b->ever[j] = 1;
    b->formed[b->n_formed++] =
        (jd_h5md_bond){{sim_particle_id(ps, (size_t)i), sim_particle_id(ps, (size_t)j)}, type, step};
    return 0;
}

int sim_bonds_form(jd_bonds *b, const jd_particles *ps, int32_t i, int32_t j, int32_t type,
                   int64_t step) {
    if (add_bond(b, ps, i, j, type, step) == 0) return 0;
    b->failed = "out of memory forming the bonds of an inlet's blocks";
    return -1;
}

static long index_of_id(const jd_scene *sc, int64_t id) {
    size_t lo = 0, hi = sc->n_particles;
    while (lo < hi) {
        size_t mid = lo + (hi - lo) / 2;
        if (sc->id[mid] < id) lo = mid + 1; else hi = mid;
    }
    return lo < sc->n_particles && sc->id[lo] == id ? (long)lo : -1;
}

/* Whether every particle of the run, the inlets' included, has the radius of the first. */
static int one_radius(const jd_particles *ps, const jd_scene *sc, double *r) {
    int have = 0, same = 1;
    for (size_t i = 0; i < ps->n; i++) {
        if (!have) *r = ps->radius[i], have = 1;
        same &= ps->radius[i] == *r;
    }
    for (size_t k = 0; k < sc->n_inlets; k++)
        for (size_t p = 0; p < sc->inlets[k].n; p++) {
            if (!have) *r = sc->inlets[k].radius[p], have = 1;
            same &= sc->inlets[k].radius[p] == *r;
        }
    return have && same;
}

int sim_bonds_init(jd_bonds **bonds, const jd_particles *ps, const jd_scene *sc, size_t capacity,
                   char *err, size_t errlen) {
    if (!sc->n_bond_types) return 0;
    jd_bonds *b = calloc(1, sizeof *b);
    if (b) b->ever_cap = capacity > ps->n ? capacity : ps->n;
    if (!b || !(b->ever = calloc(b->ever_cap ? b->ever_cap : 1, 1))) {
        free(b);
        snprintf(err, errlen, "out of memory for the bonds");
        return -1;
    }
    *bonds = b;
    b->n_types = sc->n_bond_types;
    jd_bond_params *p = malloc(b->n_types * sizeof *p);
    if (!p) goto oom;
    b->features = sc->energy ? JD_B_ENERGY : 0u;
    b->sw = jd_bond_record_len(b->features);
    for (size_t t = 0; t < b->n_types; t++) {
        p[t] = sc->bond_types[t].p;
        b->features |= jd_bond_laws(p[t].gamma);
    }
    b->params = p;
    double r = 0.0;
    if (one_radius(ps, sc, &r)) {
        jd_bond_section *sec = malloc(b->n_types * sizeof *sec);
        if (!sec) goto oom;
        for (size_t t = 0; t < b->n_types; t++) sec[t] = jd_bond_section_of(p[t].lambda, r, r);
        b->sec_type = sec;
    }
    for (size_t k = 0; k < sc->n_bonds; k++) {
        /* indices equal ids' positions: the scene's particles are sorted by id */
        const long i = index_of_id(sc, sc->bond_ids[2 * k]), j = index_of_id(sc, sc->bond_ids[2 * k + 1]);
        if (i < 0 || j < 0 || add_bond(b, ps, (int32_t)i, (int32_t)j, sc->bond_type[k], 0)) goto oom;
    }
    fit(b);
    return 0;
oom:
    snprintf(err, errlen, "out of memory for %zu bonds", sc->n_bonds);
    return -1;
}

void sim_bonds_free(jd_bonds **bonds) {
    jd_bonds *b = *bonds;
    if (!b) return;
    free((void *)b->params);
    free((void *)b->sec_type);
    free(b->i);
    free(b->j);
    free(b->type);
    free(b->state);
    free(b->out);
    free(b->ever);
    free(b->formed);
    free(b->events);
    free(b);
    *bonds = NULL;
}

size_t sim_bonds_memory_bytes(const jd_bonds *b, size_t n_particles) {
    if (!b) return 0;
    const size_t per_bond = 3 * sizeof(int32_t) + (size_t)b->sw * sizeof(double);
    return b->cap * per_bond + b->n_types * (sizeof *b->params + (b->sec_type ? sizeof *b->sec_type : 0)) +
           b->out_cap * sizeof *b->out + n_particles /* ever */ +
           b->formed_cap * sizeof *b->formed + b->events_cap * sizeof *b->events;
}

/* ---------------------------------------------------------------------------------------- */
/* Rules                                                                                     */

static int by_pair(const void *x, const void *y) {
    const int32_t *p = x, *q = y;
    if (p[0] != q[0]) return p[0] < q[0] ? -1 : 1;
    return p[1] < q[1] ? -1 : p[1] > q[1];
}

/* Bond the pairs of one rule that are not bonded already (intact).  Out of memory is recorded
 * in b->failed and stops the run at the next sim_bonds_output. */
/* Positions in scene order (x, 3n) and where[p]: the engine index of scene particle p. */
static void positions_in_scene_order(const jd_particles *ps, double *x, int32_t *where) {
    for (size_t i = 0; i < ps->n; i++) {
        const size_t p = (size_t)ps->orig[i];
        for (int d = 0; d < 3; d++) x[3 * p + d] = ps->x[3 * i + d];
        where[p] = (int32_t)i;
    }
}

static void apply_rule(jd_bonds *b, const jd_particles *ps, const jd_scene *sc,
                       const jd_bond_rule *rule, int64_t step) {
    int32_t *pairs = NULL;
    /* the rule is evaluated in the scene's particle order (the engine renumbers the particles,
     * reorder.c): positions into it, the pairs' indices back */
    const size_t n1 = ps->n ? ps->n : 1;
    double *x = malloc(3 * n1 * sizeof *x);
    int32_t *where = malloc(n1 * sizeof *where);
    const long np = x && where ? (positions_in_scene_order(ps, x, where),
                                  jd_bond_rule_pairs(sc, rule, x, &pairs))
                               : -1;
    for (long q = 0; q < 2 * np; q++) pairs[q] = where[pairs[q]];
    free(x);
    free(where);
    int32_t *have = malloc((b->n ? b->n : 1) * 2 * sizeof *have); /* intact pairs, (min, max) */
    if (np < 0 || !have) b->failed = "out of memory applying a bond rule";
    if (np <= 0 || !have) {
        free(pairs);
        free(have);
        return;
    }
    for (size_t k = 0; k < b->n; k++) {
        have[2 * k] = b->i[k] < b->j[k] ? b->i[k] : b->j[k];
        have[2 * k + 1] = b->i[k] < b->j[k] ? b->j[k] : b->i[k];
    }
    qsort(have, b->n, 2 * sizeof *have, by_pair);
    for (long p = 0; p < np; p++) {
        const int32_t i = pairs[2 * p], j = pairs[2 * p + 1];
        const int32_t key[2] = {i < j ? i : j, i < j ? j : i};
        if (!bsearch(key, have, b->n, 2 * sizeof *have, by_pair) && add_bond(b, ps, i, j, rule->type, step)) {
            b->failed = "out of memory forming the bonds of a rule";
            break;
        }
    }
    free(pairs);
    free(have);
    fit(b);
}

/* ---------------------------------------------------------------------------------------- */
/* The bond loop                                                                             */

/* A broken bond's event; xc: the bond point x_C at failure [m]; dt: the run's [s]; none at step
 * 0 (in_setup). */
static void record_break(jd_bonds *b, const jd_particles *ps, double dt, int in_setup, size_t k,
                         const jd_bond_result *out, const double xc[3], int64_t step) {
    b->n_broken[out->mode]++;
    if (in_setup) return;
    if (grow((void **)&b->events, &b->events_cap, b->n_events + 1, sizeof *b->events)) {
        b->failed = "out of memory recording a broken bond";
        return;
    }
    jd_h5md_bond_break *e = &b->events[b->n_events++];
    const int32_t i = b->i[k], j = b->j[k];
    *e = (jd_h5md_bond_break){.step = step, .time = (double)step * dt,
                              .id = {sim_particle_id(ps, (size_t)i), sim_particle_id(ps, (size_t)j)},
                              .mode = out->mode,
                              .normal_force = out->fn, .shear_force = out->ft,
                              .twisting_moment = out->mn, .bending_moment = out->mt,
                              .sigma_max = out->sigma_max, .tau_max = out->tau_max};
    for (int d = 0; d < 3; d++) e->position[d] = xc[d];
}

/* Evaluate bond k (state updated in place).  Returns the kernel's mode, or -1 when the centres
 * coincide (no direction: skipped; the contact watchdog reports it).  xc: the bond point, set
 * only when the bond failed. */
static JD_ALWAYS_INLINE int bond_eval(jd_bonds *b, const jd_particles *ps, const unsigned F,
                                      const double dt, size_t k, jd_bond_result *out,
                                      double xc[3]) {
    const int sw = jd_bond_record_len(F); /* = b->sw */
    const int32_t i = b->i[k], j = b->j[k];
    jd_bond_geom g;
    if (!jd_bond_geom_spheres(ps->x + 3 * (size_t)i, ps->radius[i], ps->x + 3 * (size_t)j,
                              ps->radius[j], &g))
        return -1;
    const jd_bond_params *p = &b->params[b->type[k]];
    g.sec = b->sec_type ? b->sec_type[b->type[k]]
                        : jd_bond_section_of(p->lambda, ps->radius[i], ps->radius[j]);
    if (F & JD_B_DAMPING)
        jd_bond_set_masses(&g, ps->mass[i], ps->mass[j], ps->inertia[i], ps->inertia[j]);
    jd_kinematics kin;
    const double *va = ps->v + 3 * (size_t)i, *wa = ps->omega + 3 * (size_t)i;
    const double *vb = ps->v + 3 * (size_t)j, *wb = ps->omega + 3 * (size_t)j;
    for (int d = 0; d < 3; d++) {
        kin.va[d] = va[d];
        kin.wa[d] = wa[d];
        kin.vb[d] = vb[d];
        kin.wb[d] = wb[d];
    }
    jd_bond_state st = state_get(b, sw, k);
    const int mode = jd_bond(F, p, &g, &kin, dt, &st, out);
    state_set(b, sw, k, &st);
    if (mode != JD_BOND_INTACT)
        for (int d = 0; d < 3; d++) xc[d] = ps->x[3 * (size_t)i + d] + g.ra[d];
    return mode;
}

/* Add an intact bond's force and torques to its particles. */
static inline void bond_add(double *f, double *t, int32_t i, int32_t j, const double fb[3],
                            const double ta[3], const double tb[3]) {
    double *fa_ = f + 3 * (size_t)i, *fb_ = f + 3 * (size_t)j;
    double *ta_ = t + 3 * (size_t)i, *tb_ = t + 3 * (size_t)j;
    for (int d = 0; d < 3; d++) {
        fa_[d] -= fb[d];
        fb_[d] += fb[d];
        ta_[d] += ta[d];
        tb_[d] += tb[d];
    }
}

/* One thread: evaluate and add as it goes.  Returns the number of bonds that broke. */
static JD_ALWAYS_INLINE size_t bond_loop(jd_bonds *b, jd_particles *ps, double run_dt, int in_setup,
                                         const unsigned F, int64_t step) {
    /* Step 0 (LIGGGHTS `setup`): no increment, the force is the stored one (bonds.h) */
    const double dt = in_setup ? 0.0 : run_dt;
    size_t broke = 0;
    for (size_t k = 0; k < b->n; k++) {
        jd_bond_result out;
        double xc[3];
        const int mode = bond_eval(b, ps, F, dt, k, &out, xc);
        if (mode < 0) continue;
        if (mode != JD_BOND_INTACT) {
            record_break(b, ps, run_dt, in_setup, k, &out, xc, step);
            broke++;
            continue;
        }
        bond_add(ps->f, ps->torque, b->i[k], b->j[k], out.f, out.ta, out.tb);
    }
    return broke;
}

/* Several threads (called by each thread of a parallel region, sim_bonds_forces): the bonds
 * are evaluated in parallel into b->out; after the loop's barrier each thread adds the intact
 * bonds' forces to the particles it owns (jd_thread_share), scanning the bonds in order, so that
 * every particle's sum has the one-thread order: the same bits for any thread count.  The
 * breaks are recorded afterwards, in bond order (bond_breaks). */
static JD_ALWAYS_INLINE void bond_loop_threads(jd_bonds *b, jd_particles *ps,
                                               const jd_thread_share *share, double dt,
                                               const unsigned F) {
    jd_bond_out *o = b->out;
    const long n = (long)b->n;
#ifdef _OPENMP
#pragma omp for schedule(static)
#endif
    for (long k = 0; k < n; k++) {
        jd_bond_result r;
        double xc[3];
        o[k].mode = bond_eval(b, ps, F, dt, (size_t)k, &r, xc);
        if (o[k].mode == JD_BOND_INTACT) {
            for (int d = 0; d < 3; d++) {
                o[k].force.f[d] = r.f[d];
                o[k].force.ta[d] = r.ta[d];
                o[k].force.tb[d] = r.tb[d];
            }
        } else if (o[k].mode > 0) {
            o[k].broke.r = (jd_bond_failure){r.fn, r.ft, r.mn, r.mt, r.sigma_max, r.tau_max};
            for (int d = 0; d < 3; d++) o[k].broke.xc[d] = xc[d];
        }
    }
    const size_t lo = share->p_lo, hi = share->p_hi;
    for (long k = 0; k < n; k++) {
        if (o[k].mode != JD_BOND_INTACT) continue;
        const size_t i = (size_t)b->i[k], j = (size_t)b->j[k];
        const double *fb = o[k].force.f;
        if (i >= lo && i < hi)
            for (int d = 0; d < 3; d++) {
                ps->f[3 * i + d] -= fb[d];
                ps->torque[3 * i + d] += o[k].force.ta[d];
            }
        if (j >= lo && j < hi)
            for (int d = 0; d < 3; d++) {
                ps->f[3 * j + d] += fb[d];
                ps->torque[3 * j + d] += o[k].force.tb[d];
            }
    }
}

/* The breaks the threaded loop found, in bond order; returns their number. */
static size_t bond_breaks(jd_bonds *b, const jd_particles *ps, double dt, int in_setup,
                          int64_t step) {
    size_t broke = 0;
    for (size_t k = 0; k < b->n; k++) {
        const jd_bond_out *o = &b->out[k];
        if (o->mode <= 0) continue; /* intact (JD_BOND_INTACT is 0), or skipped */
        const jd_bond_failure *q = &o->broke.r;
        const jd_bond_result r = {.fn = q->fn, .ft = q->ft, .mn = q->mn, .mt = q->mt,
                                  .sigma_max = q->sigma_max, .tau_max = q->tau_max,
                                  .mode = o->mode};
        record_break(b, ps, dt, in_setup, k, &r, o->broke.xc, step);
        broke++;
    }
    return broke;
}

/* Drop the bonds that broke, and those of the particles at indices >= keep, keeping the order of
 * the others; their dissipation goes to the totals.  Returns the elastic energy the removed bonds
 * held at their last evaluation [J]. */
static double remove_bonds(jd_bonds *b, size_t keep) {
    double elastic = 0.0;
    size_t w = 0;
    for (size_t k = 0; k < b->n; k++) {
        jd_bond_state st = state_get(b, b->sw, k);
        if (!jd_bond_intact(&st) || (size_t)b->i[k] >= keep || (size_t)b->j[k] >= keep) {
            jd_bond_harvest(&st, &b->e_damp_dropped, &b->e_break_dropped);
            elastic += st.u_prev;
            continue;
        }
        if (w != k) {
            b->i[w] = b->i[k];
            b->j[w] = b->j[k];
            b->type[w] = b->type[k];
            state_set(b, b->sw, w, &st);
        }
        w++;
    }
    b->n = w;
    return elastic;
}

void sim_bonds_forces(jd_bonds *b, jd_particles *ps, const jd_run_constants *run,
                      const jd_thread_layout *threads, int64_t steps_done, int in_setup) {
    const jd_scene *sc = run->scene;
    const int64_t step = steps_done + (in_setup ? 0 : 1); /* the step whose forces these are */
    while (!in_setup && b->next_rule < sc->n_bond_rules &&
           sc->bond_rules[b->next_rule].step <= step)
        apply_rule(b, ps, sc, &sc->bond_rules[b->next_rule++], step);
    size_t broke = 0;
    if (threads->n > 1 && b->n > 0) {
        if (out_reserve(b) != 0) {
            b->failed = "out of memory for the threaded bond loop";
            return;
        }
        /* the region around the switch, so that each copy of the loop has its features as a
         * literal (a region inside a copy would pass them to its threads as a value) */
#ifdef _OPENMP
#pragma omp parallel num_threads(threads->n)
#endif
        {
#ifdef _OPENMP
            const int tid = omp_get_thread_num();
#else
            const int tid = 0;
#endif
#define JD_BOND_LOOP_THREADS(bits) \
    case (bits):                   \
        bond_loop_threads(b, ps, &threads->shares[tid], in_setup ? 0.0 : run->dt, (bits)); \
        break;
            switch (b->features) {
                JD_BOND_LAW_SETS(JD_BOND_LOOP_THREADS)
            default:
                break;
            }
#undef JD_BOND_LOOP_THREADS
        }
        broke = bond_breaks(b, ps, run->dt, in_setup, step);
    } else {
#define JD_BOND_LOOP(bits)                  \
    case (bits):                            \
        broke = bond_loop(b, ps, run->dt, in_setup, (bits), step); \
        break;
        switch (b->features) {
            JD_BOND_LAW_SETS(JD_BOND_LOOP)
        default:
            break;
        }
#undef JD_BOND_LOOP
    }
    if (broke && !in_setup) remove_bonds(b, SIZE_MAX);
}

/* ---------------------------------------------------------------------------------------- */
/* Output, observables, permutation                                                          */

static int by_event(const void *x, const void *y) {
    const jd_h5md_bond_break *p = x, *q = y;
    if (p->step != q->step) return p->step < q->step ? -1 : 1;
    if (p->id[0] != q->id[0]) return p->id[0] < q->id[0] ? -1 : 1;
    return p->id[1] < q->id[1] ? -1 : p->id[1] > q->id[1];
}

int sim_bonds_output(jd_bonds *b, int64_t step, jd_h5md *h, char *err, size_t errlen) {
    if (b->failed) {
        snprintf(err, errlen, "step %lld: %s", (long long)step, b->failed);
        return -1;
    }
    if (b->n_events) qsort(b->events, b->n_events, sizeof *b->events, by_event);
    int rc = 0; /* step 0 creates the (possibly empty) datasets */
    if (h && (b->n_formed || step == 0))
        rc = jd_h5md_write_bonds(h, b->n_formed, b->formed, err, errlen);
    if (h && rc == 0 && (b->n_events || step == 0))
        rc = jd_h5md_write_bond_breaks(h, b->n_events, b->events, err, errlen);
    b->n_formed = b->n_events = 0;
    /* a scene's bonds all form in one step (step 0, or a rule's): do not keep their records'
     * room for the rest of the run */
    if (b->formed_cap > 4096) {
        free(b->formed);
        b->formed = NULL;
        b->formed_cap = 0;
    }
    return rc ? JD_RUN_OUTPUT : 0;
}

static int32_t find(int32_t *parent, int32_t x) {
    while (parent[x] != x) {
        parent[x] = parent[parent[x]];
        x = parent[x];
    }
    return x;
}

void sim_bonds_observables(const jd_bonds *b, size_t n_particles, jd_bond_observables *o) {
    *o = (jd_bond_observables){.bonds = (double)b->n,
                               .damping_dissipation = b->e_damp_dropped,
                               .breakage_energy = b->e_break_dropped};
    for (size_t k = 0; (b->features & JD_B_ENERGY) && k < b->n; k++) {
        jd_bond_state st = state_get(b, b->sw, k); /* a copy: the list keeps its accumulators */
        o->elastic_energy += st.u_prev;
        jd_bond_harvest(&st, &o->damping_dissipation, &o->breakage_energy);
    }
    /* fragments: union-find over the intact bonds; components among the particles ever bonded */
    int32_t *parent = malloc((n_particles ? n_particles : 1) * sizeof *parent);
    if (!parent) {
        o->fragments = NAN;
        return;
    }
    for (size_t i = 0; i < n_particles; i++) parent[i] = (int32_t)i;
    size_t merges = 0, ever = 0;
    for (size_t k = 0; k < b->n; k++) {
        const int32_t x = find(parent, b->i[k]), y = find(parent, b->j[k]);
        if (x != y) {
            parent[x] = y;
            merges++;
        }
    }
    for (size_t i = 0; i < n_particles; i++) ever += b->ever[i];
    o->fragments = (double)(ever - merges);
    free(parent);
}

void sim_bonds_permute(jd_bonds *b, const int32_t *new_index, size_t n) {
    if (!b) return;
    for (size_t k = 0; k < b->n; k++) {
        b->i[k] = new_index[b->i[k]];
        b->j[k] = new_index[b->j[k]];
    }
    unsigned char *ever = calloc(b->ever_cap ? b->ever_cap : 1, 1); /* inserted later: 0 */
    if (!ever) {
        b->failed = "out of memory renumbering the bonded particles";
        return;
    }
    for (size_t k = 0; k < n; k++) ever[new_index[k]] = b->ever[k];
    free(b->ever);
    b->ever = ever;
}

double sim_bonds_drop_from(jd_bonds *b, size_t keep) { return b ? remove_bonds(b, keep) : 0.0; }

/* ---------------------------------------------------------------------------------------- */
/* Guard                                                                                     */

/* The largest over an inlet's section particles of the sum of their section bonds' bounds (every
 * copy of a particle has the bonds of the section; copies are not bonded to each other). */
static double inlet_omega2(const jd_scene *sc, const jd_inlet *in) {
    if (!in->n_bonds) return 0.0;
    double *work = malloc(2 * in->n * sizeof *work);
    const jd_bond_params **params = malloc(sc->n_bond_types * sizeof *params);
    double wmax2 = INFINITY; /* cannot assess: report as unsafe */
    if (work && params) {
        double *mass = work + in->n;
        for (size_t p = 0; p < in->n; p++)
            mass[p] = jd_sphere_mass(in->radius[p], sc->materials[in->material[p]].density);
        for (size_t t = 0; t < sc->n_bond_types; t++) params[t] = &sc->bond_types[t].p;
        const jd_inlet_spec spec = {.n = in->n, .rel = in->rel, .radius = in->radius};
        wmax2 = jd_inlet_bond_omega2(&spec, mass, in->n_bonds, in->bond_pair, in->bond_type,
                                     params, work);
    }
    free(work);
    free(params);
    return wmax2;
}

static double scene_omega2(const jd_scene *sc);

double sim_bonds_omega2(const jd_scene *sc) {
    double wmax2 = sc->n_bond_types ? scene_omega2(sc) : 0.0;
    for (size_t k = 0; sc->n_bond_types && k < sc->n_inlets; k++)
        wmax2 = fmax(wmax2, inlet_omega2(sc, &sc->inlets[k]));
    return wmax2;
}

/* The scene's own bonds and rules (its particles at step 0). */
static double scene_omega2(const jd_scene *sc) {
    if (!sc->n_bond_types || (!sc->n_bonds && !sc->n_bond_rules)) return 0.0;
    double *w2 = calloc(sc->n_particles ? sc->n_particles : 1, sizeof *w2);
    if (!w2) return INFINITY; /* cannot assess: report as unsafe */
    double *m = malloc((sc->n_particles ? sc->n_particles : 1) * sizeof *m);
    if (!m) {
        free(w2);
        return INFINITY;
    }
    for (size_t i = 0; i < sc->n_particles; i++)
        m[i] = jd_sphere_mass(sc->radius[i], sc->materials[sc->material[i]].density);
    for (size_t k = 0; k < sc->n_bonds; k++) {
        const long i = index_of_id(sc, sc->bond_ids[2 * k]), j = index_of_id(sc, sc->bond_ids[2 * k + 1]);
        if (i < 0 || j < 0) continue;
        const jd_bond_params *p = &sc->bond_types[sc->bond_type[k]].p;
        double dx[3];
        for (int d = 0; d < 3; d++) dx[d] = sc->position[3 * j + d] - sc->position[3 * i + d];
        const double wk = jd_bond_omega2_pair(p, sc->radius[i], sc->radius[j], m[i], m[j],
                                              sqrt(jd_dot(dx, dx)));
        w2[i] += wk;
        w2[j] += wk;
    }
    for (size_t r = 0; r < sc->n_bond_rules; r++) {
        const jd_bond_rule *rule = &sc->bond_rules[r];
        const jd_bond_params *p = &sc->bond_types[rule->type].p;
        for (size_t i = 0; i < sc->n_particles; i++) {
            if (!rule->materials[sc->material[i]] || sc->id[i] < rule->id_range[0] ||
                sc->id[i] > rule->id_range[1])
                continue;
            w2[i] += jd_bond_omega2_rule(p, sc->radius[i], m[i]);
        }
    }
    double wmax2 = 0.0;
    for (size_t i = 0; i < sc->n_particles; i++) wmax2 = fmax(wmax2, w2[i]);
    free(w2);
    free(m);
    return wmax2;
}
