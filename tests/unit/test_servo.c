/* test_servo.c — the servo wall (kernel/jdem_servo.h) on a linear spring bed, and the boundary
 * stress tensor, against closed forms. */
#include "unit.h"

#include <string.h>

#include "jdem_servo.h"

/* A linear bed under the wall: stress k max(0, z0 - z) / A (the wall at height z, moving down
 * into the sample at the servo's speed). */
typedef struct bed {
    double k, area, z0, z, dt;
} bed;

static double bed_stress(const bed *b) {
    return b->z < b->z0 ? b->k * (b->z0 - b->z) / b->area : 0.0;
}

static const jd_servo_spec CH4 = {.target = 1000.0, .gain = 1e-4, .tolerance = 10.0,
                                  .max_speed = INFINITY, .hold_steps = 50};

/* Uncapped, starting at contact: e_n = target (1 - q)^n with q = alpha k dt / A, so the wall stops
 * at the first n with 1000 (1 - q)^n <= 10 and the test completes hold_steps - 1 steps later. */
static void converges_geometrically_then_holds(void **state) {
    (void)state;
    bed b = {.k = 2e5, .area = 0.04, .z0 = 0.2, .z = 0.2, .dt = 1e-4};
    const double q = CH4.gain * b.k * b.dt / b.area; /* 0.05 */
    const int64_t n_stop = (int64_t)ceil(log(10.0 / 1000.0) / log(1.0 - q)); /* 90 */
    jd_servo_state st = {0};
    int64_t first_zero = -1, done_at = -1;
    for (int64_t n = 0; n < 1000 && done_at < 0; n++) {
        const double sigma = bed_stress(&b);
        assert_rel(1000.0 - sigma, 1000.0 * pow(1.0 - q, (double)(first_zero < 0 ? n : first_zero)),
                   1e-9);
        const double v = jd_servo_speed(&CH4, &st, sigma);
        if (v == 0.0 && first_zero < 0)
            first_zero = n;
        if (st.done)
            done_at = n;
        b.z -= v * b.dt;
    }
    assert_int_equal(first_zero, n_stop);
    assert_int_equal(done_at, n_stop + CH4.hold_steps - 1);
    assert_true(fabs(bed_stress(&b) - 1000.0) <= 10.0);
    /* once done the wall holds whatever the stress does */
    assert_rel(jd_servo_speed(&CH4, &st, 0.0), 0.0, 0.0);
}

/* A jump beyond the tolerance during the hold restarts the count and moves the wall again. */
static void excursion_restarts_the_hold(void **state) {
    (void)state;
    jd_servo_state st = {0};
    for (int i = 0; i < 49; i++)
        assert_rel(jd_servo_speed(&CH4, &st, 1005.0), 0.0, 0.0);
    assert_int_equal(st.held, 49);
    assert_int_equal(st.done, 0);
    assert_rel(jd_servo_speed(&CH4, &st, 1020.0), 1e-4 * -20.0, 1e-15); /* retreats */
    assert_int_equal(st.held, 0);
    for (int i = 0; i < 50; i++)
        jd_servo_speed(&CH4, &st, 990.0); /* |e| = 10 = tolerance counts as within */
    assert_int_equal(st.done, 1);
}

/* Capped: far from the target the wall moves at v_max; the gain at its limit A/(k dt) reaches the
 * target in one step (q = 1). */
static void cap_and_gain_limit(void **state) {
    (void)state;
    jd_servo_spec s = CH4;
    s.max_speed = 0.02;
    jd_servo_state st = {0};
    assert_rel(jd_servo_speed(&s, &st, 0.0), 0.02, 0.0);     /* 1e-4 * 1000 = 0.1 > 0.02 */
    assert_rel(jd_servo_speed(&s, &st, 5000.0), -0.02, 0.0); /* too high: retreats */
    assert_rel(jd_servo_speed(&s, &st, 900.0), 0.01, 1e-12); /* 1e-4 * 100 */
    bed b = {.k = 2e5, .area = 0.04, .z0 = 0.2, .z = 0.2, .dt = 1e-4};
    s.max_speed = INFINITY;
    s.gain = jd_servo_gain_limit(b.k, b.area, b.dt);
    assert_rel(s.gain, 0.04 / (2e5 * 1e-4), 1e-15);
    jd_servo_state st2 = {0};
    b.z -= jd_servo_speed(&s, &st2, bed_stress(&b)) * b.dt;
    assert_rel(bed_stress(&b), 1000.0, 1e-12);
}

/* Stress of a wall: particles push the top wall (normal -z, into the sample) up with 40 N over
 * 0.04 m^2: 1000 Pa in compression. */
static void wall_stress_sign(void **state) {
    (void)state;
    const double f[3] = {0.0, 0.0, 40.0}, n[3] = {0.0, 0.0, -1.0};
    assert_rel(jd_servo_stress(f, n, 0.04), 1000.0, 1e-15);
}

/* A 0.2 m cube under a confined load: each of the six walls carries its stress times 0.04 m^2 at
 * its face centre; eq. (45) returns diag(sxx, syy, szz), whatever the centre, when forces balance. */
static void stress_tensor_of_a_loaded_cube(void **state) {
    (void)state;
    const double sxx = 400.0, syy = 300.0, szz = 1000.0, h = 0.1, a = 0.04;
    const double c[3] = {0.5, 0.5, 0.2};
    double x[18], f[18];
    const double s[3] = {sxx, syy, szz};
    for (int axis = 0; axis < 3; axis++)
        for (int side = 0; side < 2; side++) {
            const int w = 2 * axis + side;
            const double sign = side ? 1.0 : -1.0;
            for (int i = 0; i < 3; i++) {
                x[3 * w + i] = c[i] + (i == axis ? sign * h : 0.0);
                f[3 * w + i] = i == axis ? sign * s[axis] * a : 0.0; /* pushes the wall outward */
            }
        }
    double sigma[9];
    jd_stress_tensor(6, x, f, c, 0.008, sigma);
    const double want[9] = {sxx, 0, 0, 0, syy, 0, 0, 0, szz};
    for (int k = 0; k < 9; k++)
        assert_rel(sigma[k], want[k], 1e-12);
    const double origin[3] = {0.0, 0.0, 0.0};
    jd_stress_tensor(6, x, f, origin, 0.008, sigma);
    for (int k = 0; k < 9; k++)
        assert_true(fabs(sigma[k] - want[k]) <= 1e-9);
}

static void check_messages(void **state) {
    (void)state;
    char msg[256];
    jd_servo_spec s = CH4;
    assert_int_equal(jd_servo_check(&s, msg, sizeof msg), JD_SERVO_OK);
    s.target = -1000.0;
    assert_int_equal(jd_servo_check(&s, msg, sizeof msg), JD_SERVO_BAD_TARGET);
    assert_string_equal(msg, "servo target -1000 Pa has the wrong sign; valid: a compressive "
                             "stress > 0 (the wall pushes on the sample)");
    s = CH4;
    s.gain = 0.0;
    assert_int_equal(jd_servo_check(&s, msg, sizeof msg), JD_SERVO_BAD_GAIN);
    assert_string_equal(msg, "servo gain 0 is not valid; valid: a number > 0 [m/(s Pa)]");
    s = CH4;
    s.tolerance = -1.0;
    assert_int_equal(jd_servo_check(&s, msg, sizeof msg), JD_SERVO_BAD_TOLERANCE);
    assert_string_equal(msg, "servo tolerance -1 is not valid; valid: a number >= 0 [Pa]");
    s = CH4;
    s.hold_steps = 0;
    assert_int_equal(jd_servo_check(&s, msg, sizeof msg), JD_SERVO_BAD_HOLD);
    assert_string_equal(msg, "servo hold 0 steps is not valid; valid: at least 1 step");
    s = CH4;
    s.max_speed = 0.0;
    assert_int_equal(jd_servo_check(&s, msg, sizeof msg), JD_SERVO_BAD_MAX_SPEED);
    assert_string_equal(msg, "servo max_speed 0 is not valid; valid: a number > 0 [m/s], or .inf");
}

/* ceil(hold / dt), at least one step: 0.05 s at 1e-4 s is 500 steps, 0.6 s at 0.25 s is 3, a
 * hold shorter than a step is one step. */
static void hold_in_steps(void **state) {
    (void)state;
    assert_int_equal(jd_servo_hold_steps(0.05, 1e-4), 500);
    assert_int_equal(jd_servo_hold_steps(0.5, 0.25), 2);
    assert_int_equal(jd_servo_hold_steps(0.6, 0.25), 3);
    assert_int_equal(jd_servo_hold_steps(1e-9, 0.25), 1);
}

/* A 0.2 m cube's bottom, its x_lo side wall (0.3 m high) and its top at 0.28 m: the box runs
 * from the bottom to the top along z (not to the side wall's top), from x_lo to the extreme
 * corner along x (no wall faces -x), from corner to corner along y. */
static void box_of_the_walls(void **state) {
    (void)state;
    const double p[36] = {0.15, 0.4, 0.1, 0.35, 0.4, 0.1, 0.35, 0.6, 0.1, 0.15, 0.6, 0.1,
                          0.15, 0.4, 0.1, 0.15, 0.6, 0.1, 0.15, 0.6, 0.4, 0.15, 0.4, 0.4,
                          0.15, 0.4, 0.28, 0.15, 0.6, 0.28, 0.35, 0.6, 0.28, 0.35, 0.4, 0.28};
    const double n[9] = {0, 0, 1, 1, 0, 0, 0, 0, -1};
    double c[3], v;
    jd_servo_box(3, p, n, c, &v);
    assert_rel(c[0], 0.25, 1e-15);
    assert_rel(c[1], 0.5, 1e-15);
    assert_rel(c[2], 0.19, 1e-15);
    assert_rel(v, 0.2 * 0.2 * 0.18, 1e-14);
}

/* A 0.2 x 0.3 m rectangle tilted about x by 30 degrees, and a unit trapezoid of parallel sides
 * 1 and 2: the areas by hand. */
static void quad_areas(void **state) {
    (void)state;
    const double c = sqrt(3.0) / 2.0, s = 0.5; /* 30 degrees */
    const double rect[4][3] = {{0, 0, 0}, {0.2, 0, 0}, {0.2, 0.3 * c, 0.3 * s}, {0, 0.3 * c, 0.3 * s}};
    assert_rel(jd_servo_area(rect), 0.06, 1e-14);
    const double trap[4][3] = {{0, 0, 1}, {2, 0, 1}, {1.5, 1, 1}, {0.5, 1, 1}};
    assert_rel(jd_servo_area(trap), 1.5, 1e-15);
}

int run_servo_tests(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(converges_geometrically_then_holds),
        cmocka_unit_test(excursion_restarts_the_hold),
        cmocka_unit_test(cap_and_gain_limit),
        cmocka_unit_test(wall_stress_sign),
        cmocka_unit_test(stress_tensor_of_a_loaded_cube),
        cmocka_unit_test(check_messages),
        cmocka_unit_test(hold_in_steps),
        cmocka_unit_test(box_of_the_walls),
        cmocka_unit_test(quad_areas),
    };
    return cmocka_run_group_tests_name("servo", tests, NULL, NULL);
}
