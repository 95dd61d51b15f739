/*
 * test_h5md.c — cmocka tests of io/h5md.c.  Linked with the other unit tests into one binary:
 * the only external symbol is run_h5md_tests().
 */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <hdf5.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>

#include "h5md.h"
#include "unit.h" /* declares run_h5md_tests() */

enum { NP = 3, NF = 4 };

static const int64_t t_id[NP] = {1, 2, 5};
static const int32_t t_species[NP] = {0, 1, 0};
static const double t_radius[NP] = {1e-3, 2e-3, 1.5e-3};
static const double t_mass[NP] = {4.2e-6, 3.3e-5, 1.4e-5};
static const char t_scene[] = "name: glass\nmaterials: [{name: glass, E: 6.3e10}]\n# ünïcode\n";

/* value of array `arr` (0 position .. 4 torque) at frame f, particle i, component c */
static double val(int arr, int f, int i, int c) {
    return 1000.0 * arr + 100.0 * f + 10.0 * i + c + 0.125;
}

typedef struct tdir {
    char dir[64];
    char h5[128], part[128], xdmf[128];
} tdir;

static void tdir_make(tdir *t) {
    strcpy(t->dir, "/tmp/jdem_h5md_XXXXXX");
    assert_non_null(mkdtemp(t->dir));
    snprintf(t->h5, sizeof t->h5, "%s/glass.jdem.h5", t->dir);
    snprintf(t->part, sizeof t->part, "%s/glass.jdem.h5.part", t->dir);
    snprintf(t->xdmf, sizeof t->xdmf, "%s/glass.jdem.xdmf", t->dir);
}

static void tdir_remove(tdir *t) {
    char extra[160];
    unlink(t->h5);
    unlink(t->part);
    unlink(t->xdmf);
    snprintf(extra, sizeof extra, "%s/second.h5", t->dir);
    unlink(extra);
    snprintf(extra, sizeof extra, "%s/second.xdmf", t->dir);
    unlink(extra);
    rmdir(t->dir);
}

static int exists(const char *p) {
    struct stat st;
    return stat(p, &st) == 0;
}

static jd_h5md *open_writer(const char *path, char *err, size_t errlen) {
    jd_h5md_meta meta = {"jdem", "0.1.0", "glass", "chung_ooi_1", t_scene, 1e-6, "A. Tester"};
    jd_h5md_particles p = {NP, t_id, t_species, t_radius, t_mass, 0};
    return jd_h5md_create(path, &meta, &p, err, errlen);
}

/* Write frames [0, nf); `mask` bit k set = array k (0 position..4 torque) is given. */
static void write_frames(jd_h5md *h, int nf, unsigned mask) {
    double buf[5][3 * NP];
    char err[256];
    for (int f = 0; f < nf; ++f) {
        for (int a = 0; a < 5; ++a)
            for (int i = 0; i < NP; ++i)
                for (int c = 0; c < 3; ++c) buf[a][3 * i + c] = val(a, f, i, c);
        jd_h5md_frame fr = {100 * f, 1e-4 * f, buf[0], (mask & 2) ? buf[1] : NULL,
                            (mask & 4) ? buf[2] : NULL, (mask & 8) ? buf[3] : NULL,
                            (mask & 16) ? buf[4] : NULL, NULL};
        err[0] = 0;
        int rc = jd_h5md_write_frame(h, &fr, err, sizeof err);
        if (rc != 0) fail_msg("write_frame: %s", err);
    }
}

/* ---- read-back helpers ---- */

static void check_dims(hid_t f, const char *name, int rank, const hsize_t *want, int unlimited) {
    hid_t d = H5Dopen2(f, name, H5P_DEFAULT);
    assert_true(d >= 0);
    hid_t s = H5Dget_space(d);
    hsize_t dims[3] = {0}, maxd[3] = {0};
    assert_int_equal(H5Sget_simple_extent_ndims(s), rank);
    H5Sget_simple_extent_dims(s, dims, maxd);
    for (int i = 0; i < rank; ++i) assert_int_equal(dims[i], want[i]);
    if (unlimited) {
        assert_true(maxd[0] == H5S_UNLIMITED);
        hid_t dcpl = H5Dget_create_plist(d);
        assert_int_equal(H5Pget_layout(dcpl), H5D_CHUNKED);
        H5Pclose(dcpl);
    }
    H5Sclose(s);
    H5Dclose(d);
}

static void read_doubles(hid_t f, const char *name, double *out) {
    hid_t d = H5Dopen2(f, name, H5P_DEFAULT);
    assert_true(d >= 0);
    hid_t t = H5Dget_type(d);
    assert_int_equal(H5Tget_class(t), H5T_FLOAT);
    assert_int_equal(H5Tget_size(t), 8);
    H5Tclose(t);
    assert_true(H5Dread(d, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, out) >= 0);
    H5Dclose(d);
}

static void read_i64(hid_t f, const char *name, int64_t *out) {
    hid_t d = H5Dopen2(f, name, H5P_DEFAULT);
    assert_true(d >= 0);
    assert_true(H5Dread(d, H5T_NATIVE_INT64, H5S_ALL, H5S_ALL, H5P_DEFAULT, out) >= 0);
    H5Dclose(d);
}

/* string attribute (fixed or variable length) of object `obj` into buf */
static void attr_string(hid_t f, const char *obj, const char *name, char *buf, size_t len) {
    hid_t a = H5Aopen_by_name(f, obj, name, H5P_DEFAULT, H5P_DEFAULT);
    assert_true(a >= 0);
    hid_t t = H5Aget_type(a);
    assert_int_equal(H5Tget_class(t), H5T_STRING);
    if (H5Tis_variable_str(t)) {
        char *s = NULL;
        assert_true(H5Aread(a, t, &s) >= 0);
        snprintf(buf, len, "%s", s);
        H5free_memory(s);
    } else {
        size_t sz = H5Tget_size(t);
        char *tmp = calloc(1, sz + 1);
        assert_non_null(tmp);
        assert_true(H5Aread(a, t, tmp) >= 0);
        snprintf(buf, len, "%s", tmp);
        free(tmp);
    }
    H5Tclose(t);
    H5Aclose(a);
}

static double attr_double(hid_t f, const char *obj, const char *name) {
    double v = NAN;
    hid_t a = H5Aopen_by_name(f, obj, name, H5P_DEFAULT, H5P_DEFAULT);
    assert_true(a >= 0);
    assert_true(H5Aread(a, H5T_NATIVE_DOUBLE, &v) >= 0);
    H5Aclose(a);
    return v;
}

static int link_exists(hid_t f, const char *path) { return H5Lexists(f, path, H5P_DEFAULT) > 0; }

static void check_frames(hid_t f, int nf, unsigned mask) {
    static const char *const groups[5] = {"position", "velocity", "angular_velocity", "force",
                                          "torque"};
    static const char *const units[5] = {"m", "m s-1", "s-1", "N", "N m"};
    char name[128], s[64];
    double v[NF * NP * 3];
    double tm[NF];
    int64_t st[NF];
    for (int a = 0; a < 5; ++a) {
        snprintf(name, sizeof name, "/particles/all/%s", groups[a]);
        if (!(mask & (1u << a))) {
            assert_false(link_exists(f, name));
            continue;
        }
        snprintf(name, sizeof name, "/particles/all/%s/value", groups[a]);
        hsize_t want[3] = {(hsize_t)nf, NP, 3};
        check_dims(f, name, 3, want, 1);
        read_doubles(f, name, v);
        for (int fr = 0; fr < nf; ++fr)
            for (int i = 0; i < NP; ++i)
                for (int c = 0; c < 3; ++c)
                    assert_true(v[(fr * NP + i) * 3 + c] == val(a, fr, i, c));
        attr_string(f, name, "unit", s, sizeof s);
        assert_string_equal(s, units[a]);
        snprintf(name, sizeof name, "/particles/all/%s/step", groups[a]);
        check_dims(f, name, 1, want, 1);
        read_i64(f, name, st);
        snprintf(name, sizeof name, "/particles/all/%s/time", groups[a]);
        check_dims(f, name, 1, want, 1);
        read_doubles(f, name, tm);
        attr_string(f, name, "unit", s, sizeof s);
        assert_string_equal(s, "s");
        for (int fr = 0; fr < nf; ++fr) {
            assert_int_equal(st[fr], 100 * fr);
            assert_true(tm[fr] == 1e-4 * fr);
        }
    }
}

/* ---- tests ---- */

static herr_t counting_handler(hid_t estack, void *data) {
    (void)estack;
    ++*(int *)data;
    return 0;
}

static void test_roundtrip_layout(void **state) {
    (void)state;
    tdir t;
    tdir_make(&t);
    char err[256] = "";
    jd_h5md *h = open_writer(t.h5, err, sizeof err);
    if (!h) fail_msg("create: %s", err);
    write_frames(h, NF, 31u);
    /* two observables on different schedules */
    for (int k = 0; k < NF; ++k)
        assert_int_equal(jd_h5md_write_observable(h, "kinetic_energy", 100 * k, 1e-4 * k,
                                                  0.5 * k, err, sizeof err), 0);
    for (int k = 0; k < 2; ++k)
        assert_int_equal(jd_h5md_write_observable(h, "contacts", 200 * k, 2e-4 * k, 3.0 + k,
                                                  err, sizeof err), 0);
    assert_int_equal(jd_h5md_close(h, 1, err, sizeof err), 0);
    /* the writer left nothing open in the library */
    assert_int_equal(H5Fget_obj_count((hid_t)H5F_OBJ_ALL, H5F_OBJ_ALL), 0);

    assert_true(exists(t.h5));
    assert_false(exists(t.part));
    hid_t f = H5Fopen(t.h5, H5F_ACC_RDONLY, H5P_DEFAULT);
    assert_true(f >= 0);

    /* /h5md */
    {
        int ver[2] = {0, 0};
        hid_t a = H5Aopen_by_name(f, "/h5md", "version", H5P_DEFAULT, H5P_DEFAULT);
        assert_true(a >= 0);
        hid_t sp = H5Aget_space(a);
        hsize_t d = 0;
        assert_int_equal(H5Sget_simple_extent_ndims(sp), 1);
        H5Sget_simple_extent_dims(sp, &d, NULL);
        assert_int_equal(d, 2);
        hid_t ty = H5Aget_type(a);
        assert_int_equal(H5Tget_class(ty), H5T_INTEGER);
        H5Tclose(ty);
        H5Sclose(sp);
        assert_true(H5Aread(a, H5T_NATIVE_INT, ver) >= 0);
        H5Aclose(a);
        assert_int_equal(ver[0], 1);
        assert_int_equal(ver[1], 1);
    }
    char s[128];
    attr_string(f, "/h5md/author", "name", s, sizeof s);
    assert_string_equal(s, "A. Tester");
    /* the units module (H5MD units module 1.0): version [1, 0], system "SI", ASCII units */
    attr_string(f, "/h5md/modules/units", "system", s, sizeof s);
    assert_string_equal(s, "SI");
    {
        int uv[2] = {0, 0};
        hid_t a = H5Aopen_by_name(f, "/h5md/modules/units", "version", H5P_DEFAULT, H5P_DEFAULT);
        assert_true(a >= 0 && H5Aread(a, H5T_NATIVE_INT, uv) >= 0);
        H5Aclose(a);
        assert_int_equal(uv[0], 1);
        assert_int_equal(uv[1], 0);
        a = H5Aopen_by_name(f, "/particles/all/position/value", "unit", H5P_DEFAULT, H5P_DEFAULT);
        hid_t ty = H5Aget_type(a);
        assert_int_equal(H5Tget_cset(ty), H5T_CSET_ASCII);
        H5Tclose(ty);
        H5Aclose(a);
    }
    attr_string(f, "/h5md/creator", "name", s, sizeof s);
    assert_string_equal(s, "jdem");
    attr_string(f, "/h5md/creator", "version", s, sizeof s);
    assert_string_equal(s, "0.1.0");

    /* /parameters */
    attr_string(f, "/parameters", "engine", s, sizeof s);
    assert_string_equal(s, "jdem");
    attr_string(f, "/parameters", "scene_name", s, sizeof s);
    assert_string_equal(s, "glass");
    attr_string(f, "/parameters", "case_name", s, sizeof s);
    assert_string_equal(s, "chung_ooi_1");
    assert_true(attr_double(f, "/parameters", "dt") == 1e-6);
    {
        hid_t d = H5Dopen2(f, "/parameters/scene", H5P_DEFAULT);
        assert_true(d >= 0);
        hid_t ty = H5Dget_type(d);
        assert_true(H5Tis_variable_str(ty) > 0);
        assert_int_equal(H5Tget_cset(ty), H5T_CSET_UTF8);
        char *txt = NULL;
        assert_true(H5Dread(d, ty, H5S_ALL, H5S_ALL, H5P_DEFAULT, &txt) >= 0);
        assert_string_equal(txt, t_scene);
        H5free_memory(txt);
        H5Tclose(ty);
        H5Dclose(d);
    }

    /* box */
    {
        int dim = 0;
        hid_t a = H5Aopen_by_name(f, "/particles/all/box", "dimension", H5P_DEFAULT,
                                  H5P_DEFAULT);
        assert_true(a >= 0);
        assert_true(H5Aread(a, H5T_NATIVE_INT, &dim) >= 0);
        H5Aclose(a);
        assert_int_equal(dim, 3);
        a = H5Aopen_by_name(f, "/particles/all/box", "boundary", H5P_DEFAULT, H5P_DEFAULT);
        assert_true(a >= 0);
        hid_t ty = H5Aget_type(a);
        assert_int_equal(H5Tget_class(ty), H5T_STRING);
        assert_false(H5Tis_variable_str(ty));
        size_t sz = H5Tget_size(ty);
        hid_t sp = H5Aget_space(a);
        hsize_t n = 0;
        H5Sget_simple_extent_dims(sp, &n, NULL);
        assert_int_equal(n, 3);
        char *b = calloc(3, sz);
        assert_non_null(b);
        assert_true(H5Aread(a, ty, b) >= 0);
        for (int i = 0; i < 3; ++i) assert_true(strncmp(b + i * sz, "none", sz) == 0);
        free(b);
        H5Sclose(sp);
        H5Tclose(ty);
        H5Aclose(a);
    }

    /* time-independent data */
    {
        int64_t id[NP];
        int32_t sp[NP];
        double r[NP], m[NP];
        hsize_t want[1] = {NP};
        check_dims(f, "/particles/all/id", 1, want, 0);
        check_dims(f, "/particles/all/species", 1, want, 0);
        check_dims(f, "/particles/all/radius", 1, want, 0);
        check_dims(f, "/particles/all/mass", 1, want, 0);
        read_i64(f, "/particles/all/id", id);
        hid_t d = H5Dopen2(f, "/particles/all/species", H5P_DEFAULT);
        hid_t ty = H5Dget_type(d);
        assert_int_equal(H5Tget_size(ty), 4);
        H5Tclose(ty);
        assert_true(H5Dread(d, H5T_NATIVE_INT32, H5S_ALL, H5S_ALL, H5P_DEFAULT, sp) >= 0);
        H5Dclose(d);
        d = H5Dopen2(f, "/particles/all/id", H5P_DEFAULT);
        ty = H5Dget_type(d);
        assert_int_equal(H5Tget_size(ty), 8);
        H5Tclose(ty);
        H5Dclose(d);
        read_doubles(f, "/particles/all/radius", r);
        read_doubles(f, "/particles/all/mass", m);
        for (int i = 0; i < NP; ++i) {
            assert_int_equal(id[i], t_id[i]);
            assert_int_equal(sp[i], t_species[i]);
            assert_true(r[i] == t_radius[i]);
            assert_true(m[i] == t_mass[i]);
        }
    }

    check_frames(f, NF, 31u);

    /* observables */
    {
        double v[NF], tm[NF];
        int64_t st[NF];
        hsize_t w4[1] = {NF}, w2[1] = {2};
        check_dims(f, "/observables/kinetic_energy/value", 1, w4, 1);
        check_dims(f, "/observables/kinetic_energy/step", 1, w4, 1);
        check_dims(f, "/observables/kinetic_energy/time", 1, w4, 1);
        read_doubles(f, "/observables/kinetic_energy/value", v);
        read_doubles(f, "/observables/kinetic_energy/time", tm);
        read_i64(f, "/observables/kinetic_energy/step", st);
        for (int k = 0; k < NF; ++k) {
            assert_true(v[k] == 0.5 * k);
            assert_true(tm[k] == 1e-4 * k);
            assert_int_equal(st[k], 100 * k);
        }
        check_dims(f, "/observables/contacts/value", 1, w2, 1);
        check_dims(f, "/observables/contacts/step", 1, w2, 1);
        read_doubles(f, "/observables/contacts/value", v);
        read_i64(f, "/observables/contacts/step", st);
        assert_true(v[0] == 3.0 && v[1] == 4.0);
        assert_int_equal(st[1], 200);
    }
    H5Fclose(f);
    assert_int_equal(H5Fget_obj_count((hid_t)H5F_OBJ_ALL, H5F_OBJ_ALL), 0);
    tdir_remove(&t);
}

static void test_xdmf_sidecar(void **state) {
    (void)state;
    tdir t;
    tdir_make(&t);
    char err[256] = "";
    jd_h5md *h = open_writer(t.h5, err, sizeof err);
    if (!h) fail_msg("create: %s", err);
    write_frames(h, NF, 1u | 2u | 8u); /* position, velocity, force */
    assert_false(exists(t.xdmf));
    assert_int_equal(jd_h5md_close(h, 1, err, sizeof err), 0);
    assert_true(exists(t.xdmf));

    FILE *fp = fopen(t.xdmf, "r");
    assert_non_null(fp);
    static char text[1 << 16];
    size_t n = fread(text, 1, sizeof text - 1, fp);
    fclose(fp);
    text[n] = 0;
    int grids = 0, times = 0;
    for (const char *p = text; (p = strstr(p, "<Grid Name=\"frame_")); ++p) ++grids;
    for (const char *p = text; (p = strstr(p, "<Time Value=")); ++p) ++times;
    assert_int_equal(grids, NF);
    assert_int_equal(times, NF);
    assert_non_null(strstr(text, "CollectionType=\"Temporal\""));
    assert_non_null(strstr(text, "TopologyType=\"Polyvertex\""));
    /* relative reference to the .h5, never the directory or the .part name */
    assert_non_null(strstr(text, ">glass.jdem.h5:/particles/all/position/value|"));
    assert_null(strstr(text, t.dir));
    assert_null(strstr(text, ".part"));
    assert_non_null(strstr(text, "Name=\"velocity\""));
    assert_non_null(strstr(text, "Name=\"force\""));
    assert_non_null(strstr(text, "Name=\"radius\""));
    assert_non_null(strstr(text, "Name=\"species\""));
    assert_null(strstr(text, "Name=\"angular_velocity\"")); /* not written in this run */
    /* the last frame's selection, in Xdmf3's start:stride:count:dataspace syntax (the
     * HyperSlab items of before showed 0 points in ParaView's default reader) */
    char slab[96];
    snprintf(slab, sizeof slab, "position/value|%d 0 0:1 1 1:1 %d 3:%d %d 3<", NF - 1, NP, NF,
             NP);
    assert_non_null(strstr(text, slab));
    assert_null(strstr(text, "HyperSlab"));
    char vertices[96];
    snprintf(vertices, sizeof vertices, ">glass.jdem.h5:/jdem/vertex_index|0:1:%d:%d</DataItem></Topology>",
             NP, NP);
    assert_non_null(strstr(text, vertices));
    tdir_remove(&t);
}

static void test_abort_keeps_part(void **state) {
    (void)state;
    tdir t;
    tdir_make(&t);
    /* a complete file from an earlier run must survive an aborted one */
    FILE *fp = fopen(t.h5, "w");
    assert_non_null(fp);
    fputs("old", fp);
    fclose(fp);

    char err[256] = "";
    jd_h5md *h = open_writer(t.h5, err, sizeof err);
    if (!h) fail_msg("create: %s", err);
    assert_true(exists(t.part));
    write_frames(h, 2, 3u);
    assert_int_equal(jd_h5md_close(h, 0, err, sizeof err), 0);
    assert_true(exists(t.part));
    assert_false(exists(t.xdmf));
    assert_true(H5Fis_hdf5(t.h5) <= 0); /* still the old file (not HDF5) */

    hid_t f = H5Fopen(t.part, H5F_ACC_RDONLY, H5P_DEFAULT);
    assert_true(f >= 0);
    check_frames(f, 2, 3u);
    H5Fclose(f);

    /* a successful run replaces the old file only at close */
    h = open_writer(t.h5, err, sizeof err);
    if (!h) fail_msg("create: %s", err);
    write_frames(h, 1, 1u);
    assert_true(H5Fis_hdf5(t.h5) <= 0);
    assert_int_equal(jd_h5md_close(h, 1, err, sizeof err), 0);
    assert_true(H5Fis_hdf5(t.h5) > 0);
    assert_false(exists(t.part));
    assert_true(exists(t.xdmf));
    tdir_remove(&t);
}

static void test_killed_run_readable(void **state) {
    (void)state;
    tdir t;
    tdir_make(&t);
    fflush(NULL);
    pid_t pid = fork();
    assert_true(pid >= 0);
    if (pid == 0) { /* child: write 3 frames + observables, then die without closing */
        char err[256];
        jd_h5md *h = open_writer(t.h5, err, sizeof err);
        if (!h) _exit(2);
        double pos[3 * NP] = {0};
        for (int f = 0; f < 3; ++f) {
            jd_h5md_frame fr = {f, 0.5 * f, pos, NULL, NULL, NULL, NULL, NULL};
            if (jd_h5md_write_frame(h, &fr, err, sizeof err) != 0) _exit(3);
        }
        /* batch at step 2 (two samples), then a new batch at step 3 flushes it */
        if (jd_h5md_write_observable(h, "e", 2, 1.0, 7.0, err, sizeof err) != 0) _exit(4);
        if (jd_h5md_write_observable(h, "f", 2, 1.0, 8.0, err, sizeof err) != 0) _exit(4);
        if (jd_h5md_write_observable(h, "e", 3, 1.5, 9.0, err, sizeof err) != 0) _exit(4);
        _exit(0);
    }
    int status = 0;
    assert_int_equal(waitpid(pid, &status, 0), pid);
    assert_true(WIFEXITED(status));
    assert_int_equal(WEXITSTATUS(status), 0);
    assert_false(exists(t.h5));
    hid_t f = H5Fopen(t.part, H5F_ACC_RDONLY, H5P_DEFAULT);
    assert_true(f >= 0);
    hsize_t w3[3] = {3, NP, 3}, w1[1] = {1};
    check_dims(f, "/particles/all/position/value", 3, w3, 1);
    check_dims(f, "/particles/all/position/step", 1, w3, 1);
    check_dims(f, "/observables/f/value", 1, w1, 1); /* the complete batch at step 2 */
    {
        hid_t d = H5Dopen2(f, "/observables/e/value", H5P_DEFAULT);
        assert_true(d >= 0);
        hid_t sp = H5Dget_space(d);
        hsize_t n = 0;
        H5Sget_simple_extent_dims(sp, &n, NULL);
        assert_true(n >= 1); /* step 2 surely; step 3 (unflushed batch) maybe */
        double v = 0.0;
        hsize_t start = 0, one = 1;
        hid_t ms = H5Screate_simple(1, &one, NULL);
        H5Sselect_hyperslab(sp, H5S_SELECT_SET, &start, NULL, &one, NULL);
        assert_true(H5Dread(d, H5T_NATIVE_DOUBLE, ms, sp, H5P_DEFAULT, &v) >= 0);
        assert_true(v == 7.0);
        H5Sclose(ms);
        H5Sclose(sp);
        H5Dclose(d);
    }
    H5Fclose(f);
    tdir_remove(&t);
}

static void test_two_writers(void **state) {
    (void)state;
    tdir t;
    tdir_make(&t);
    char second[160], err[256] = "";
    snprintf(second, sizeof second, "%s/second.h5", t.dir);
    jd_h5md *a = open_writer(t.h5, err, sizeof err);
    if (!a) fail_msg("create: %s", err);
    jd_h5md *b = open_writer(second, err, sizeof err);
    if (!b) fail_msg("create: %s", err);
    write_frames(a, 2, 31u);
    write_frames(b, 3, 1u);
    assert_int_equal(jd_h5md_write_observable(b, "x", 0, 0.0, 1.0, err, sizeof err), 0);
    assert_int_equal(jd_h5md_close(a, 1, err, sizeof err), 0);
    assert_int_equal(jd_h5md_close(b, 1, err, sizeof err), 0);
    hid_t f = H5Fopen(t.h5, H5F_ACC_RDONLY, H5P_DEFAULT);
    assert_true(f >= 0);
    check_frames(f, 2, 31u);
    assert_false(link_exists(f, "/observables"));
    H5Fclose(f);
    f = H5Fopen(second, H5F_ACC_RDONLY, H5P_DEFAULT);
    assert_true(f >= 0);
    check_frames(f, 3, 1u);
    H5Fclose(f);
    snprintf(second, sizeof second, "%s/second.xdmf", t.dir);
    assert_true(exists(second));
    tdir_remove(&t);
}

static void test_errors(void **state) {
    (void)state;
    char err[256] = "";
    jd_h5md *h = open_writer("/nonexistent_jdem_dir/x/out.h5", err, sizeof err);
    assert_null(h);
    assert_non_null(strstr(err, "cannot create '/nonexistent_jdem_dir/x/out.h5.part'"));
    assert_non_null(strstr(err, "No such file or directory"));
    assert_null(strchr(err, '\n'));

    tdir t;
    tdir_make(&t);
    {
        const int64_t unsorted[NP] = {1, 5, 2};
        jd_h5md_particles p = {NP, unsorted, t_species, t_radius, t_mass, 0};
        assert_null(jd_h5md_create(t.h5, NULL, &p, err, sizeof err));
        assert_non_null(strstr(err, "sorted"));
        assert_false(exists(t.part));
    }
    h = open_writer(t.h5, err, sizeof err);
    if (!h) fail_msg("create: %s", err);
    jd_h5md_frame nopos = {0, 0.0, NULL, NULL, NULL, NULL, NULL, NULL};
    err[0] = 0;
    assert_int_equal(jd_h5md_write_frame(h, &nopos, err, sizeof err), -1);
    assert_true(err[0] != 0);
    write_frames(h, 1, 3u);
    /* changing the set of arrays after the first frame is refused */
    double pos[3 * NP] = {0};
    jd_h5md_frame fr = {1, 1.0, pos, NULL, NULL, NULL, NULL, NULL};
    err[0] = 0;
    assert_int_equal(jd_h5md_write_frame(h, &fr, err, sizeof err), -1);
    assert_non_null(strstr(err, "velocity"));
    err[0] = 0;
    assert_int_equal(jd_h5md_write_observable(h, "", 0, 0.0, 0.0, err, sizeof err), -1);
    assert_true(err[0] != 0);
    /* an HDF5-level failure (a dataset where a group is needed) is reported in one line and
     * leaves the writer usable */
    assert_int_equal(jd_h5md_write_observable(h, "e", 0, 0.0, 1.0, err, sizeof err), 0);
    err[0] = 0;
    /* the caller's HDF5 error handler is neither called nor lost */
    H5E_auto2_t old_fn = NULL;
    void *old_data = NULL;
    H5Eget_auto2(H5E_DEFAULT, &old_fn, &old_data);
    int calls = 0;
    H5Eset_auto2(H5E_DEFAULT, counting_handler, &calls);
    assert_int_equal(jd_h5md_write_observable(h, "e/value/x", 0, 0.0, 0.0, err, sizeof err), -1);
    H5E_auto2_t fn = NULL;
    void *data = NULL;
    H5Eget_auto2(H5E_DEFAULT, &fn, &data);
    assert_true(fn == counting_handler && data == &calls);
    assert_int_equal(calls, 0);
    H5Eset_auto2(H5E_DEFAULT, old_fn, old_data);
    assert_non_null(strstr(err, "cannot create /observables/e/value/x"));
    assert_null(strchr(err, '\n'));
    assert_int_equal(jd_h5md_write_observable(h, "e", 1, 1.0, 2.0, err, sizeof err), 0);
    assert_int_equal(jd_h5md_close(h, 1, err, sizeof err), 0);
    assert_int_equal(jd_h5md_close(NULL, 1, err, sizeof err), 0);
    assert_int_equal(H5Fget_obj_count((hid_t)H5F_OBJ_ALL, H5F_OBJ_ALL), 0);
    tdir_remove(&t);
}

static void write_text(const char *path, const char *text) {
    FILE *fp = fopen(path, "w");
    assert_non_null(fp);
    fputs(text, fp);
    assert_int_equal(fclose(fp), 0);
}

static void assert_text(const char *path, const char *text) {
    char buf[64] = "";
    FILE *fp = fopen(path, "r");
    assert_non_null(fp);
    size_t n = fread(buf, 1, sizeof buf - 1, fp);
    fclose(fp);
    buf[n] = 0;
    assert_string_equal(buf, text);
}

static hsize_t frames_in(const char *path) {
    hid_t f = H5Fopen(path, H5F_ACC_RDONLY, H5P_DEFAULT);
    assert_true(f >= 0);
    hid_t d = H5Dopen2(f, "/particles/all/position/step", H5P_DEFAULT);
    hid_t sp = H5Dget_space(d);
    hsize_t n = (hsize_t)H5Sget_simple_extent_npoints(sp);
    H5Sclose(sp);
    H5Dclose(d);
    H5Fclose(f);
    return n;
}

/* A link at PATH.part is refused and its target left alone; so is a directory at PATH. */
static void test_part_links_refused(void **state) {
    (void)state;
    tdir t;
    tdir_make(&t);
    char victim[160], err[256] = "";
    snprintf(victim, sizeof victim, "%s/victim.txt", t.dir);
    write_text(victim, "keep");
    assert_int_equal(symlink(victim, t.part), 0);
    assert_null(open_writer(t.h5, err, sizeof err));
    char want[512];
    snprintf(want, sizeof want, "'%s' is a symbolic link; a trajectory is never written through "
             "one (remove it or choose another output path)", t.part);
    assert_string_equal(err, want);
    assert_text(victim, "keep");
    unlink(t.part);
    assert_int_equal(link(victim, t.part), 0);
    assert_null(open_writer(t.h5, err, sizeof err));
    snprintf(want, sizeof want, "cannot write '%s': it has other hard links, whose contents would "
             "be destroyed (remove it or choose another output path)", t.part);
    assert_string_equal(err, want);
    assert_text(victim, "keep");
    unlink(t.part);
    unlink(victim);
    assert_int_equal(mkdir(t.h5, 0777), 0);
    assert_null(open_writer(t.h5, err, sizeof err));
    snprintf(want, sizeof want, "output path '%s' is a directory (give a file name, e.g. "
             "'%s/run.h5')", t.h5, t.h5);
    assert_string_equal(err, want);
    assert_false(exists(t.part));
    rmdir(t.h5);
    tdir_remove(&t);
}

/* A second writer on a live PATH.part fails before it truncates anything; the first one ends
 * normally with its own frames. */
static void test_second_run_locked_out(void **state) {
    (void)state;
    tdir t;
    tdir_make(&t);
    char err[256] = "", want[512];
    jd_h5md *a = open_writer(t.h5, err, sizeof err);
    if (!a) fail_msg("create: %s", err);
    write_frames(a, 3, 31u);
    assert_null(open_writer(t.h5, err, sizeof err));
    snprintf(want, sizeof want, "'%s' is being written by another run (it holds the file's lock); "
             "choose another output path or wait for it to end", t.part);
    assert_string_equal(err, want);
    assert_true(exists(t.part));
    write_frames(a, 1, 31u);
    assert_int_equal(jd_h5md_close(a, 1, err, sizeof err), 0);
    assert_int_equal(frames_in(t.h5), 1 + 3);
    /* the lock went with the writer: the next run on the path works */
    a = open_writer(t.h5, err, sizeof err);
    if (!a) fail_msg("create: %s", err);
    assert_int_equal(jd_h5md_close(a, 0, err, sizeof err), 0);
    tdir_remove(&t);
}

/* A sidecar that cannot be written leaves the previous .h5 and .xdmf pair as it was. */
static void test_failed_sidecar_keeps_previous_pair(void **state) {
    (void)state;
    tdir t;
    tdir_make(&t);
    char err[256] = "", blocker[160], inside[200], want[512];
    jd_h5md *h = open_writer(t.h5, err, sizeof err);
    if (!h) fail_msg("create: %s", err);
    write_frames(h, 2, 1u);
    assert_int_equal(jd_h5md_close(h, 1, err, sizeof err), 0);
    snprintf(blocker, sizeof blocker, "%s.part", t.xdmf);
    assert_int_equal(mkdir(blocker, 0777), 0);
    snprintf(inside, sizeof inside, "%s/x", blocker);
    write_text(inside, "x");
    h = open_writer(t.h5, err, sizeof err);
    if (!h) fail_msg("create: %s", err);
    write_frames(h, 3, 1u);
    assert_int_equal(jd_h5md_close(h, 1, err, sizeof err), -1);
    snprintf(want, sizeof want, "cannot create '%s': File exists; the trajectory is complete in "
             "'%s' (without its sidecar); the previous result is unchanged", blocker, t.part);
    assert_string_equal(err, want);
    assert_int_equal(frames_in(t.h5), 2);
    assert_true(exists(t.part)); /* the new, complete run stays under PATH.part */
    assert_int_equal(frames_in(t.part), 3);
    unlink(inside);
    rmdir(blocker);
    tdir_remove(&t);
}

int run_h5md_tests(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_roundtrip_layout),  cmocka_unit_test(test_xdmf_sidecar),
        cmocka_unit_test(test_abort_keeps_part),  cmocka_unit_test(test_killed_run_readable),
        cmocka_unit_test(test_two_writers),       cmocka_unit_test(test_errors),
        cmocka_unit_test(test_part_links_refused), cmocka_unit_test(test_second_run_locked_out),
        cmocka_unit_test(test_failed_sidecar_keeps_previous_pair),
    };
    return cmocka_run_group_tests_name("h5md", tests, NULL, NULL);
}
