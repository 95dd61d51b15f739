/* test_watchdog.c — the watchdog's limits (kernel/jdem_watchdog.h), which both engines apply. */
#include "unit.h"

#include "jdem_watchdog.h"

static void overlap_against_the_smaller_radius(void **state) {
    (void)state;
    assert_int_equal(jd_overlap_excessive(0.0011, 0.01, 0.02, 0.1), 1); /* 11 % of 0.01 */
    assert_int_equal(jd_overlap_excessive(0.0009, 0.02, 0.01, 0.1), 0);
    assert_int_equal(jd_overlap_excessive(0.0011, 0.01, INFINITY, 0.1), 1); /* a wall */
    assert_int_equal(jd_overlap_excessive(1.0, 0.01, 0.01, INFINITY), 0);   /* watchdog off */
    assert_int_equal(jd_overlap_excessive(NAN, 0.01, 0.01, 0.1), 0); /* the non-finite check's */
}

static void energy_jump_relative_to_energy_in_play(void **state) {
    (void)state;
    /* free fall: kinetic energy from gravitational, total unchanged -> no jump */
    const jd_energy_terms a = {.kinetic = 1.0, .gravitational = -5.0};
    const jd_energy_terms b = {.kinetic = 2.0, .gravitational = -6.0};
    assert_rel(jd_energy_jump(&a, &b), 0.0, 0.0);
    /* 0.1 J from nowhere against 2.1 J in play (the larger sample's) */
    const jd_energy_terms c = {.kinetic = 2.1, .gravitational = -6.0};
    assert_rel(jd_energy_jump(&b, &c), 0.1 / 2.1, 1e-10); /* + the 1e-12 |grav| floor */
    /* dissipated energy stays in the balance and in the scale; wall work is subtracted */
    const jd_energy_terms d = {.kinetic = 1.0, .damping = 1.0, .gravitational = -6.0};
    assert_rel(jd_energy_jump(&b, &d), 0.0, 0.0);
    const jd_energy_terms e = {.kinetic = 3.0, .gravitational = -6.0, .wall_work = 1.0};
    assert_rel(jd_energy_jump(&b, &e), 0.0, 0.0);
    /* nothing in play: a far origin of height does not make round-off a jump */
    const jd_energy_terms rest = {.gravitational = 1e6};
    const jd_energy_terms rest2 = {.gravitational = 1e6 * (1.0 + 1e-16)};
    assert_true(jd_energy_jump(&rest, &rest2) < 1e-3);
    const jd_energy_terms bad = {.kinetic = NAN};
    assert_true(isnan(jd_energy_jump(&a, &bad)));
}

int run_watchdog_tests(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(overlap_against_the_smaller_radius),
        cmocka_unit_test(energy_jump_relative_to_energy_in_play),
    };
    return cmocka_run_group_tests_name("watchdog", tests, NULL, NULL);
}
