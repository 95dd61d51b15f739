/*
 * forces.c — force loops.  The scene's feature set (JD_F_* bits) is fixed for a run; the loop
 * body is instantiated once per combination with the bits as a literal constant, so that
 * jd_contact() compiles away every law the scene does not use (DESIGN.md: "leave out what a
 * scene does not need").  Order as LIGGGHTS: pair forces in list order, wall forces, gravity.
 */
#include <math.h>
#include <string.h>

#include "geometry.h"
#include "sim.h"

#if defined(__GNUC__)
#define JD_ALWAYS_INLINE inline __attribute__((always_inline))
#else
#define JD_ALWAYS_INLINE inline
#endif

static JD_ALWAYS_INLINE void load_kinematics(const jd_sim *s, int32_t i, jd_kinematics *k) {
    const double *v = s->v + 3 * (size_t)i, *w = s->omega + 3 * (size_t)i;
    for (int d = 0; d < 3; d++) {
        k->va[d] = v[d];
        k->wa[d] = w[d];
    }
}

static JD_ALWAYS_INLINE void pair_loop(jd_sim *s, const unsigned F) {
    const jd_contact_list *L = &s->pairs;
    const size_t nm = s->n_materials;
    for (size_t c = 0; c < L->n; c++) {
        const int32_t i = L->i[c], j = L->j[c];
        jd_contact_state *st = &L->state[c];
        jd_rolling_state *rs = (F & JD_F_ROLLING) ? &L->roll[c] : NULL;
        jd_contact_geom g;
        if (!sim_pair_geom(s, F, i, j, &g)) {
            jd_contact_separate(st, rs);
            continue;
        }
        if (jd_overlap_excessive(g.delta, s->radius[i], s->radius[j], s->max_overlap))
            sim_watchdog_overlap(s, i, j, g.delta, fmin(s->radius[i], s->radius[j]));
        jd_kinematics k;
        load_kinematics(s, i, &k);
        const double *vb = s->v + 3 * (size_t)j, *wb = s->omega + 3 * (size_t)j;
        for (int d = 0; d < 3; d++) {
            k.vb[d] = vb[d];
            k.wb[d] = wb[d];
        }
        const jd_pair_coeffs *co = &s->coeffs[(size_t)s->species[i] * nm + (size_t)s->species[j]];
        jd_contact_result out;
        if (!jd_contact(F, co, &g, &k, s->dt, st, rs, &out)) continue;
        double *fa = s->f + 3 * (size_t)i, *fb = s->f + 3 * (size_t)j;
        double *ta = s->torque + 3 * (size_t)i, *tb = s->torque + 3 * (size_t)j;
        for (int d = 0; d < 3; d++) {
            fa[d] -= out.f[d];
            fb[d] += out.f[d];
            ta[d] += out.ta[d];
            tb[d] += out.tb[d];
        }
    }
}

static JD_ALWAYS_INLINE void wall_loop(jd_sim *s, const unsigned F) {
    const jd_contact_list *L = &s->wall_pairs;
    const size_t nm = s->n_materials;
    double work = 0.0;
    for (size_t c = 0; c < L->n; c++) {
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
            sim_watchdog_overlap(s, i, -1 - L->j[c], g.delta, s->radius[i]);
        jd_kinematics k;
        load_kinematics(s, i, &k);
        for (int d = 0; d < 3; d++) {
            k.vb[d] = w->v[d];
            k.wb[d] = 0.0;
        }
        const jd_pair_coeffs *co = &s->coeffs[(size_t)s->species[i] * nm + (size_t)w->material];
        jd_contact_result out;
        const double f_prev[3] = {st->f_prev[0], st->f_prev[1], st->f_prev[2]};
        const int carries = jd_contact(F, co, &g, &k, s->dt, st, rs, &out);
        work += jd_wall_work(f_prev, out.f, w->v, s->dt); /* also over the step a contact ends */
        if (!carries) continue;
        double *fa = s->f + 3 * (size_t)i, *ta = s->torque + 3 * (size_t)i;
        for (int d = 0; d < 3; d++) {
            fa[d] -= out.f[d];
            ta[d] += out.ta[d];
        }
    }
    s->wall_work += work;
}

static JD_ALWAYS_INLINE void contact_loops(jd_sim *s, const unsigned F) {
    pair_loop(s, F);
    wall_loop(s, F);
}

/* One instantiation per combination of the four optional laws; JD_F_ENERGY is always on (the
 * observables need it).  The switch maps the run-time bits to a literal constant. */
#define JD_FORCE_CASE(bits)                        \
    case (bits):                                   \
        contact_loops(s, (bits) | JD_F_ENERGY);    \
        break;

void sim_compute_forces(jd_sim *s) {
    s->overlap_trip.fraction = 0.0; /* the watchdog looks at this evaluation only */
    memset(s->f, 0, 3 * s->n * sizeof *s->f);
    memset(s->torque, 0, 3 * s->n * sizeof *s->torque);
    _Static_assert(JD_F_DAMPING == 1 && JD_F_FRICTION == 2 && JD_F_ROLLING == 4 && JD_F_MU_R == 8,
                   "the dispatch below enumerates the four optional laws as bits 0-3");
    switch (s->features & 15u) {
        JD_FORCE_CASE(0) JD_FORCE_CASE(1) JD_FORCE_CASE(2) JD_FORCE_CASE(3)
        JD_FORCE_CASE(4) JD_FORCE_CASE(5) JD_FORCE_CASE(6) JD_FORCE_CASE(7)
        JD_FORCE_CASE(8) JD_FORCE_CASE(9) JD_FORCE_CASE(10) JD_FORCE_CASE(11)
        JD_FORCE_CASE(12) JD_FORCE_CASE(13) JD_FORCE_CASE(14) JD_FORCE_CASE(15)
    }
    if (s->bonds) sim_bonds_forces(s); /* in parallel with the contacts (bonds.c) */
    const double *g = s->g;
    if (g[0] != 0.0 || g[1] != 0.0 || g[2] != 0.0) {
        for (size_t i = 0; i < s->n; i++) {
            const double m = s->mass[i];
            for (int d = 0; d < 3; d++) s->f[3 * i + d] += m * g[d];
        }
    }
    if (s->loads) sim_loads_apply(s); /* last, as LIGGGHTS' post-force fixes (loads.c) */
}
