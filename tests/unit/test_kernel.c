/*
 * test_kernel.c — each contact law against a closed form or a published value.
 * References: Johnson's Hertz theory (E*, R*), the spec's tabulated gamma(e) and e_out(gamma)
 * (jiang_model.md §7.3 and §13.4 Test 3), anchors.md §1.3 (contact time constant 2.868),
 * jiang_model.md §10.2 (Rayleigh steps).
 */
#include "unit.h"

#include "jdem_kernel.h"

/* A sphere pair or sphere–wall contact along z with the given overlap; a at the origin. */
static jd_contact_geom geom_z(double delta, double Ra, double k_n, double m_eff) {
    jd_contact_geom g = {.n = {0, 0, 1}, .delta = delta, .k_n = k_n, .m_eff = m_eff,
                         .i_eff = 0.4 * m_eff * Ra * Ra, .r_roll = 0.5 * Ra};
    g.ra[2] = Ra - 0.5 * delta;
    g.rb[2] = -(Ra - 0.5 * delta);
    return g;
}

static void hertz_pair_identical_spheres_is_exact_hertz(void **state) {
    (void)state;
    const double E = 4.8e10, nu = 0.2, R = 0.01; /* Chung–Ooi test 1, glass */
    const double kp = jd_hertz_prefactor(E, nu, R);
    const double Estar = E / (2.0 * (1.0 - nu * nu)), Rstar = 0.5 * R;
    assert_rel(jd_kn_pair(kp, kp), 4.0 / 3.0 * Estar * sqrt(Rstar), 1e-14);
}

static void hertz_pair_equal_radii_mixed_materials_is_exact_hertz(void **state) {
    (void)state;
    const double R = 0.1, Ea = 7e10, nua = 0.33, Eb = 2.5e9, nub = 0.4;
    const double k = jd_kn_pair(jd_hertz_prefactor(Ea, nua, R), jd_hertz_prefactor(Eb, nub, R));
    const double Estar = 1.0 / ((1 - nua * nua) / Ea + (1 - nub * nub) / Eb);
    assert_rel(k, 4.0 / 3.0 * Estar * sqrt(0.5 * R), 1e-14);
}

static void wall_rules(void **state) {
    (void)state;
    const double E = 7e10, nu = 0.3, R = 0.1;
    const double exact = 4.0 / 3.0 * E / (1 - nu * nu) * sqrt(R);
    assert_rel(jd_kn_wall(JD_WALL_HERTZ, E, nu, R), exact, 1e-14);
    /* the seed's literal 2 K_p is 1/sqrt(2) of Hertz (jiang_model.md §3.3) */
    assert_rel(jd_kn_wall(JD_WALL_JIANG2021, E, nu, R), exact / sqrt(2.0), 1e-14);
    /* Chung–Ooi test 2, Al alloy: k = 3.2434e10 N/m^1.5 (jiang_model.md §13.4) */
    assert_rel(jd_kn_wall(JD_WALL_HERTZ, E, nu, R), 3.2434e10, 1e-4);
}

static void static_hertz_force_and_energy(void **state) {
    (void)state;
    const double k = 2.357e9, d = 1e-4, m = 5e-3;
    double K, C;
    const double f = jd_normal_force(k, d, 0.0, 1, 0.3, m, &K, &C);
    assert_rel(f, k * pow(d, 1.5), 1e-14);
    assert_rel(K, k * sqrt(d), 1e-14);
    /* elastic energy is the integral of the force: (2/5) k d^(5/2) */
    assert_rel(jd_normal_energy(k, d), 0.4 * k * pow(d, 2.5), 1e-14);
}

static void damping_coefficient(void **state) {
    (void)state;
    const double k = 1e9, d = 2e-5, m = 0.01, gamma = 0.215454, rate = 0.7;
    double K, C;
    const double f = jd_normal_force(k, d, rate, 1, gamma, m, &K, &C);
    assert_rel(C, 2.0 * gamma * sqrt(m * k * sqrt(d)), 1e-14); /* eq. (29) */
    assert_rel(f, k * pow(d, 1.5) + C * rate, 1e-14);           /* eq. (31) */
}

static void gamma_of_restitution_matches_spec_table(void **state) {
    (void)state;
    const double e[] = {1.0, 0.98, 0.9, 0.8, 0.5, 0.1};
    const double g[] = {0.0, 0.006431, 0.033518, 0.070850, 0.215454, 0.591155};
    /* the table has 6 decimals: agree to half a unit of the last one */
    for (int i = 0; i < 6; i++) assert_true(fabs(jd_gamma_jiang2021(e[i]) - g[i]) <= 5e-7);
}

static void restitution_of_jiang2021_damping_matches_spec_table(void **state) {
    (void)state;
    /* jiang_model.md §13.4 Test 3, "end when F_n = 0" row (3 digits) */
    const double ein[] = {0.9, 0.8, 0.7, 0.6, 0.5, 0.4, 0.3, 0.2, 0.1, 0.05};
    const double eout[] = {0.912, 0.826, 0.742, 0.661, 0.582, 0.506, 0.431, 0.358, 0.283, 0.241};
    /* the table has 3 decimals: agree to half a unit of the last one */
    for (int i = 0; i < 10; i++)
        assert_true(fabs(jd_restitution_for_gamma(jd_gamma_jiang2021(ein[i])) - eout[i]) <= 5e-4);
}

static void exact_restitution_mapping_round_trips(void **state) {
    (void)state;
    for (double e = 0.1; e < 1.0; e += 0.1)
        assert_rel(jd_restitution_for_gamma(jd_gamma_exact(e)), e, 1e-9);
    assert_true(jd_gamma_exact(1.0) == 0.0);
}

static void hertz_impact_closed_forms(void **state) {
    (void)state;
    /* anchors.md §1.3: t_c = 2.868 (m*^2/(R* E*^2 v))^(1/5); test 1 glass values */
    const double E = 4.8e10, nu = 0.2, R = 0.01, rho = 2800, v = 20.0;
    const double m = jd_sphere_mass(R, rho), ms = 0.5 * m;
    const double Es = E / (2 * (1 - nu * nu)), Rs = 0.5 * R, k = 4.0 / 3.0 * Es * sqrt(Rs);
    assert_rel(jd_hertz_contact_time(ms, k, v), 2.868 * pow(ms * ms / (Rs * Es * Es * v), 0.2), 1e-3);
    assert_rel(jd_hertz_contact_time(ms, k, v), 4.034e-5, 1e-3);
    assert_rel(jd_hertz_peak_overlap(ms, k, v), 2.741e-4, 1e-3);
    assert_rel(jd_hertz_peak_force(ms, k, v), 1.0697e4, 1e-3);
}

static void rayleigh_step_matches_spec_table(void **state) {
    (void)state;
    /* jiang_model.md §10.2: glass 1.293e-5 s, Al oxide (T3) 1.383e-6 s */
    assert_rel(jd_rayleigh_step(0.010, 2800, 4.8e10, 0.20), 1.293e-5, 1e-3);
    assert_rel(jd_rayleigh_step(0.0025, 4000, 3.8e11, 0.23), 1.383e-6, 1e-3);
}

static void rotation_into_plane_preserves_length(void **state) {
    (void)state;
    double xi[3] = {3e-6, -1e-6, 2e-6};
    const double len = sqrt(jd_dot(xi, xi));
    const double n[3] = {0.6, 0.0, 0.8};
    jd_rotate_into_plane(xi, n);
    assert_rel(sqrt(jd_dot(xi, xi)), len, 1e-14);
    assert_true(fabs(jd_dot(xi, n)) < 1e-15 * len);
}

/* Tangential slip so large that the Coulomb cap acts: |F_t| = mu F_n, opposite to the slip, and
 * with the coulomb limit K_t |xi| = mu F_n. */
static void coulomb_cap(void **state) {
    (void)state;
    const double R = 0.01, k = 2e9, d = 1e-5, m = 0.01;
    jd_contact_geom g = geom_z(d, R, k, m);
    jd_pair_coeffs c = {.gamma = 0.0, .mu = 0.3, .mu_r = 1.0, .xi_limit = JD_XI_COULOMB};
    jd_kinematics kin = {.vb = {1.0, 0.0, 0.0}};
    jd_contact_state s = {0};
    jd_contact_result out;
    for (int i = 0; i < 3; i++)
        jd_contact(JD_F_FRICTION | JD_F_ENERGY, &c, &g, &kin, 1e-4, &s, NULL, &out);
    const double fn = k * pow(d, 1.5);
    assert_rel(out.fn, fn, 1e-14);
    assert_rel(out.f[0], -0.3 * fn, 1e-14);
    assert_rel(k * sqrt(d) * fabs(s.xi[0]), 0.3 * fn, 1e-14);
    assert_true(s.flags == (double)JD_S_SLIDING);
    /* while sliding the slider dissipates mu F_n |v_t| dt per step (after the first step, which
     * also loads the spring) */
    const double before = s.e_fric;
    jd_contact(JD_F_FRICTION | JD_F_ENERGY, &c, &g, &kin, 1e-4, &s, NULL, &out);
    assert_rel(s.e_fric - before, 0.3 * fn * 1.0 * 1e-4, 1e-12);
}

/* Below the cap the spring holds: F_t = -K_t xi with xi = v_t t. */
static void tangential_stick(void **state) {
    (void)state;
    const double R = 0.01, k = 2e9, d = 1e-5, m = 0.01, dt = 1e-7;
    jd_contact_geom g = geom_z(d, R, k, m);
    jd_pair_coeffs c = {.gamma = 0.0, .mu = 0.5, .mu_r = 1.0, .xi_limit = JD_XI_COULOMB};
    jd_kinematics kin = {.vb = {0.0, 1e-3, 0.0}};
    jd_contact_state s = {0};
    jd_contact_result out;
    for (int i = 0; i < 10; i++) jd_contact(JD_F_FRICTION, &c, &g, &kin, dt, &s, NULL, &out);
    assert_rel(out.f[1], -k * sqrt(d) * 10 * 1e-3 * dt, 1e-12);
    assert_true(s.flags != (double)JD_S_SLIDING);
}

static void rolling_cap(void **state) {
    (void)state;
    const double R = 0.01, k = 2e9, d = 1e-5, m = 0.01;
    jd_contact_geom g = geom_z(d, R, k, m);
    jd_pair_coeffs c = {.gamma = 0.0, .mu = 0.0, .eta = 0.1, .mu_r = 1.0, .xi_limit = JD_XI_COULOMB};
    jd_kinematics kin = {.wb = {0.0, 50.0, 0.0}};
    jd_contact_state s = {0};
    jd_rolling_state r = {{0}, {0}};
    jd_contact_result out;
    for (int i = 0; i < 5; i++) jd_contact(JD_F_ROLLING, &c, &g, &kin, 1e-3, &s, &r, &out);
    const double cap = 0.1 * g.r_roll * k * pow(d, 1.5);
    /* the moment on b opposes its relative spin and is capped at eta r F_n */
    assert_rel(out.tb[1], -cap, 1e-12);
    assert_rel(out.ta[1], cap, 1e-12);
}

/* Newton's third law for moments: with lever arms from the same contact point the torques on a
 * and b and the moment of the force pair about a sum to zero (angular momentum conservation). */
static void angular_momentum_balance(void **state) {
    (void)state;
    const double Ra = 0.01, d = 2e-5;
    jd_contact_geom g = geom_z(d, Ra, 1e9, 0.01);
    jd_pair_coeffs c = {.gamma = 0.1, .mu = 0.4, .eta = 0.05, .mu_r = 1.0, .xi_limit = JD_XI_COULOMB};
    jd_kinematics kin = {.va = {0.1, 0.2, 0.5}, .wa = {3, -1, 2}, .vb = {-0.3, 0.1, -0.5}, .wb = {-2, 4, 1}};
    jd_contact_state s = {0};
    jd_rolling_state r = {{0}, {0}};
    jd_contact_result out;
    jd_contact(JD_F_DAMPING | JD_F_FRICTION | JD_F_ROLLING, &c, &g, &kin, 1e-6, &s, &r, &out);
    double xab[3], lever[3];
    for (int i = 0; i < 3; i++) xab[i] = g.ra[i] - g.rb[i]; /* x_b - x_a */
    jd_cross(xab, out.f, lever);
    for (int i = 0; i < 3; i++) {
        const double sum = out.ta[i] + out.tb[i] + lever[i];
        assert_true(fabs(sum) <= 1e-12 * (fabs(out.ta[i]) + fabs(out.tb[i]) + fabs(lever[i]) + 1e-30));
    }
}

/* Luding's end of collision: an over-damped unloading contact never pulls; it ends, drops its
 * history, and books as dissipated the energy it had stored, less the work its last force still
 * does over the ending step (trapezoidal rule); it stays ended while the bodies separate. */
static void luding_end_of_collision(void **state) {
    (void)state;
    const double R = 0.01, k = 2e9, d = 1e-6, m = 0.01, dt = 1e-7;
    jd_contact_geom g = geom_z(d, R, k, m);
    jd_pair_coeffs c = {.gamma = 2.0, .mu = 0.3, .mu_r = 1.0, .xi_limit = JD_XI_COULOMB};
    jd_contact_state s = {0};
    jd_contact_result out;
    const unsigned F = JD_F_DAMPING | JD_F_FRICTION | JD_F_ENERGY;
    jd_kinematics slow = {.vb = {0.0, 0.0, -1e-6}}; /* loading slowly: stores energy */
    assert_int_equal(jd_contact(F, &c, &g, &slow, dt, &s, NULL, &out), 1);
    const double f1 = out.fn, stored = s.u_prev;
    assert_rel(stored, jd_normal_energy(k, d), 1e-14);
    const double damp_before = s.e_damp;
    jd_kinematics fast = {.vb = {0.01, 0.0, 1.0}}; /* b moves away fast: over-damped unloading */
    assert_int_equal(jd_contact(F, &c, &g, &fast, dt, &s, NULL, &out), 0);
    assert_true(out.fn == 0.0 && out.f[0] == 0.0 && out.f[2] == 0.0);
    assert_true(s.xi[0] == 0.0 && s.u_prev == 0.0 && s.flags == (double)JD_S_ENDED);
    assert_rel(s.e_damp - damp_before, stored - 0.5 * f1 * 1.0 * dt, 1e-12);
    assert_int_equal(jd_contact(F, &c, &g, &fast, dt, &s, NULL, &out), 0);
    /* approaching again while still overlapping starts a new contact, whose already compressed
     * spring is stored energy again (taken back from damping), never negative friction */
    fast.vb[2] = -1.0;
    fast.vb[0] = 0.0;
    const double damp_ended = s.e_damp, fric_ended = s.e_fric;
    assert_int_equal(jd_contact(F, &c, &g, &fast, dt, &s, NULL, &out), 1);
    assert_true(out.fn > 0.0);
    /* (the restart step itself may book at most the work of one step, F_n |v_n| dt) */
    assert_true(fabs(s.e_fric - fric_ended) <= out.fn * 1.0 * dt);
    /* its stored energy comes back out of damping, plus at most one step of dashpot work */
    const double restored = damp_ended - jd_normal_energy(k, d);
    const double dashpot_step = 2.0 * c.gamma * sqrt(m * k * sqrt(d)) * 1.0 * 1.0 * dt;
    assert_true(s.e_damp >= restored && s.e_damp <= restored + dashpot_step);
}


/* What separation keeps: the stepper resets entries that stopped overlapping in place, every
 * field zero but e_damp and e_fric (stepper/forces.c, hist_separate), relying on exactly this. */
static void separate_keeps_only_the_dissipation_accumulators(void **state) {
    (void)state;
    jd_contact_state s;
    jd_rolling_state r;
    double *a = (double *)&s, *b = (double *)&r;
    for (int k = 0; k < JD_CONTACT_STATE_LEN; k++) a[k] = k + 1.0;
    for (int k = 0; k < JD_ROLLING_STATE_LEN; k++) b[k] = k + 1.0;
    jd_contact_separate(&s, &r);
    for (int k = 0; k < JD_CONTACT_STATE_LEN; k++) {
        const int kept = a + k == &s.e_damp || a + k == &s.e_fric;
        assert_true(a[k] == (kept ? k + 1.0 : 0.0));
    }
    for (int k = 0; k < JD_ROLLING_STATE_LEN; k++) assert_true(b[k] == 0.0);
}

int run_kernel_tests(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(hertz_pair_identical_spheres_is_exact_hertz),
        cmocka_unit_test(hertz_pair_equal_radii_mixed_materials_is_exact_hertz),
        cmocka_unit_test(wall_rules),
        cmocka_unit_test(static_hertz_force_and_energy),
        cmocka_unit_test(damping_coefficient),
        cmocka_unit_test(gamma_of_restitution_matches_spec_table),
        cmocka_unit_test(restitution_of_jiang2021_damping_matches_spec_table),
        cmocka_unit_test(exact_restitution_mapping_round_trips),
        cmocka_unit_test(hertz_impact_closed_forms),
        cmocka_unit_test(rayleigh_step_matches_spec_table),
        cmocka_unit_test(rotation_into_plane_preserves_length),
        cmocka_unit_test(coulomb_cap),
        cmocka_unit_test(tangential_stick),
        cmocka_unit_test(rolling_cap),
        cmocka_unit_test(angular_momentum_balance),
        cmocka_unit_test(luding_end_of_collision),
        cmocka_unit_test(separate_keeps_only_the_dissipation_accumulators),
    };
    return cmocka_run_group_tests_name("kernel", tests, NULL, NULL);
}
