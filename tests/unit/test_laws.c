/*
 * test_laws.c — the laws jd_contact is composed of, each alone against its closed form, and the
 * rulebook both engines call (jdem_laws.h): law-set selection, the list of law sets, the pair
 * coefficients, the history records; and the laws jd_bond is composed of, with the bonds'
 * frequency bound.
 */
#include <string.h>

#include "unit.h"

#include "jdem_bond.h"
#include "jdem_guard.h"
#include "jdem_kernel.h"
#include "jdem_laws.h"

enum { ALL = JD_F_DAMPING | JD_F_FRICTION | JD_F_ROLLING | JD_F_MU_R | JD_F_ENERGY | JD_F_MINDLIN |
             JD_F_MEPA };

/* Two spheres along z, a at the origin, overlapping by delta. */
static jd_contact_geom geom_z(double delta, double R, double k_n, double m_eff) {
    jd_contact_geom g = {.n = {0, 0, 1}, .delta = delta, .k_n = k_n, .m_eff = m_eff,
                         .i_eff = 0.2 * m_eff * R * R, .r_roll = 0.5 * R};
    g.ra[2] = R - 0.5 * delta;
    g.rb[2] = -(R - 0.5 * delta);
    return g;
}

static void kinematics_is_eq6(void **state) {
    (void)state;
    const jd_contact_geom g = geom_z(1e-4, 0.01, 1e9, 1e-3);
    const jd_kinematics k = {.va = {0.1, 0, 0.2}, .wa = {0, 3, 0}, .vb = {0, 0.4, -0.1},
                             .wb = {1, 0, 0}};
    jd_contact_motion m;
    jd_contact_kinematics(JD_F_ROLLING, &g, &k, &m);
    const double la = 0.01 - 0.5e-4;
    /* w_a x r_a = (0,3,0) x (0,0,la) = (3 la, 0, 0); w_b x r_b = (1,0,0) x (0,0,-la) = (0, la, 0) */
    assert_rel(m.vrel[0], 0.0 - (0.1 + 3 * la), 1e-15);
    assert_rel(m.vrel[1], 0.4 + la, 1e-15);
    assert_rel(m.vrel[2], -0.1 - 0.2, 1e-15);
    assert_rel(m.vn, -0.3, 1e-15);
    assert_rel(m.ddelta, 0.3, 1e-15);
    assert_rel(m.wrel[0], 1.0, 0.0);
    assert_rel(m.wrel[1], -3.0, 0.0);
    jd_contact_kinematics(0u, &g, &k, &m); /* without rolling the relative spin is not computed */
    assert_true(m.wrel[0] == 0.0 && m.wrel[1] == 0.0 && m.wrel[2] == 0.0);
}

static void normal_law_with_damping_and_luding_end(void **state) {
    (void)state;
    const double k = 1e9, d = 2e-5, m = 0.01;
    const jd_contact_geom g = geom_z(d, 0.01, k, m);
    const jd_pair_coeffs c = {.gamma = 0.2, .mu = 0.5, .mu_r = 1.0};
    jd_normal nl;
    jd_law_normal(0u, &c, &g, 0.7, 0, 0.0, 0.0, &nl); /* undamped: Hertz alone, gamma ignored */
    assert_rel(nl.fn, k * pow(d, 1.5), 1e-14);
    assert_rel(nl.Kn, k * sqrt(d), 1e-14);
    assert_true(nl.Cn == 0.0 && nl.carries && !nl.ends);
    jd_law_normal(JD_F_DAMPING, &c, &g, 0.7, 0, 0.0, 0.0, &nl); /* eq. (29), (31) */
    assert_rel(nl.Cn, 2.0 * 0.2 * sqrt(m * k * sqrt(d)), 1e-14);
    assert_rel(nl.fn, k * pow(d, 1.5) + nl.Cn * 0.7, 1e-14);
    /* unloading so fast that the dashpot outpulls the spring: Luding's end, no force */
    const double fast = -2.0 * k * pow(d, 1.5) / nl.Cn;
    jd_law_normal(JD_F_DAMPING, &c, &g, fast, 0, 0.0, 0.0, &nl);
    assert_true(nl.fn < 0.0 && nl.ends && !nl.carries);
    jd_law_normal(0u, &c, &g, fast, 0, 0.0, 0.0, &nl); /* without damping a contact never ends so */
    assert_true(nl.carries && !nl.ends);
    jd_law_normal(JD_F_DAMPING, &c, &g, -1e-3, 1, 0.0, 0.0, &nl); /* still ended: carries nothing */
    assert_true(!nl.carries && !nl.ends);
}

static void contact_begin_restarts_an_ended_contact(void **state) {
    (void)state;
    const jd_contact_geom g = geom_z(1e-4, 0.01, 1e9, 1e-3);
    jd_contact_state s = {.xi = {1e-6, 0, 0}, .flags = JD_S_ENDED, .u_prev = 5.0, .e_damp = 2.0,
                          .e_fric = 1.0};
    jd_contact_step h;
    jd_contact_begin(JD_F_ENERGY, &g, &s, NULL, -0.1, &h); /* still separating */
    assert_true(h.still_ended && !h.restart && h.xi[0] == 1e-6 && h.u_prev == 5.0);
    jd_contact_begin(JD_F_ENERGY, &g, &s, NULL, 0.1, &h); /* approaching again: a new contact */
    const double u = 0.4 * 1e9 * pow(1e-4, 2.5);
    assert_true(!h.still_ended && h.restart && h.xi[0] == 0.0 && h.flags == 0.0);
    assert_rel(h.u_prev, u, 1e-14);        /* the compressed spring is stored again */
    assert_rel(h.e_damp, 2.0 - u, 1e-14);  /* and taken back from damping */
    assert_rel(h.e_fric, 1.0, 0.0);
}

static void tangential_law_sticks_then_slides(void **state) {
    (void)state;
    const double k = 1e9, d = 1e-4, dt = 1e-6;
    const jd_contact_geom g = geom_z(d, 0.01, k, 1e-3);
    const jd_pair_coeffs c = {.gamma = 0.0, .mu = 0.3, .mu_r = 1.0, .xi_limit = JD_XI_COULOMB};
    jd_normal nl;
    jd_law_normal(0u, &c, &g, 0.0, 0, 0.0, 0.0, &nl);
    jd_contact_motion m = {.vrel = {0.01, 0, 0}, .vn = 0.0};
    jd_contact_step h = {0};
    double f[3] = {0, 0, nl.fn}, u = 0.0, dash = 0.0;
    jd_law_tangential(JD_F_FRICTION | JD_F_ENERGY, &c, &g, &m, &nl, dt, &h, f, &u, &dash);
    const double Kt = k * sqrt(d); /* K_t = K_n */
    assert_rel(f[0], -Kt * 0.01 * dt, 1e-14);
    assert_rel(h.xi[0], 0.01 * dt, 1e-14);
    assert_rel(u, 0.5 * Kt * (0.01 * dt) * (0.01 * dt), 1e-13);
    assert_true(h.flags == 0.0 && dash == 0.0);
    /* a slip far beyond mu F_n / K_t: the force is capped and xi reset to it (Coulomb) */
    m.vrel[0] = 1e3;
    f[0] = 0.0;
    jd_law_tangential(JD_F_FRICTION, &c, &g, &m, &nl, dt, &h, f, &u, &dash);
    assert_rel(f[0], -0.3 * nl.fn, 1e-14);
    assert_rel(h.xi[0], 0.3 * nl.fn / Kt, 1e-14);
    assert_true(h.flags == (double)JD_S_SLIDING);
}

/* Mindlin's K_t = 8 G* sqrt(R* delta), 1/G* = 2(2-nu1)(1+nu1)/E1 + 2(2-nu2)(1+nu2)/E2 (LIGGGHTS'
 * Geff and hertz model), with C_t = 2 gamma sqrt(m K_t) (eq. 29); the seed's K_t = K_n without
 * the bit. */
static void mindlin_tangential_stiffness_is_8_g_sqrt_r_delta(void **state) {
    (void)state;
    const double E1 = 2.08e11, nu1 = 0.3, E2 = 7.0e10, nu2 = 0.33, R = 0.01, d = 1e-5, m = 1e-3;
    const double g_star = 1.0 / (2.0 * (2.0 - nu1) * (1.0 + nu1) / E1 + 2.0 * (2.0 - nu2) * (1.0 + nu2) / E2);
    const jd_contact_geom g = geom_z(d, R, 1e9, m); /* r_roll = R/2 = R* of two spheres of R */
    const jd_pair_coeffs c = {.gamma = 0.2, .mu = 0.3, .mu_r = 1.0, .g_star = g_star};
    jd_normal nl;
    jd_law_normal(JD_F_DAMPING, &c, &g, 0.0, 0, 0.0, 0.0, &nl);
    const double Kt = jd_tangential_stiffness(JD_F_FRICTION | JD_F_MINDLIN, &c, &g, &nl);
    assert_rel(Kt, 8.0 * g_star * sqrt(0.5 * R * d), 1e-15);
    assert_rel(jd_tangential_damping(JD_F_DAMPING | JD_F_FRICTION | JD_F_MINDLIN, &c, &g, &nl, Kt),
               2.0 * 0.2 * sqrt(m * Kt), 1e-15);
    assert_true(jd_tangential_damping(JD_F_FRICTION | JD_F_MINDLIN, &c, &g, &nl, Kt) == 0.0);
    assert_true(jd_tangential_stiffness(JD_F_FRICTION, &c, &g, &nl) == nl.Kn);
    assert_true(jd_tangential_damping(JD_F_DAMPING | JD_F_FRICTION, &c, &g, &nl, nl.Kn) == nl.Cn);
    /* the law sticks on K_t: F_t = -K_t xi */
    jd_contact_motion mo = {.vrel = {0.01, 0, 0}};
    jd_contact_step h = {0};
    double f[3] = {0, 0, nl.fn}, u = 0.0, dash = 0.0;
    jd_law_tangential(JD_F_FRICTION | JD_F_MINDLIN, &c, &g, &mo, &nl, 1e-6, &h, f, &u, &dash);
    assert_rel(f[0], -Kt * 0.01 * 1e-6, 1e-14);
}

/* For like spheres Mindlin's K_t against the tangent normal stiffness dF_n/d(delta) = 3/2 K_n of
 * the Hertz law (k_n of eqs. 4-5) is 2(1-nu)/(2-nu) (Mindlin 1949; Johnson 1985 §7.2). */
static void mindlin_over_hertz_tangent_is_2_1mnu_over_2mnu(void **state) {
    (void)state;
    const double E = 7.0e10, nu = 0.33, R = 0.1, d = 2e-6;
    jd_pair_coeffs t[1];
    const double e = 1.0, mu = 0.4, eta = 0.0;
    jd_pair_coeffs_table(1, &e, &mu, &eta, &E, &nu, JD_DAMP_JIANG2021, 1.0, JD_XI_COULOMB, NULL,
                         t);
    const double kp = jd_hertz_prefactor(E, nu, R);
    jd_contact_geom g = geom_z(d, R, jd_kn_pair(kp, kp), 1.0);
    jd_normal nl;
    jd_law_normal(0u, &t[0], &g, 0.0, 0, 0.0, 0.0, &nl);
    const double Kt = jd_tangential_stiffness(JD_F_FRICTION | JD_F_MINDLIN, &t[0], &g, &nl);
    assert_rel(Kt / (1.5 * nl.Kn), 2.0 * (1.0 - nu) / (2.0 - nu), 1e-14);
    /* against a rigid wall (r_roll = R, G* of the particle alone): the same ratio to the exact
     * rigid-plane Hertz stiffness, whose prefactor is jd_kn_wall's */
    const jd_pair_coeffs w = jd_wall_coeffs(&t[0]);
    g.r_roll = R;
    g.k_n = jd_kn_wall(JD_WALL_HERTZ, E, nu, R);
    jd_law_normal(0u, &w, &g, 0.0, 0, 0.0, 0.0, &nl);
    assert_rel(jd_tangential_stiffness(JD_F_FRICTION | JD_F_MINDLIN, &w, &g, &nl) / (1.5 * nl.Kn),
               2.0 * (1.0 - nu) / (2.0 - nu), 1e-14);
}

static void rolling_law_spring_and_cap(void **state) {
    (void)state;
    const double k = 1e9, d = 1e-4, dt = 1e-6, R = 0.01;
    const jd_contact_geom g = geom_z(d, R, k, 1e-3);
    const jd_pair_coeffs c = {.gamma = 0.1, .eta = 0.05, .mu_r = 1.0, .xi_limit = JD_XI_COULOMB};
    jd_normal nl;
    jd_law_normal(JD_F_DAMPING, &c, &g, 0.0, 0, 0.0, 0.0, &nl);
    const jd_contact_motion m = {.wrel = {0, 2.0, 0}};
    jd_contact_step h = {0};
    double mr[3], u = 0.0, dash = 0.0;
    jd_law_rolling(JD_F_ROLLING | JD_F_DAMPING, &c, &g, &m, &nl, dt, &h, mr, &u, &dash);
    const double Kr = k * sqrt(d) * g.r_roll * g.r_roll, Cr = 2.0 * 0.1 * sqrt(g.i_eff * Kr);
    const double free_moment = Kr * 2.0 * dt + Cr * 2.0, cap = 0.05 * g.r_roll * nl.fn;
    /* eq. (32): the spring-dashpot moment, or the cap eta r F_n when it is smaller */
    assert_rel(-mr[1], free_moment < cap ? free_moment : cap, 1e-13);
    assert_rel(h.theta[1], free_moment < cap ? 2.0 * dt : cap / Kr, 1e-13);
}

static void energy_law_books_work_and_luding_end(void **state) {
    (void)state;
    const double dt = 1e-6;
    const jd_contact_motion m = {.vrel = {0, 0, -0.5}, .ddelta = 0.5};
    const jd_kinematics k = {.vb = {0, 0, -0.5}}; /* no spin: v_rel at the centres is m's */
    jd_normal nl = {.fn = 10.0, .Cn = 2.0, .carries = 1};
    const jd_contact_step h = {.f_prev = {0, 0, 8.0}, .fd_prev = 0.6, .u_prev = 1e-3,
                               .e_damp = 0.25, .e_fric = 0.125};
    const double f[3] = {0, 0, 10.0}, mr[3] = {0, 0, 0}, u_new = 1.5e-3;
    jd_contact_energy e;
    jd_law_energy(JD_F_DAMPING | JD_F_ENERGY, &k, &m, &nl, &h, f, mr, u_new, 0.0, dt, &e);
    /* trapezoidal work on the bodies, W = -(8 + 10)/2 * 0.5 dt; dissipated = -W - dU, all of it
     * the dashpot's without sliders */
    const double W = 0.5 * (8.0 * -0.5 + 10.0 * -0.5) * dt;
    assert_rel(e.fd, 2.0 * 0.5, 0.0);
    assert_rel(e.e_damp, 0.25 + (-W - (u_new - 1e-3)), 1e-14);
    assert_rel(e.e_fric, 0.125, 0.0);
    /* at Luding's end the stored energy is lost, less the previous force's work this step */
    nl.ends = 1;
    nl.carries = 0;
    jd_law_energy(JD_F_DAMPING | JD_F_ENERGY, &k, &m, &nl, &h, f, mr, u_new, 0.0, dt, &e);
    assert_rel(e.e_damp, 0.25 + (1e-3 - 0.5 * (8.0 * -0.5) * dt), 1e-14);
    /* with a slider the dashpots' share stays damping and the rest is friction */
    nl.ends = 0;
    jd_law_energy(JD_F_FRICTION | JD_F_ENERGY, &k, &m, &nl, &h, f, mr, u_new, 1e-7, dt, &e);
    const double dash = 1e-7 + 0.5 * (0.6 + 1.0) * 0.5 * dt;
    assert_rel(e.e_damp, 0.25 + dash, 1e-14);
    assert_rel(e.e_fric, 0.125 + ((-W - (u_new - 1e-3)) - dash), 1e-13);
}

/* The previous force works through the levers it was applied with: f_prev = (1, 0, 0) N applied
 * at r_a = (0, 0, 0.01), r_b = (0, 0, -0.01) m gave T_a = r_a x (-f) = (0, -0.01, 0) and
 * T_b = r_b x f = (0, -0.01, 0) N m; with the bodies spinning at w_a = (0, 3, 0), w_b = (0, 5, 0)
 * rad/s and not translating, its work rate is T_a.w_a + T_b.w_b = -0.08 W, whatever the levers
 * are now (turned to x, where f x r would give 0).  This step's force is zero and nothing is
 * stored, so without sliders the dashpot books -1/2 (-0.08) dt. */
static void energy_law_uses_the_previous_levers(void **state) {
    (void)state;
    const double dt = 1e-4;
    const jd_contact_motion m = {.vrel = {0, 0, 0}};
    const jd_kinematics k = {.wa = {0, 3, 0}, .wb = {0, 5, 0}};
    const jd_normal nl = {.carries = 1};
    const jd_contact_step h = {.f_prev = {1, 0, 0}, .ts_prev = {0, -0.02, 0}, .td_prev = {0, 0, 0}};
    const double f[3] = {0, 0, 0}, mr[3] = {0, 0, 0};
    jd_contact_energy e;
    jd_law_energy(JD_F_DAMPING | JD_F_ENERGY, &k, &m, &nl, &h, f, mr, 0.0, 0.0, dt, &e);
    assert_rel(e.e_damp, -0.5 * -0.08 * dt, 1e-14);
    /* a <-> b: the difference flips sign, the spins swap: the same work */
    const jd_kinematics ks = {.wa = {0, 5, 0}, .wb = {0, 3, 0}};
    const jd_contact_step hs = {.f_prev = {-1, 0, 0}, .ts_prev = {0, -0.02, 0}, .td_prev = {0, 0, 0}};
    jd_law_energy(JD_F_DAMPING | JD_F_ENERGY, &ks, &m, &nl, &hs, f, mr, 0.0, 0.0, dt, &e);
    assert_rel(e.e_damp, -0.5 * -0.08 * dt, 1e-14);
}

static void law_sets_are_the_combinations_with_mu_r_and_mindlin_only_with_friction(void **state) {
    (void)state;
    int n = 0;
    for (unsigned b = 0; b <= ALL; b++) {
        const int expected = !((b & (JD_F_MU_R | JD_F_MINDLIN)) && !(b & JD_F_FRICTION));
        assert_int_equal(jd_law_set_valid(b), expected);
        n += jd_law_set_valid(b);
    }
    /* 2 (MEPA) x 2 (energy) x (4 without friction + 2 (mindlin) x 8 with it) */
    assert_int_equal(n, 80);
    assert_int_equal(jd_law_set_valid(ALL + 1), 0);
}

/* The compiled loops (JD_LAW_LOOPS) are the valid sets without a run-time law, and each valid
 * law set runs in exactly one of them, whose law set inside is the run's own again. */
#define COUNT_LOOP(bits)                              \
    n_loops++;                                        \
    assert_int_equal((bits) & JD_F_RUN_TIME, 0u);     \
    assert_true(jd_law_set_valid(bits));
#define MATCH_LOOP(bits) matches += (bits) == loop;
static void every_law_set_runs_in_one_compiled_loop(void **state) {
    (void)state;
    int n_loops = 0;
    JD_LAW_LOOPS(COUNT_LOOP)
    assert_int_equal(n_loops, 24); /* 2 (energy) x (4 without friction + 8 with it) */
    for (unsigned b = 0; b <= ALL; b++) {
        if (!jd_law_set_valid(b)) continue;
        const unsigned loop = jd_law_set_loop(b);
        int matches = 0;
        JD_LAW_LOOPS(MATCH_LOOP)
        assert_int_equal(matches, 1);
        assert_int_equal(jd_law_set_of_loop(loop, b), b);
    }
}
#undef COUNT_LOOP
#undef MATCH_LOOP

static void law_set_select_counts_only_interactions_that_occur(void **state) {
    (void)state;
    /* materials: 0 and 1 for particles, 2 for walls only, 3 unused */
    enum { NM = 4 };
    double e[NM * NM], mu[NM * NM], eta[NM * NM];
    for (int k = 0; k < NM * NM; k++) e[k] = 1.0, mu[k] = 0.0, eta[k] = 0.0;
    const unsigned char parts[NM] = {1, 1, 0, 0}, walls[NM] = {0, 0, 1, 0};
    mu[3 * NM + 3] = 0.5;  /* unused against unused */
    e[2 * NM + 2] = 0.5;   /* wall against wall: never occurs */
    eta[3 * NM + 0] = 0.1; /* unused against a particle material */
    const int KT = JD_KT_JIANG2021, MINDLIN = JD_KT_MINDLIN, HZ = JD_NORMAL_HERTZ;
    assert_int_equal(jd_law_set_select(NM, e, mu, eta, parts, walls, 1.0, MINDLIN, HZ, 0), 0u);
    assert_int_equal(jd_law_set_select(NM, e, mu, eta, parts, walls, 1.0, KT, HZ, 0), 0u);
    e[1 * NM + 2] = 0.9; /* particle against wall */
    assert_int_equal(jd_law_set_select(NM, e, mu, eta, parts, walls, 1.0, KT, HZ, 0), JD_F_DAMPING);
    assert_int_equal(jd_law_set_select(NM, e, mu, eta, parts, NULL, 1.0, KT, HZ, 0), 0u);
    eta[0 * NM + 1] = 0.1; /* particle against particle */
    assert_int_equal(jd_law_set_select(NM, e, mu, eta, parts, walls, 0.5, KT, HZ, 1),
                     JD_F_DAMPING | JD_F_ROLLING | JD_F_ENERGY); /* mu_R needs friction */
    mu[1 * NM + 0] = 0.3;
    assert_int_equal(jd_law_set_select(NM, e, mu, eta, parts, walls, 0.5, KT, HZ, 0),
                     JD_F_DAMPING | JD_F_FRICTION | JD_F_ROLLING | JD_F_MU_R);
    assert_int_equal(jd_law_set_select(NM, e, mu, eta, parts, walls, 1.0, KT, HZ, 0),
                     JD_F_DAMPING | JD_F_FRICTION | JD_F_ROLLING);
    assert_int_equal(jd_law_set_select(NM, e, mu, eta, parts, walls, 1.0, MINDLIN, HZ, 0),
                     JD_F_DAMPING | JD_F_FRICTION | JD_F_ROLLING | JD_F_MINDLIN);
    assert_int_equal(jd_law_set_select(NM, e, mu, eta, parts, walls, 1.0, KT, JD_NORMAL_MEPA, 1),
                     JD_F_DAMPING | JD_F_FRICTION | JD_F_ROLLING | JD_F_MEPA | JD_F_ENERGY);
}

static void law_set_names(void **state) {
    (void)state;
    char buf[96];
    assert_string_equal(jd_law_set_describe(0u, buf, sizeof buf), "elastic");
    assert_string_equal(jd_law_set_describe(JD_F_DAMPING | JD_F_FRICTION | JD_F_ENERGY, buf, sizeof buf),
                        "damping+friction+energy");
    assert_string_equal(jd_law_set_describe(ALL, buf, sizeof buf),
                        "damping+friction+rolling+mu_r+energy+mindlin+mepa");
    assert_string_equal(jd_law_set_describe(ALL, buf, 8), "damping"); /* truncated, terminated */
}

static void pair_coeffs_table_maps_each_restitution(void **state) {
    (void)state;
    const double e[4] = {0.5, 0.9, 0.9, 1.0}, mu[4] = {0.1, 0.2, 0.3, 0.4}, eta[4] = {0, 0.01, 0.02, 0};
    const double E[2] = {2.08e11, 0.0}, nu[2] = {0.3, 0.0}; /* material 1: wall-only, rigid */
    jd_pair_coeffs t[4];
    jd_pair_coeffs_table(2, e, mu, eta, E, nu, JD_DAMP_JIANG2021, 0.7, JD_XI_UNCONSTRAINED, NULL,
                         t);
    for (int k = 0; k < 4; k++) {
        /* eq. (30) */
        const double le = log(e[k]), gamma = -le / sqrt(3.14159265358979323846 * 3.14159265358979323846 + le * le);
        assert_rel(t[k].gamma, gamma, 1e-15);
        assert_true(t[k].mu == mu[k] && t[k].eta == eta[k] && t[k].mu_r == 0.7);
        assert_int_equal(t[k].xi_limit, JD_XI_UNCONSTRAINED);
    }
    assert_true(t[3].gamma == 0.0);
    /* LIGGGHTS' Geff: 1/G* = 2(2-nu)(1+nu)/E per elastic material, a rigid one adds nothing */
    const double g_self = 2.08e11 / (2.0 * 1.7 * 1.3);
    assert_rel(t[0].g_star, 0.5 * g_self, 1e-15);
    assert_rel(t[1].g_star, g_self, 1e-15);
    assert_rel(t[0].g_wall, g_self, 1e-15);
    assert_rel(t[2].g_star, g_self, 1e-15);
    assert_true(t[3].g_star == 0.0); /* two rigid materials never touch */
    assert_rel(jd_wall_coeffs(&t[0]).g_star, g_self, 1e-15);
}

static void records_keep_the_law_fields_or_everything(void **state) {
    (void)state;
    assert_int_equal(jd_contact_record_len(0u), 4);
    assert_int_equal(jd_contact_record_len(JD_F_ENERGY), JD_CONTACT_ENERGY_LEN);
    assert_int_equal(jd_contact_record_len(JD_F_MEPA), JD_CONTACT_STATE_LEN); /* dp comes last */
    assert_int_equal(jd_contact_record_len(JD_F_MEPA | JD_F_ENERGY), JD_CONTACT_STATE_LEN);
    assert_int_equal(jd_rolling_record_len(JD_F_ENERGY), 0);
    assert_int_equal(jd_rolling_record_len(JD_F_ROLLING), 3);
    assert_int_equal(jd_rolling_record_len(JD_F_ROLLING | JD_F_ENERGY), JD_ROLLING_STATE_LEN);
    double h[JD_CONTACT_STATE_LEN], r[JD_ROLLING_STATE_LEN];
    for (int k = 0; k < JD_CONTACT_STATE_LEN; k++) h[k] = k + 1.0;
    for (int k = 0; k < JD_ROLLING_STATE_LEN; k++) r[k] = -(k + 1.0);
    jd_contact_state st;
    jd_rolling_state rs;
    jd_record_load(h, 4, r, 3, &st, &rs); /* the short records: the rest reads as zero */
    assert_true(st.xi[0] == 1.0 && st.xi[2] == 3.0 && st.flags == 4.0 && st.f_prev[0] == 0.0 &&
                st.e_fric == 0.0 && rs.theta[2] == -3.0 && rs.m_prev[0] == 0.0);
    jd_record_load(h, JD_CONTACT_STATE_LEN, NULL, 0, &st, &rs);
    assert_true(st.e_damp == 10.0 && st.e_fric == 11.0 && st.dp == 18.0 && rs.theta[0] == 0.0);
    double h2[JD_CONTACT_STATE_LEN] = {0}, r2[JD_ROLLING_STATE_LEN] = {0};
    jd_record_store(h2, 4, r2, 0, &st, &rs);
    assert_true(h2[3] == 4.0 && h2[4] == 0.0 && r2[0] == 0.0);
    /* separation: everything zero but the dissipation accumulators, as jd_contact_separate */
    jd_record_separate(h, JD_CONTACT_STATE_LEN, r, JD_ROLLING_STATE_LEN);
    jd_contact_state ref;
    jd_rolling_state rref;
    memcpy(&ref, (double[JD_CONTACT_STATE_LEN]){1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11}, sizeof ref);
    memcpy(&rref, r, sizeof rref);
    rref.theta[0] = 1.0;
    jd_contact_separate(&ref, &rref);
    assert_memory_equal(h, &ref, sizeof h);
    assert_memory_equal(r, &rref, sizeof r);
    /* LIGGGHTS' sign flags of a combined record: the contact record's, then the rolling one's */
    assert_int_equal(jd_record_newton(4, 3), 0);
    assert_int_equal(jd_record_newton(4, 4), 1);
    assert_int_equal(jd_record_newton(JD_CONTACT_STATE_LEN, 7), jd_contact_state_newton[7]);
}

/* ---- MEPA (Del Cid 2015; docs/model.md §13) ---- */

/* Del Cid's copper ore, 5 % moisture (her Table 5.1 script values per atom type, spec §1.6): the
 * pair values of two like spheres are the series combination, half the type's. */
static jd_mepa_coeffs copper_ore(double kadh_type) {
    static double k1[1] = {474788897.8}, k2[1] = {2373944489.0}, kadh[1];
    kadh[0] = kadh_type;
    const jd_mepa_inputs in = {.k1 = k1, .k2 = k2, .kadh = kadh, .n = 1.5, .depth = 0.1};
    return jd_mepa_coeffs_of(&in, 0, 0);
}

/* F of a MEPA contact driven from dp along overlaps d0 -> d1 in n equal steps (the rate's sign
 * from the direction); *dp updated; the smallest force and its overlap into *fmin, *dmin. */
static double mepa_drive(const jd_mepa_coeffs *c, double r_star, double d0, double d1, int n,
                         double *dp, double *fmin, double *dmin) {
    double f = 0.0;
    for (int k = 1; k <= n; k++) {
        const double d = d0 + (d1 - d0) * k / n;
        jd_mepa_step step;
        f = jd_mepa_force(c, d, d1 - d0, r_star, *dp, &step);
        *dp = step.dp;
        if (fmin && f < *fmin) *fmin = f, *dmin = d;
    }
    return f;
}

/* Spec §8, "numbers an implementation can be checked against": for two 3.175 mm ore spheres,
 * dp_max = 0.15875 mm, the virgin branch ends at 0.18421 mm with Fmax = 593.5 N, and the largest
 * tension is Fmin = -309.7 N (8 %: -474.8 N) at 0.14463 mm. */
static void mepa_copper_ore_pair_has_del_cids_bounds(void **state) {
    (void)state;
    const jd_mepa_coeffs c = copper_ore(356091673.35);
    const double r_star = 0.5 * 3.175e-3, dp_max = 0.1 * r_star;
    assert_rel(c.k1, 2.374e8, 1e-3);
    assert_rel(c.k2, 1.187e9, 1e-3);
    assert_rel(c.kadh, 1.780e8, 1e-3);
    assert_rel(c.x_end * dp_max, 0.18421e-3, 1e-4);
    double dp = 0.0;
    /* virgin loading: F = k1 d^n with dp = ((k2 - k1)/k2)^(1/n) d */
    const double d_in = 0.1e-3;
    double f = mepa_drive(&c, r_star, 0.0, d_in, 1000, &dp, NULL, NULL);
    assert_rel(f, c.k1 * pow(d_in, 1.5), 1e-14);
    assert_rel(dp, pow(1.0 - c.k1 / c.k2, 1.0 / 1.5) * d_in, 1e-14);
    /* to the branch's end: Fmax, dp at its cap */
    f = mepa_drive(&c, r_star, d_in, c.x_end * dp_max, 1000, &dp, NULL, NULL);
    assert_rel(f, 593.5, 1e-3);
    assert_rel(dp, dp_max, 1e-12);
    /* past it: the k2 branch from dp_max */
    const double d_deep = 1.1 * c.x_end * dp_max;
    f = mepa_drive(&c, r_star, c.x_end * dp_max, d_deep, 100, &dp, NULL, NULL);
    assert_rel(f, c.k2 * (pow(d_deep, 1.5) - pow(dp_max, 1.5)), 1e-14);
    assert_true(dp == dp_max);
    /* unloading to separation: elastic along k2, then the adhesive bound down to zero */
    double fmin = 0.0, dmin = 0.0, dp5 = dp;
    f = mepa_drive(&c, r_star, d_deep, 1e-9, 200000, &dp5, &fmin, &dmin);
    assert_rel(fmin, -309.7, 1e-3);
    assert_rel(dmin, 0.14463e-3, 2e-4);
    assert_true(f < 0.0 && f > -1e-3 && dp5 < 1e-8); /* on the adhesive bound: dp follows d */
    const jd_mepa_coeffs c8 = copper_ore(5.93e8);
    fmin = 0.0;
    mepa_drive(&c8, r_star, d_deep, 1e-9, 200000, &dp, &fmin, &dmin);
    assert_rel(fmin, -474.8, 1e-3);
}

/* A whole contact (jd_contact with MEPA and the energy accounts, n = 1, no dashpot): loaded on
 * the virgin branch to d_a, unloaded to separation.  What it dissipated is the loop's area,
 * k1 d_a^2/2 - [k2 ((d_a - dp)^2 - (d_s - dp)^2)/2 - kadh d_s^2/2], dp = (1 - k1/k2) d_a, with
 * d_s = k2 dp/(k2 + kadh) where the k2 branch meets the adhesive bound. */
/* One MEPA contact driven through the loop of mepa_contact_dissipates_its_loop with law set F;
 * returns its final state. */
static jd_contact_state mepa_loop(unsigned F) {
    double k1t[1] = {2e5}, k2t[1] = {4e5}, kat[1] = {1e5}; /* pair: 1e5, 2e5, 5e4 N/m */
    const jd_mepa_inputs in = {.k1 = k1t, .k2 = k2t, .kadh = kat, .n = 1.0, .depth = 0.1};
    jd_pair_coeffs c = {.mu = 0.3, .mepa = jd_mepa_coeffs_of(&in, 0, 0)};
    const double d_a = 4e-4, v = 1e-3, dt = 1e-4;
    jd_contact_state st = {0};
    jd_contact_result out;
    double d = 0.0;
    const int n_load = 4000; /* d_a / (v dt) */
    for (int k = 1; k <= 2 * n_load; k++) {
        const int loading = k <= n_load;
        d += loading ? v * dt : -v * dt;
        if (d <= 1e-12) break;
        jd_contact_geom g = geom_z(d, 0.01, 0.0, 1e-3); /* R* 5 mm: dp_max 0.5 mm, never reached */
        const jd_kinematics kin = {.vb = {0, 0, loading ? -v : v}};
        assert_int_equal(jd_contact(F, &c, &g, &kin, dt, &st, NULL, &out), 1);
        if (k == n_load) {
            assert_rel(out.fn, 1e5 * d_a, 1e-9);
            assert_rel(st.dp, 0.5 * d_a, 1e-9);
        }
    }
    return st;
}

/* A whole contact (jd_contact with MEPA and the energy accounts, n = 1, no dashpot): loaded on
 * the virgin branch to d_a, unloaded to separation.  What it dissipated is the loop's area,
 * k1 d_a^2/2 - [k2 ((d_a - dp)^2 - (d_s - dp)^2)/2 - kadh d_s^2/2], dp = (1 - k1/k2) d_a, with
 * d_s = k2 dp/(k2 + kadh) where the k2 branch meets the adhesive bound; and it is booked as
 * plastic work (damping), not as friction, when the contact has a tangential law that never
 * slides (no tangential motion). */
static void mepa_contact_dissipates_its_loop(void **state) {
    (void)state;
    const double k1 = 1e5, k2 = 2e5, kadh = 5e4, d_a = 4e-4;
    const double dp = (1.0 - k1 / k2) * d_a, d_s = k2 * dp / (k2 + kadh);
    const double area = 0.5 * k1 * d_a * d_a -
                        (0.5 * k2 * ((d_a - dp) * (d_a - dp) - (d_s - dp) * (d_s - dp)) -
                         0.5 * kadh * d_s * d_s);
    const jd_contact_state alone = mepa_loop(JD_F_MEPA | JD_F_ENERGY);
    assert_rel(alone.e_damp + alone.u_prev, area, 1e-3);
    assert_true(alone.e_fric == 0.0);
    const jd_contact_state with_friction = mepa_loop(JD_F_MEPA | JD_F_FRICTION | JD_F_ENERGY);
    assert_rel(with_friction.e_damp + with_friction.u_prev, area, 1e-3);
    assert_true(fabs(with_friction.e_fric) <= 1e-6 * area);
}

/* The guard's MEPA impact: for n = 1 a quarter period on k1 and one on k2; for n = 3/2 its
 * virgin loading is half of a Hertz impact with k_n = k1 (LIGGGHTS' closed form). */
static void mepa_impact_time_closed_forms(void **state) {
    (void)state;
    const double m = 2e-3, v = 0.7, k1 = 3e5, k2 = 9e5;
    double d;
    const double t1 = jd_mepa_impact_time(m, k1, k2, 1.0, v, &d);
    assert_rel(t1, 0.5 * JD_PI * (sqrt(m / k1) + sqrt(m / k2)), 1e-12);
    assert_rel(d, v * sqrt(m / k1), 1e-12);
    const double t15 = jd_mepa_impact_time(m, k1, k2, 1.5, v, &d);
    assert_rel(d, jd_hertz_peak_overlap(m, k1, v), 1e-12);
    const double unload = 0.5 * JD_PI * sqrt(m / (1.5 * k2 * sqrt(d)));
    assert_rel(t15 - unload, 0.5 * jd_hertz_contact_time(m, k1, v), 1e-12);
}

/* With MEPA an adhesive contact resists sliding by mu |F_n| (Del Cid's fabs), and its tangential
 * spring takes the virgin secant k1 d^(n-1). */
static void mepa_friction_caps_at_the_normal_force_magnitude(void **state) {
    (void)state;
    double k1t[1] = {2e5}, k2t[1] = {4e5}, kat[1] = {1e5};
    const jd_mepa_inputs in = {.k1 = k1t, .k2 = k2t, .kadh = kat, .n = 1.0, .depth = 0.1};
    jd_pair_coeffs c = {.mu = 0.3, .mepa = jd_mepa_coeffs_of(&in, 0, 0)};
    const jd_contact_geom g = geom_z(1e-4, 0.01, 0.0, 1e-3);
    jd_normal nl;
    /* unloading below the k2 branch's zero: k2 (d - dp) = -10 N is beyond the adhesive bound
     * -kadh d = -5 N, so the contact is on the bound, and dp = ((k2 + kadh)/k2) d */
    jd_law_mepa(JD_F_MEPA, &c, &g, -1.0, 1.5e-4, 0.0, &nl);
    assert_rel(nl.fn, -5.0, 1e-12);
    assert_rel(nl.dp, 1.25e-4, 1e-12);
    assert_rel(nl.Kn, 1e5, 1e-12);
    assert_true(nl.fcap == 5.0 && nl.carries && !nl.ends);
    /* the tangential law caps at mu |F_n| */
    jd_contact_state st = {.dp = 1.5e-4};
    const jd_kinematics kin = {.vb = {2.0, 0, 1e-3}}; /* sliding along x, separating */
    jd_contact_result out;
    jd_contact(JD_F_MEPA | JD_F_FRICTION, &c, &g, &kin, 1e-3, &st, NULL, &out);
    assert_rel(out.f[0], -0.3 * 5.0, 1e-12);
    assert_rel(out.f[2], -5.0, 1e-12);
}

static void bond_frequency_bounds(void **state) {
    (void)state;
    jd_bond_params p = {0};
    p.lambda = 0.8;
    p.kn = 1e12;
    p.kt = 4e11;
    const double R = 1e-3, m = jd_sphere_mass(R, 2500.0), I = jd_sphere_inertia(m, R);
    const jd_bond_section sec = jd_bond_section_of(p.lambda, R, R);
    const double one = jd_bond_omega2_bound(&p, &sec, m, m, I, I, R, R);
    /* a rule bonds a particle to up to 12 equal neighbours at contact */
    assert_rel(jd_bond_omega2_rule(&p, R, m), 12.0 * one, 1e-15);
    assert_rel(JD_GUARD_DEFAULT_COORDINATION, 12.0, 0.0);
    /* two equal spheres touching: lever arms R, the same bound */
    assert_rel(jd_bond_omega2_pair(&p, R, R, m, m, 2.0 * R), one, 1e-15);
    assert_int_equal(jd_bond_laws(0.0), 0);
    assert_int_equal(jd_bond_laws(0.1), JD_B_DAMPING);
}

/* A bond of unit section along z (A = 1, I = 1/4, J = 1/2 as for rbar = 1, scaled by pi). */
static jd_bond_params bond_params(void) {
    jd_bond_params p = {0};
    p.kn = 2e9;
    p.kt = 1e9;
    p.sigma_c = 1e6;
    p.tau_c = 2e6;
    p.gamma = 0.1;
    p.lambda = 1.0;
    p.bending = JD_BOND_BEND_I;
    return p;
}

static void bond_springs_are_eq16(void **state) {
    (void)state;
    const jd_bond_params p = bond_params();
    jd_bond_geom g = {.n = {0, 0, 1}, .ra = {0, 0, 1e-3}, .rb = {0, 0, -1e-3}};
    g.sec = jd_bond_section_of(1.0, 1e-3, 1e-3);
    const jd_kinematics k = {.vb = {0.1, 0, -0.2}, .wb = {0, 0, 3.0}};
    jd_bond_motion m;
    jd_bond_kinematics(&g, &k, &m);
    assert_rel(m.vn, -0.2, 1e-15);
    assert_rel(m.wn, 3.0, 1e-15);
    assert_rel(m.vt[0], 0.1, 1e-15);
    const jd_bond_stiffness K = jd_bond_stiffness_of(&p, &g.sec);
    assert_rel(K.Kn, p.kn * g.sec.A, 1e-15);
    assert_rel(K.Kb, p.kn * g.sec.I, 1e-15); /* bending on I (Potyondy & Cundall) */
    assert_rel(K.Ktw, p.kt * g.sec.J, 1e-15);
    jd_bond_state s = {.flags = JD_BS_INTACT};
    const double dt = 1e-7;
    jd_bond_springs(&K, &g, &m, dt, &s);
    assert_rel(s.fn, K.Kn * 0.2 * dt, 1e-14);   /* approaching: compression grows */
    assert_rel(s.ft[0], -K.Kt * 0.1 * dt, 1e-14);
    assert_rel(s.mn, -K.Ktw * 3.0 * dt, 1e-14);
    /* the load on b: springs minus the dashpots 2 gamma sqrt(m K) */
    g.m_eff = 1e-5;
    g.i_eff = 1e-12;
    double f[3], mo[3];
    jd_bond_load(JD_B_DAMPING, &p, &K, &g, &m, &s, f, mo);
    assert_rel(f[2], s.fn - 2.0 * 0.1 * sqrt(1e-5 * K.Kn) * -0.2, 1e-14);
    assert_rel(f[0], s.ft[0] - 2.0 * 0.1 * sqrt(1e-5 * K.Kt) * 0.1, 1e-14);
    assert_rel(mo[2], s.mn - 2.0 * 0.1 * sqrt(1e-12 * K.Ktw) * 3.0, 1e-14);
}

static void bond_strength_and_break(void **state) {
    (void)state;
    const jd_bond_params p = bond_params();
    const jd_bond_section sec = jd_bond_section_of(1.0, 1e-3, 1e-3);
    jd_bond_state s = {.fn = -0.5 * p.sigma_c * sec.A, .mt = {0.25 * p.sigma_c * sec.I / sec.rbar, 0, 0},
                       .flags = JD_BS_INTACT, .u_prev = 3e-6, .e_damp = 1e-6, .f_prev = {0, 0, 2.0}};
    jd_bond_result out;
    /* eq. (17): sigma = -F_n/A + |M_t| rbar/I = 0.75 sigma_c: intact */
    assert_int_equal(jd_bond_strength(&p, &sec, &s, &out), JD_BOND_INTACT);
    assert_rel(out.sigma_max, 0.75 * p.sigma_c, 1e-12);
    s.fn *= 2.0; /* 1.25 sigma_c in tension, no shear: breaks in tension */
    assert_int_equal(jd_bond_strength(&p, &sec, &s, &out), JD_BOND_BROKE_TENSION);
    /* its last load still works half a step: f_prev.(v_b - v_a) = 1 W, and its torques
     * T_a = T_b = (0, -0.01, 0) N m (sum ts_prev, difference 0) on spins (0, 3, 0), (0, 5, 0)
     * rad/s: -0.08 W */
    s.ts_prev[1] = -0.02;
    const jd_kinematics k = {.vb = {0, 0, 0.5}, .wa = {0, 3, 0}, .wb = {0, 5, 0}};
    jd_bond_break(JD_B_ENERGY, &k, 1e-7, &s, &out);
    assert_rel(s.e_break, 3e-6 - 0.5 * (2.0 * 0.5 - 0.08) * 1e-7, 1e-14);
    assert_true(s.flags == (double)JD_BS_BROKEN && s.fn == 0.0 && s.mt[0] == 0.0 &&
                s.u_prev == 0.0 && s.e_damp == 1e-6 && out.f[2] == 0.0);
}

/* A bond's previous load works through the levers it was applied with, as a contact's
 * (energy_law_uses_the_previous_levers): f_prev = (1, 0, 0) N gave T_a = T_b = (0, -0.01, 0) N m;
 * the pair has since turned, so that the bond point's relative velocity (0, 0, 0.08) m/s is
 * normal to f_prev, but the work rate on spins (0, 3, 0), (0, 5, 0) rad/s is still -0.08 W.
 * Nothing is stored and this step's load is zero, so the dashpots book -1/2 (-0.08) dt; the
 * book keeps this step's torques as the next one's sum and difference. */
static void bond_energy_uses_the_previous_levers(void **state) {
    (void)state;
    const jd_bond_params p = bond_params();
    const jd_bond_section sec = jd_bond_section_of(1.0, 1e-3, 1e-3);
    const double dt = 1e-7, f[3] = {0, 0, 0}, mo[3] = {0, 0, 0};
    const jd_kinematics k = {.wa = {0, 3, 0}, .wb = {0, 5, 0}};
    const jd_bond_motion m = {.vrel = {0, 0, 0.08}, .wrel = {0, 2, 0}};
    const jd_bond_result out = {.ta = {1, 2, 3}, .tb = {5, 7, 11}};
    jd_bond_state s = {.flags = JD_BS_INTACT, .f_prev = {1, 0, 0}, .ts_prev = {0, -0.02, 0}};
    jd_bond_energy_book(JD_B_DAMPING | JD_B_ENERGY, &p, &sec, &k, &m, f, mo, &out, dt, &s);
    assert_rel(s.e_damp, -0.5 * -0.08 * dt, 1e-14);
    for (int d = 0; d < 3; d++) {
        assert_rel(s.ts_prev[d], out.ta[d] + out.tb[d], 0.0);
        assert_rel(s.td_prev[d], out.tb[d] - out.ta[d], 0.0);
    }
    /* a <-> b: the force and the difference flip, the spins swap: the same work */
    const jd_kinematics ks = {.wa = {0, 5, 0}, .wb = {0, 3, 0}};
    jd_bond_state t = {.flags = JD_BS_INTACT, .f_prev = {-1, 0, 0}, .ts_prev = {0, -0.02, 0}};
    jd_bond_energy_book(JD_B_DAMPING | JD_B_ENERGY, &p, &sec, &ks, &m, f, mo, &out, dt, &t);
    assert_rel(t.e_damp, -0.5 * -0.08 * dt, 1e-14);
}

static void guard_damping_ratio_over_species_with_particles(void **state) {
    (void)state;
    const jd_guard_species sp[2] = {{.count = 3}, {.count = 0}};
    const double e[4] = {0.9, 0.5, 0.1, 0.1}; /* (1, *) is not read: species 1 has no particles */
    assert_rel(jd_guard_damping_ratio(sp, 2, e, JD_DAMP_JIANG2021), jd_gamma_jiang2021(0.5), 0.0);
}

int run_laws_tests(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(kinematics_is_eq6),
        cmocka_unit_test(normal_law_with_damping_and_luding_end),
        cmocka_unit_test(contact_begin_restarts_an_ended_contact),
        cmocka_unit_test(tangential_law_sticks_then_slides),
        cmocka_unit_test(mindlin_tangential_stiffness_is_8_g_sqrt_r_delta),
        cmocka_unit_test(mindlin_over_hertz_tangent_is_2_1mnu_over_2mnu),
        cmocka_unit_test(rolling_law_spring_and_cap),
        cmocka_unit_test(energy_law_books_work_and_luding_end),
        cmocka_unit_test(energy_law_uses_the_previous_levers),
        cmocka_unit_test(bond_energy_uses_the_previous_levers),
        cmocka_unit_test(law_sets_are_the_combinations_with_mu_r_and_mindlin_only_with_friction),
        cmocka_unit_test(every_law_set_runs_in_one_compiled_loop),
        cmocka_unit_test(law_set_select_counts_only_interactions_that_occur),
        cmocka_unit_test(law_set_names),
        cmocka_unit_test(mepa_copper_ore_pair_has_del_cids_bounds),
        cmocka_unit_test(mepa_contact_dissipates_its_loop),
        cmocka_unit_test(mepa_impact_time_closed_forms),
        cmocka_unit_test(mepa_friction_caps_at_the_normal_force_magnitude),
        cmocka_unit_test(pair_coeffs_table_maps_each_restitution),
        cmocka_unit_test(records_keep_the_law_fields_or_everything),
        cmocka_unit_test(bond_frequency_bounds),
        cmocka_unit_test(bond_springs_are_eq16),
        cmocka_unit_test(bond_strength_and_break),
        cmocka_unit_test(guard_damping_ratio_over_species_with_particles),
    };
    return cmocka_run_group_tests_name("laws", tests, NULL, NULL);
}
