/*
 * test_geometry.c — contact geometry against hand-computed configurations.
 */
#include "unit.h"

#include "jdem_geometry.h"

static void spheres_overlap_and_contact_point(void **state) {
    (void)state;
    const double xa[3] = {0, 0, 0}, xb[3] = {0.03, 0.04, 0}; /* distance 0.05 */
    jd_contact_geom g = {0};
    assert_int_equal(jd_geom_spheres(xa, 0.02, xb, 0.035, &g), 1);
    assert_rel(g.delta, 0.005, 1e-13);
    assert_rel(g.n[0], 0.6, 1e-15);
    assert_rel(g.n[1], 0.8, 1e-15);
    /* the contact point is R_a - delta/2 from a along n, and the same point seen from b */
    assert_rel(g.ra[0], 0.6 * 0.0175, 1e-13);
    assert_rel(g.rb[0] + xb[0], g.ra[0] + xa[0], 1e-13);
    assert_rel(g.r_roll, 0.02 * 0.035 / 0.055, 1e-14);
    /* touching exactly is not a contact (LIGGGHTS: rsq < radsum^2); binary-exact values */
    const double xc[3] = {0.75, 0, 0};
    assert_int_equal(jd_geom_spheres(xa, 0.25, xc, 0.5, &g), 0);
}

static void plane_active_side_and_finite_extent(void **state) {
    (void)state;
    const double c[4][3] = {{-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}};
    jd_plane w;
    assert_int_equal(jd_plane_init(&w, c, 1e-9), JD_GEOM_OK);
    assert_rel(w.n[2], 1.0, 1e-15);
    jd_contact_geom g = {0};
    const double above[3] = {0.5, 0.2, 0.009};
    assert_int_equal(jd_geom_plane(&w, above, 0.01, &g), 1);
    assert_rel(g.delta, 0.001, 1e-12);
    assert_rel(g.n[2], -1.0, 1e-15);
    assert_rel(g.ra[2], -0.009, 1e-14);
    const double below[3] = {0.5, 0.2, -0.009}; /* inactive side */
    assert_int_equal(jd_geom_plane(&w, below, 0.01, &g), 0);
    const double outside[3] = {1.5, 0.2, 0.009}; /* projection outside the quadrilateral */
    assert_int_equal(jd_geom_plane(&w, outside, 0.01, &g), 0);
}

static void plane_rejects_bad_corners(void **state) {
    (void)state;
    const double collinear[4][3] = {{0, 0, 0}, {1, 0, 0}, {2, 0, 0}, {3, 0, 0}};
    const double warped[4][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0.1}};
    jd_plane w;
    assert_int_equal(jd_plane_init(&w, collinear, 1e-9), JD_GEOM_DEGENERATE);
    assert_int_equal(jd_plane_init(&w, warped, 1e-9), JD_GEOM_NOT_PLANAR);
}

static void cylinder_outside_and_inside(void **state) {
    (void)state;
    jd_cylinder cyl = {.a0 = {0, 0, 0}, .a1 = {0, 0, 1}, .rc = 0.1, .inside = 0};
    jd_contact_geom g = {0};
    const double x[3] = {0.105, 0, 0.5};
    assert_int_equal(jd_geom_cylinder(&cyl, x, 0.01, &g), 1);
    assert_rel(g.delta, 0.005, 1e-12);
    assert_rel(g.n[0], -1.0, 1e-15);
    const double beyond[3] = {0.105, 0, 1.5}; /* past the end of the axis segment */
    assert_int_equal(jd_geom_cylinder(&cyl, beyond, 0.01, &g), 0);
    cyl.inside = 1;
    const double wall[3] = {0.095, 0, 0.5};
    assert_int_equal(jd_geom_cylinder(&cyl, wall, 0.01, &g), 1);
    assert_rel(g.delta, 0.005, 1e-12);
    assert_rel(g.n[0], 1.0, 1e-15);
    assert_rel(g.ra[0], 0.005, 1e-12);
}

int run_geometry_tests(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(spheres_overlap_and_contact_point),
        cmocka_unit_test(plane_active_side_and_finite_extent),
        cmocka_unit_test(plane_rejects_bad_corners),
        cmocka_unit_test(cylinder_outside_and_inside),
    };
    return cmocka_run_group_tests_name("geometry", tests, NULL, NULL);
}
