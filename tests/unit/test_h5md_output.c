/*
 * test_h5md_output.c — what io/h5md.c writes for the sidecar and for a changing particle set,
 * against values worked out by hand: a growing set (H5MD 1.1's time-dependent id, -1 and NaN
 * in empty rows, a row keeps its particle), the bonds intact at each frame (/jdem/bond_lines),
 * and the walls' mesh and motion (/jdem/walls).
 */
#include "unit.h"

#include <hdf5.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "h5md.h"

static void read_all(hid_t f, const char *name, hid_t mtype, void *buf) {
    hid_t d = H5Dopen2(f, name, H5P_DEFAULT);
    assert_true(d >= 0);
    assert_true(H5Dread(d, mtype, H5S_ALL, H5S_ALL, H5P_DEFAULT, buf) >= 0);
    H5Dclose(d);
}

static void out_path(char *dir, char *path, size_t len, const char *name) {
    assert_non_null(mkdtemp(dir));
    snprintf(path, len, "%s/%s", dir, name);
}

static void write_frame(jd_h5md *h, int64_t step, const double *x, const jd_h5md_particles *rows) {
    char err[256] = "";
    const jd_h5md_frame fr = {.step = step, .time = (double)step, .position = x, .rows = rows};
    if (jd_h5md_write_frame(h, &fr, err, sizeof err) != 0) fail_msg("frame %lld: %s", (long long)step, err);
}

/* Rows 0 frames: none; then ids {5, 7}; then {5, -1, 9}: 7 left, 9 arrived. */
static void growing_set(void **state) {
    (void)state;
    char dir[] = "/tmp/jdem_grow_XXXXXX", path[128], err[256] = "";
    out_path(dir, path, sizeof path, "g.h5");
    const jd_h5md_particles none = {.n = 0, .growing = 1};
    const jd_h5md_meta meta = {.creator = "test", .dt = 1.0};
    jd_h5md *h = jd_h5md_create(path, &meta, &none, err, sizeof err);
    if (!h) fail_msg("create: %s", err);
    const double x0[3] = {0}, x1[6] = {1, 1, 1, 2, 2, 2}, x2[9] = {3, 3, 3, 8, 8, 8, 4, 4, 4};
    const int64_t id1[2] = {5, 7}, id2[3] = {5, -1, 9}, bad[3] = {6, -1, 9};
    const int32_t sp[3] = {0, 1, 2};
    const double r[3] = {0.1, 0.2, 0.3}, m[3] = {1, 2, 3};
    const jd_h5md_particles f0 = {.n = 0}, f1 = {2, id1, sp, r, m, 0}, f2 = {3, id2, sp, r, m, 0};
    write_frame(h, 0, x0, &f0);
    write_frame(h, 10, x1, &f1);
    write_frame(h, 20, x2, &f2);
    const jd_h5md_particles moved = {3, bad, sp, r, m, 0};
    const jd_h5md_frame fr = {.step = 30, .time = 30, .position = x2, .rows = &moved};
    assert_int_equal(jd_h5md_write_frame(h, &fr, err, sizeof err), -1);
    assert_non_null(strstr(err, "a row keeps its particle"));
    jd_h5md_close(h, 0, err, sizeof err);
    char part[160];
    snprintf(part, sizeof part, "%s.part", path);
    hid_t f = H5Fopen(part, H5F_ACC_RDONLY, H5P_DEFAULT);
    assert_true(f >= 0);
    int64_t ids[9];
    double pos[27], rad[3];
    read_all(f, "/particles/all/id/value", H5T_NATIVE_INT64, ids);
    read_all(f, "/particles/all/position/value", H5T_NATIVE_DOUBLE, pos);
    read_all(f, "/particles/all/radius", H5T_NATIVE_DOUBLE, rad);
    const int64_t want[9] = {-1, -1, -1, 5, 7, -1, 5, -1, 9};
    for (int i = 0; i < 9; i++) assert_int_equal(ids[i], want[i]);
    for (int i = 0; i < 9; i++) assert_true(isnan(pos[i]));             /* frame 0: no rows yet */
    for (int i = 0; i < 6; i++) assert_true(pos[9 + i] == x1[i]);
    assert_true(isnan(pos[9 + 6]));                                      /* row 2 before 9 came */
    assert_true(pos[18] == 3 && isnan(pos[21]) && pos[24] == 4);         /* row 1 empty: NaN */
    for (int i = 0; i < 3; i++) assert_true(rad[i] == r[i]);
    H5Fclose(f);
    unlink(part);
    rmdir(dir);
}

/* Bonds 1-2 and 2-3 from step 0, 1-3 from step 50, 2-3 broken at 70; frames at 0, 40, 60, 80:
 * 2, 2, 3, 2 intact, rows (0,1) (1,2) | same block | (0,1) (1,2) (0,2) | (0,1) (0,2). */
static void bond_lines(void **state) {
    (void)state;
    char dir[] = "/tmp/jdem_lines_XXXXXX", path[128], err[256] = "";
    out_path(dir, path, sizeof path, "b.h5");
    const int64_t id[3] = {1, 2, 3};
    const int32_t sp[3] = {0, 0, 0};
    const double r[3] = {1, 1, 1}, m[3] = {1, 1, 1}, x[9] = {0};
    const jd_h5md_particles p = {3, id, sp, r, m, 0};
    const jd_h5md_meta meta = {.creator = "test", .dt = 1.0};
    jd_h5md *h = jd_h5md_create(path, &meta, &p, err, sizeof err);
    if (!h) fail_msg("create: %s", err);
    const jd_h5md_bond b[3] = {{{1, 2}, 0, 0}, {{2, 3}, 0, 0}, {{1, 3}, 0, 50}};
    const jd_h5md_bond_break e = {.step = 70, .id = {2, 3}, .mode = 1};
    assert_int_equal(jd_h5md_write_bonds(h, 2, b, err, sizeof err), 0);
    for (int64_t s = 0; s <= 80; s += 20) {
        if (s == 20) continue;
        if (s == 60) assert_int_equal(jd_h5md_write_bonds(h, 1, b + 2, err, sizeof err), 0);
        if (s == 80) assert_int_equal(jd_h5md_write_bond_breaks(h, 1, &e, err, sizeof err), 0);
        write_frame(h, s, x, NULL);
    }
    if (jd_h5md_close(h, 1, err, sizeof err) != 0) fail_msg("close: %s", err);
    hid_t f = H5Fopen(path, H5F_ACC_RDONLY, H5P_DEFAULT);
    assert_true(f >= 0);
    unsigned long long start[4], count[4];
    int64_t rows[14];
    read_all(f, "/jdem/bond_lines/frame_start", H5T_NATIVE_ULLONG, start);
    read_all(f, "/jdem/bond_lines/frame_count", H5T_NATIVE_ULLONG, count);
    read_all(f, "/jdem/bond_lines/rows", H5T_NATIVE_INT64, rows);
    const unsigned long long want_count[4] = {2, 2, 3, 2}, want_start[4] = {0, 0, 2, 5};
    const int64_t want_rows[14] = {0, 1, 1, 2, 0, 1, 1, 2, 0, 2, 0, 1, 0, 2};
    for (int k = 0; k < 4; k++) {
        assert_int_equal(count[k], want_count[k]);
        assert_int_equal(start[k], want_start[k]);
    }
    for (int i = 0; i < 14; i++) assert_int_equal(rows[i], want_rows[i]);
    H5Fclose(f);
    char side[160];
    snprintf(side, sizeof side, "%s/b.xdmf", dir);
    unlink(path);
    unlink(side);
    rmdir(dir);
}

/* A plane and a moving cylinder (axis z from 0 to 1, R 0.5, 1 m/s along x): 1 + 32
 * quadrilaterals; frame vertices = time-0 vertices + v t; cylinder vertices at R from the
 * axis; the obstacle's facets face outwards. */
static void walls_mesh(void **state) {
    (void)state;
    char dir[] = "/tmp/jdem_walls_XXXXXX", path[128], err[256] = "";
    out_path(dir, path, sizeof path, "w.h5");
    const int64_t id[1] = {1};
    const int32_t sp[1] = {0};
    const double r[1] = {1}, m[1] = {1}, x[3] = {0};
    const jd_h5md_particles p = {1, id, sp, r, m, 0};
    const jd_h5md_meta meta = {.creator = "test", .dt = 1.0};
    jd_h5md *h = jd_h5md_create(path, &meta, &p, err, sizeof err);
    if (!h) fail_msg("create: %s", err);
    jd_h5md_wall w[2] = {{.name = "floor", .type = 0,
                          .corners = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}}},
                         {.name = "bar", .type = 1, .axis = {{0, 0, 0}, {0, 0, 1}},
                          .radius = 0.5, .velocity = {1, 0, 0}}};
    assert_int_equal(jd_h5md_set_walls(h, 2, w, err, sizeof err), 0);
    write_frame(h, 0, x, NULL);
    write_frame(h, 2, x, NULL);
    if (jd_h5md_close(h, 1, err, sizeof err) != 0) fail_msg("close: %s", err);
    enum { NV = 4 + 2 * JD_H5MD_CYLINDER_FACETS, NQ = 1 + JD_H5MD_CYLINDER_FACETS };
    hid_t f = H5Fopen(path, H5F_ACC_RDONLY, H5P_DEFAULT);
    assert_true(f >= 0);
    static double v[2][NV][3];
    static int64_t q[NQ][4];
    read_all(f, "/jdem/walls/mesh/vertex_position", H5T_NATIVE_DOUBLE, v);
    read_all(f, "/jdem/walls/mesh/quads", H5T_NATIVE_INT64, q);
    for (int j = 0; j < NV; j++) {
        const double shift = j < 4 ? 0.0 : 2.0; /* the plane stands still */
        assert_true(fabs(v[1][j][0] - v[0][j][0] - shift) < 1e-15);
        if (j >= 4) assert_true(fabs(hypot(v[0][j][0], v[0][j][1]) - 0.5) < 1e-15);
    }
    for (int c = 0; c < 4; c++) assert_int_equal(q[0][c], c);
    /* facet 1: (P2 - P1) x (P4 - P1) points away from the axis */
    const double *a = v[0][q[1][0]], *b = v[0][q[1][1]], *d = v[0][q[1][3]];
    const double e1[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
    const double e2[3] = {d[0] - a[0], d[1] - a[1], d[2] - a[2]};
    const double n[2] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2]};
    assert_true(n[0] * (a[0] + b[0]) + n[1] * (a[1] + b[1]) > 0.0);
    H5Fclose(f);
    char side[160];
    snprintf(side, sizeof side, "%s/w.xdmf", dir);
    unlink(path);
    unlink(side);
    rmdir(dir);
}

int run_h5md_output_tests(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(growing_set),
        cmocka_unit_test(bond_lines),
        cmocka_unit_test(walls_mesh),
    };
    return cmocka_run_group_tests_name("h5md output (growing set, bond lines, walls)", tests,
                                       NULL, NULL);
}
