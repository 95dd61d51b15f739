/* test_guard.c — the time-step guard (kernel/jdem_guard.h) against published values: the
 * Rayleigh steps of jiang_model.md §10.2, the Hertz contact time of Chung & Ooi test 1
 * (anchors.md §1.3), and the damped central-difference limit. */
#include <string.h>

#include "unit.h"

#include "jdem_guard.h"
#include "jdem_kernel.h"

/* Chung & Ooi test 1: two glass spheres R = 10 mm at 20 m/s relative speed. */
static jd_guard_input glass_pair(jd_guard_species *sp, double dt) {
    *sp = (jd_guard_species){.count = 2, .rmin = 0.01, .density = 2800, .E = 4.8e10, .nu = 0.2};
    return (jd_guard_input){.species = sp, .n_species = 1, .max_impact_speed = 20.0,
                            .coordination = JD_GUARD_DEFAULT_COORDINATION, .dt = dt};
}

static void bounds_match_published_values(void **state) {
    (void)state;
    jd_guard_species sp;
    const jd_guard_input in = glass_pair(&sp, 1e-7);
    jd_guard_result r;
    jd_guard_assess(&in, &r);
    assert_rel(r.rayleigh_bound, 2.59e-6, 2e-3);        /* §10.2: 0.2 x 1.293e-5 s */
    assert_rel(r.contact_time, 4.034e-5, 1e-3);         /* Chung & Ooi test 1 */
    assert_rel(r.contact_bound, 4.034e-5 / 50, 1e-3);
    assert_int_equal(r.binding, JD_GUARD_CONTACT_TIME);
    assert_rel(r.safe_dt, r.contact_bound, 0.0);
    assert_int_equal(r.violated, JD_GUARD_SAFE);
}

static void the_tightest_broken_bound_is_named(void **state) {
    (void)state;
    jd_guard_species sp;
    jd_guard_input in = glass_pair(&sp, 3e-6); /* above all three bounds */
    jd_guard_result r;
    jd_guard_assess(&in, &r);
    assert_int_equal(r.violated, JD_GUARD_CONTACT_TIME);
    char msg[512];
    jd_guard_refusal(&in, &r, "Use --force to run anyway.", msg, sizeof msg);
    assert_string_equal(msg, "time step 3e-06 s is unsafe: it exceeds 1/50 of the shortest Hertz "
                        "contact time (8.06789e-07 s); largest safe dt = 8.06789e-07 s. Use --force "
                        "to run anyway.");
    /* nothing moves: only the Rayleigh bound remains */
    in.max_impact_speed = 0.0;
    jd_guard_assess(&in, &r);
    assert_true(isinf(r.contact_bound) && isinf(r.coordination_bound));
    assert_int_equal(r.violated, JD_GUARD_RAYLEIGH);
    jd_guard_warning(&in, &r, "--force", msg, sizeof msg);
    assert_non_null(strstr(msg, "exceeds 20 % of the Rayleigh time step"));
}

static void coordination_and_damping_scale_the_verlet_limit(void **state) {
    (void)state;
    jd_guard_species sp;
    jd_guard_input in = glass_pair(&sp, 1e-9);
    jd_guard_result one, four, damped;
    in.coordination = 1.0;
    jd_guard_assess(&in, &one);
    in.coordination = 4.0;
    jd_guard_assess(&in, &four);
    assert_rel(four.coordination_bound, one.coordination_bound / 2.0, 1e-12); /* omega ~ sqrt(C) */
    in.damping_ratio = 0.75; /* (2/omega)(sqrt(1 + 0.5625) - 0.75) = (2/omega) 0.5 */
    jd_guard_assess(&in, &damped);
    assert_rel(damped.coordination_bound, four.coordination_bound * 0.5, 1e-12);
}

/* With Mindlin's K_t = rho K, rho = 3(1-nu)/(2-nu) for like materials (the secant Hertz K against
 * 8 G* sqrt(R* delta), G* = G/(2(2-nu)), R* = R/2), the sliding-rolling term of the row sum,
 * K_t (1/m + R^2/I) = 3.5 K_t/m per side, grows by rho and the rolling spring K r^2/I does not:
 * two like spheres, m omega^2 = 7 rho K + 2 K (R/2)^2/(0.4 R^2) = (7 rho + 1.25) K instead of
 * 8.25 K; a sphere on a rigid wall (G* of the sphere alone, R* = R, the same rho against the
 * exact rigid-plane Hertz), (3.5 rho + 2.5) K instead of 6 K. */
static void mindlin_stiffer_spring_tightens_the_verlet_limit(void **state) {
    (void)state;
    jd_guard_species sp;
    jd_guard_input in = glass_pair(&sp, 1e-9);
    jd_guard_result seed, mindlin;
    jd_guard_assess(&in, &seed);
    in.tangential_rule = JD_KT_MINDLIN;
    jd_guard_assess(&in, &mindlin);
    const double nu = 0.2, rho = 3.0 * (1.0 - nu) / (2.0 - nu);
    assert_rel(mindlin.coordination_bound, seed.coordination_bound * sqrt(8.25 / (7.0 * rho + 1.25)),
               1e-12);
    assert_rel(mindlin.contact_bound, seed.contact_bound, 0.0); /* the normal law is unchanged */
    sp.count = 1; /* alone, on a wall */
    in.has_walls = 1;
    in.tangential_rule = JD_KT_JIANG2021;
    jd_guard_assess(&in, &seed);
    in.tangential_rule = JD_KT_MINDLIN;
    jd_guard_assess(&in, &mindlin);
    assert_rel(mindlin.coordination_bound, seed.coordination_bound * sqrt(6.0 / (3.5 * rho + 2.5)),
               1e-12);
}

/* Two glass spheres (as above) joined by a bond whose fastest mode is 1 MHz: the bond bound is
 * 1/20 of its period, 5e-8 s, tighter than the contact bound (8.07e-7 s), and it is named. */
static void a_stiff_bond_binds(void **state) {
    (void)state;
    jd_guard_species sp;
    jd_guard_input in = glass_pair(&sp, 1e-7);
    const double omega = 2.0 * JD_PI * 1e6;
    in.bond_omega2 = omega * omega;
    jd_guard_result r;
    jd_guard_assess(&in, &r);
    assert_rel(r.bond_bound, 1e-6 / 20.0, 1e-14);
    assert_int_equal(r.binding, JD_GUARD_BOND);
    assert_int_equal(r.violated, JD_GUARD_BOND);
    char msg[512];
    jd_guard_refusal(&in, &r, "Use --force to run anyway.", msg, sizeof msg);
    assert_string_equal(msg, "time step 1e-07 s is unsafe: it exceeds 1/20 of the fastest bond "
                             "period (5e-08 s); largest safe dt = 5e-08 s. Use --force to run anyway.");
}

/* Two copper-ore spheres with MEPA (Del Cid's Table 5.1 per-type values): the contact-time bound
 * is 1/50 of jd_mepa_impact_time of the series pair, named as MEPA's, and the Verlet bound is
 * 2/omega with omega^2 = C x 2 [max(n k2 d^(n-1)/m, 3.5 K_t/m) + K_r/I] at the impact's peak d
 * (equal spheres: the block Gershgorin row of jdem_guard.c, exact in form), with the tangential
 * spring k1 d^(n-1), or Mindlin's 8 G* sqrt(R* d) when the scene asks for it. */
static void mepa_pair_bounds(void **state) {
    (void)state;
    const double R = 3.175e-3, rho = 2481.3, E = 1.19e11, nu = 0.34, v = 2.0, n = 1.5;
    const jd_guard_species sp = {.count = 2, .rmin = R, .density = rho, .E = E, .nu = nu,
                                 .mepa_k1 = 4.75e8, .mepa_k2 = 2.37e9};
    jd_guard_input in = {.species = &sp, .n_species = 1, .max_impact_speed = v,
                         .coordination = JD_GUARD_DEFAULT_COORDINATION, .normal_law = JD_NORMAL_MEPA,
                         .mepa_n = n, .dt = 1e-9};
    const double m = jd_sphere_mass(R, rho), I = jd_sphere_inertia(m, R), r = 0.5 * R;
    const double k1 = 0.5 * 4.75e8, k2 = 0.5 * 2.37e9; /* like types in series */
    double d;
    const double tc = jd_mepa_impact_time(0.5 * m, k1, k2, n, v, &d);
    const double K = k1 * sqrt(d), Kn = n * k2 * sqrt(d), G = 1.0 / (2.0 * jd_shear_compliance(E, nu));
    for (int rule = JD_KT_JIANG2021; rule <= JD_KT_MINDLIN; rule++) {
        in.tangential_rule = rule;
        jd_guard_result res;
        jd_guard_assess(&in, &res);
        assert_rel(res.contact_bound, tc / JD_GUARD_STEPS_PER_CONTACT, 1e-14);
        const double Kt = rule == JD_KT_MINDLIN ? 8.0 * G * sqrt(r * d) : K;
        const double row = 2.0 * (fmax(Kn / m, 3.5 * Kt / m) + K * r * r / I);
        assert_rel(res.coordination_bound, 2.0 / sqrt(JD_GUARD_DEFAULT_COORDINATION * row), 1e-12);
    }
    /* the contact time's bound, when broken, is named as MEPA's */
    jd_guard_result res;
    jd_guard_assess(&in, &res);
    char msg[512];
    jd_guard_warning(&in, &(jd_guard_result){.violated = JD_GUARD_CONTACT_TIME,
                                              .violated_value = res.contact_bound},
                     "--force", msg, sizeof msg);
    assert_non_null(strstr(msg, "exceeds 1/50 of the shortest MEPA contact time"));
}

int run_guard_tests(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(bounds_match_published_values),
        cmocka_unit_test(the_tightest_broken_bound_is_named),
        cmocka_unit_test(coordination_and_damping_scale_the_verlet_limit),
        cmocka_unit_test(mindlin_stiffer_spring_tightens_the_verlet_limit),
        cmocka_unit_test(a_stiff_bond_binds),
        cmocka_unit_test(mepa_pair_bounds),
    };
    return cmocka_run_group_tests_name("guard", tests, NULL, NULL);
}
