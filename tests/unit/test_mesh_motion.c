/* test_mesh_motion.c — kernel/jdem_mesh_motion.h against closed forms: the rotation after N
 * incremental steps is the rotation by N omega dt (Rodrigues' formula), the corners keep their
 * distances to the axis, the velocities are omega x r and the translation's, and a conveyor's
 * velocity is tangential with the surface velocity's magnitude. */
#include <string.h>

#include "jdem_kernel.h"
#include "jdem_mesh_motion.h"
#include "unit.h"

/* p rotated by angle about the unit axis a through o (Rodrigues) */
static void rodrigues(const double o[3], const double a[3], double angle, const double p[3], double out[3]) {
    const double r[3] = {p[0] - o[0], p[1] - o[1], p[2] - o[2]};
    const double c = cos(angle), s = sin(angle), ad = a[0] * r[0] + a[1] * r[1] + a[2] * r[2];
    const double x[3] = {a[1] * r[2] - a[2] * r[1], a[2] * r[0] - a[0] * r[2], a[0] * r[1] - a[1] * r[0]};
    for (int k = 0; k < 3; k++) out[k] = o[k] + r[k] * c + x[k] * s + a[k] * ad * (1.0 - c);
}

/* 20000 incremental rotations of corners about 1 m from the axis: each step's product rounds
 * at about 4 ulp, so the corners stay within 20000 x 4 x 2.2e-16 m, 2e-11 m, of the exact
 * rotation */
#define TOL 2e-11
static void rotation_after_many_steps_is_the_closed_form(void **state) {
    (void)state;
    const double origin[3] = {0.3, -0.2, 0.1}, axis[3] = {1.0, 2.0, 2.0}, unit[3] = {1 / 3., 2 / 3., 2 / 3.};
    const double period = 0.7, dt = 1.0e-5;
    const int steps = 20000;
    jd_mesh_motion m;
    assert_int_equal(jd_mesh_motion_rotating(&m, origin, axis, period), 0);
    assert_rel(m.omega, 2.0 * JD_PI / period, 1e-15);
    double p[2][3] = {{1.0, 0.5, -0.25}, {0.3, -0.2, 0.6}};
    const double start[2][3] = {{1.0, 0.5, -0.25}, {0.3, -0.2, 0.6}};
    for (int n = 0; n < steps; n++) jd_mesh_motion_step(&m, dt, 2, p);
    for (int i = 0; i < 2; i++) {
        double want[3];
        rodrigues(origin, unit, m.omega * dt * steps, start[i], want);
        for (int k = 0; k < 3; k++)
            if (!(fabs(p[i][k] - want[k]) < TOL)) fail_msg("corner %d axis %d: %.17g, want %.17g", i, k, p[i][k], want[k]);
    }
}

static void rotation_velocity_is_omega_cross_r(void **state) {
    (void)state;
    const double origin[3] = {0.0, 0.0, 0.0}, axis[3] = {0.0, 0.0, -2.0};
    jd_mesh_motion m;
    assert_int_equal(jd_mesh_motion_rotating(&m, origin, axis, 2.0), 0);
    const double p[1][3] = {{0.5, 0.0, 0.3}};
    double v[1][3];
    jd_mesh_motion_velocity(&m, 1, p, v);
    /* omega = pi about -z: at (0.5, 0, z) the velocity is -pi 0.5 along y */
    assert_rel(v[0][0], 0.0, 1e-15);
    assert_rel(v[0][1], -JD_PI * 0.5, 1e-15);
    assert_rel(v[0][2], 0.0, 1e-15);
}

static void translation_moves_by_v_dt_with_velocity_v(void **state) {
    (void)state;
    const double vel[3] = {0.25, -0.5, 1.0};
    jd_mesh_motion m;
    jd_mesh_motion_translating(&m, vel);
    double p[1][3] = {{1.0, 2.0, 3.0}}, v[1][3];
    for (int n = 0; n < 1000; n++) jd_mesh_motion_step(&m, 1.0e-3, 1, p);
    jd_mesh_motion_velocity(&m, 1, (const double(*)[3])p, v);
    for (int k = 0; k < 3; k++) {
        assert_rel(p[0][k], (k + 1.0) + vel[k], 1e-12);
        assert_true(v[0][k] == vel[k]);
    }
}

static void still_mesh_neither_moves_nor_has_velocity(void **state) {
    (void)state;
    jd_mesh_motion m;
    jd_mesh_motion_still(&m);
    double p[1][3] = {{1.0, 2.0, 3.0}}, v[1][3] = {{9.0, 9.0, 9.0}};
    jd_mesh_motion_step(&m, 0.1, 1, p);
    jd_mesh_motion_velocity(&m, 1, (const double(*)[3])p, v);
    assert_true(p[0][0] == 1.0 && p[0][1] == 2.0 && p[0][2] == 3.0);
    assert_true(v[0][0] == 0.0 && v[0][1] == 0.0 && v[0][2] == 0.0);
}

static void bad_rotations_are_refused(void **state) {
    (void)state;
    jd_mesh_motion m;
    const double o[3] = {0, 0, 0}, zero[3] = {0, 0, 0}, z[3] = {0, 0, 1};
    assert_int_equal(jd_mesh_motion_rotating(&m, o, zero, 1.0), -1);
    assert_int_equal(jd_mesh_motion_rotating(&m, o, z, 0.0), -1);
    assert_int_equal(jd_mesh_motion_rotating(&m, o, z, INFINITY), -1);
    assert_int_equal(jd_mesh_motion_rotating(&m, o, z, -1.0), 0);
    assert_rel(m.omega, -2.0 * JD_PI, 1e-15);
}

static void conveyor_velocity_is_tangential_at_full_speed(void **state) {
    (void)state;
    /* a triangle in the plane x + z = 1 (normal (1, 0, 1)/sqrt 2) */
    const double t[3][3] = {{1.0, 0.0, 0.0}, {0.0, 1.0, 1.0}, {0.0, 0.0, 1.0}};
    const double u[3] = {2.0, 1.0, 0.0};
    double v[3][3];
    jd_mesh_conveyor_velocity(u, t, v);
    const double speed = sqrt(5.0), h = sqrt(0.5), n[3] = {h, 0.0, h};
    /* u minus its normal part (1, 0, 1): (1, 1, -1), rescaled to |u| */
    const double dir[3] = {1.0 / sqrt(3.0), 1.0 / sqrt(3.0), -1.0 / sqrt(3.0)};
    for (int c = 0; c < 3; c++) {
        assert_rel(v[c][0] * n[0] + v[c][1] * n[1] + v[c][2] * n[2], 0.0, 1e-15);
        for (int k = 0; k < 3; k++) assert_rel(v[c][k], speed * dir[k], 1e-15);
    }
    /* a surface velocity along the normal leaves the surface at rest (no rescaled remainder) */
    const double un[3] = {1.0, 0.0, 1.0};
    jd_mesh_conveyor_velocity(un, t, v);
    for (int c = 0; c < 3; c++)
        for (int k = 0; k < 3; k++) assert_true(v[c][k] == 0.0);
}

int run_mesh_motion_tests(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(rotation_after_many_steps_is_the_closed_form),
        cmocka_unit_test(rotation_velocity_is_omega_cross_r),
        cmocka_unit_test(translation_moves_by_v_dt_with_velocity_v),
        cmocka_unit_test(still_mesh_neither_moves_nor_has_velocity),
        cmocka_unit_test(bad_rotations_are_refused),
        cmocka_unit_test(conveyor_velocity_is_tangential_at_full_speed),
    };
    return cmocka_run_group_tests_name("mesh_motion", tests, NULL, NULL);
}
