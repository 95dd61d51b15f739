/*
 * test_h5md_bonds.c — /connectivity written by io/h5md_bonds.c: bonds and broken-bond events
 * appended in two calls read back exactly (values, shapes, attributes), and an empty first call
 * creates the datasets.
 */
#include "unit.h"

#include <hdf5.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "h5md.h"

static hsize_t rows(hid_t f, const char *name, int *rank) {
    hid_t d = H5Dopen2(f, name, H5P_DEFAULT);
    assert_true(d >= 0);
    hid_t sp = H5Dget_space(d);
    hsize_t dims[2] = {0, 0};
    *rank = H5Sget_simple_extent_dims(sp, dims, NULL);
    H5Sclose(sp);
    H5Dclose(d);
    return dims[0];
}

static void read_all(hid_t f, const char *name, hid_t mtype, void *buf) {
    hid_t d = H5Dopen2(f, name, H5P_DEFAULT);
    assert_true(d >= 0);
    assert_true(H5Dread(d, mtype, H5S_ALL, H5S_ALL, H5P_DEFAULT, buf) >= 0);
    H5Dclose(d);
}

static void connectivity_roundtrip(void **state) {
    (void)state;
    char dir[] = "/tmp/jdem_bonds_XXXXXX";
    assert_non_null(mkdtemp(dir));
    char path[128], err[256] = "";
    snprintf(path, sizeof path, "%s/b.h5", dir);
    const int64_t id[3] = {1, 2, 3};
    const int32_t sp[3] = {0, 0, 0};
    const double r[3] = {1e-3, 1e-3, 1e-3}, m[3] = {1e-6, 1e-6, 1e-6};
    const jd_h5md_particles p = {3, id, sp, r, m, 0};
    const jd_h5md_meta meta = {.creator = "test", .dt = 1e-6};
    jd_h5md *h = jd_h5md_create(path, &meta, &p, err, sizeof err);
    if (!h) fail_msg("create: %s", err);
    assert_int_equal(jd_h5md_write_bonds(h, 0, NULL, err, sizeof err), 0);
    assert_int_equal(jd_h5md_write_bond_breaks(h, 0, NULL, err, sizeof err), 0);
    const jd_h5md_bond b[3] = {{{1, 2}, 0, 0}, {{2, 3}, 1, 0}, {{1, 3}, 0, 50}};
    assert_int_equal(jd_h5md_write_bonds(h, 2, b, err, sizeof err), 0);
    assert_int_equal(jd_h5md_write_bonds(h, 1, b + 2, err, sizeof err), 0);
    const jd_h5md_bond_break e = {.step = 70, .time = 7e-5, .id = {2, 3}, .mode = 2,
                                  .position = {0.5, 0.25, 0.125}, .normal_force = -1.5,
                                  .shear_force = 2.5, .twisting_moment = 3.5,
                                  .bending_moment = 4.5, .sigma_max = 5.5, .tau_max = 6.5};
    assert_int_equal(jd_h5md_write_bond_breaks(h, 1, &e, err, sizeof err), 0);
    assert_int_equal(jd_h5md_close(h, 1, err, sizeof err), 0);

    hid_t f = H5Fopen(path, H5F_ACC_RDONLY, H5P_DEFAULT);
    assert_true(f >= 0);
    int rank;
    assert_int_equal(rows(f, "/connectivity/bonds", &rank), 3);
    assert_int_equal(rank, 2);
    int64_t ids[6], steps[3];
    int32_t types[3];
    read_all(f, "/connectivity/bonds", H5T_NATIVE_INT64, ids);
    read_all(f, "/jdem/bonds/type", H5T_NATIVE_INT32, types);
    read_all(f, "/jdem/bonds/formed_step", H5T_NATIVE_INT64, steps);
    for (int i = 0; i < 3; i++) {
        assert_int_equal(ids[2 * i], b[i].id[0]);
        assert_int_equal(ids[2 * i + 1], b[i].id[1]);
        assert_int_equal(types[i], b[i].type);
        assert_int_equal(steps[i], b[i].formed_step);
    }
    /* H5MD tuple lists: particles_group is an object reference to /particles/all */
    for (int k = 0; k < 2; ++k) {
        const char *list = k ? "/connectivity/broken_bonds" : "/connectivity/bonds";
        hid_t a = H5Aopen_by_name(f, list, "particles_group", H5P_DEFAULT, H5P_DEFAULT);
        assert_true(a >= 0);
        hid_t t = H5Aget_type(a);
        assert_true(H5Tequal(t, H5T_STD_REF_OBJ) > 0);
        hobj_ref_t ref;
        assert_true(H5Aread(a, H5T_STD_REF_OBJ, &ref) >= 0);
        H5Tclose(t);
        H5Aclose(a);
        char name[64] = "";
        hid_t g = H5Rdereference2(f, H5P_DEFAULT, H5R_OBJECT, &ref);
        assert_true(g >= 0);
        assert_true(H5Iget_name(g, name, sizeof name) > 0);
        H5Oclose(g);
        assert_string_equal(name, "/particles/all");
    }
    /* the tuple lists are the tables' id columns themselves (hard links) */
    {
        H5O_info_t a, b;
        assert_true(H5Oget_info_by_name(f, "/connectivity/bonds", &a, H5P_DEFAULT) >= 0);
        assert_true(H5Oget_info_by_name(f, "/jdem/bonds/ids", &b, H5P_DEFAULT) >= 0);
        assert_true(a.addr == b.addr);
        assert_true(H5Oget_info_by_name(f, "/connectivity/broken_bonds", &a, H5P_DEFAULT) >= 0);
        assert_true(H5Oget_info_by_name(f, "/jdem/broken_bonds/ids", &b, H5P_DEFAULT) >= 0);
        assert_true(a.addr == b.addr);
        hsize_t nlinks = 0;
        hid_t c = H5Gopen2(f, "/connectivity", H5P_DEFAULT);
        H5G_info_t gi;
        assert_true(H5Gget_info(c, &gi) >= 0);
        nlinks = gi.nlinks;
        H5Gclose(c);
        assert_int_equal(nlinks, 2);
    }
    assert_int_equal(rows(f, "/jdem/broken_bonds/position", &rank), 1);
    assert_int_equal(rank, 2);
    double pos[3], v;
    int64_t eid[2];
    int32_t mode;
    read_all(f, "/jdem/broken_bonds/position", H5T_NATIVE_DOUBLE, pos);
    read_all(f, "/jdem/broken_bonds/ids", H5T_NATIVE_INT64, eid);
    read_all(f, "/jdem/broken_bonds/mode", H5T_NATIVE_INT32, &mode);
    assert_int_equal(eid[0], 2);
    assert_int_equal(eid[1], 3);
    assert_int_equal(mode, 2);
    assert_rel(pos[2], 0.125, 0.0);
    read_all(f, "/jdem/broken_bonds/tau_max", H5T_NATIVE_DOUBLE, &v);
    assert_rel(v, 6.5, 0.0);
    read_all(f, "/jdem/broken_bonds/normal_force", H5T_NATIVE_DOUBLE, &v);
    assert_rel(v, -1.5, 0.0);
    read_all(f, "/jdem/broken_bonds/step", H5T_NATIVE_INT64, eid);
    assert_int_equal(eid[0], 70);
    H5Fclose(f);
    unlink(path);
    char xdmf[128];
    snprintf(xdmf, sizeof xdmf, "%s/b.xdmf", dir);
    unlink(xdmf);
    rmdir(dir);
}

int run_h5md_bonds_tests(void) {
    const struct CMUnitTest tests[] = {cmocka_unit_test(connectivity_roundtrip)};
    return cmocka_run_group_tests_name("h5md_bonds", tests, NULL, NULL);
}
