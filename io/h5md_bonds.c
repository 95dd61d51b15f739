/*
 * h5md_bonds.c — the bonds of the H5MD writer (io/h5md.h): the bonds formed in a run and the
 * broken-bond events, appended as they happen.  Both engines call these two functions, so the
 * layout is written in one place.
 *
 * Each record type is a table of columns in a group of ours, /jdem/bonds and
 * /jdem/broken_bonds; a call gathers each column of the n records into a contiguous buffer and
 * appends it to that column's extendible dataset (created by the first call, so a run with bonds
 * always has the datasets, possibly empty).  The id pairs of each table are also H5MD 1.1 tuple
 * lists, /connectivity/bonds and /connectivity/broken_bonds (hard links to the same datasets),
 * so that /connectivity holds nothing else.
 */
#include <stddef.h>
#include <stdlib.h>
#include <string.h>

#include "h5md_internal.h"

typedef struct column {
    const char *name;
    int is_int;        /* 1: int64, 2: int32, 0: float64 */
    int width;         /* values per record: 1 (rank-1 dataset), 2 or 3 (rank 2) */
    size_t offset;     /* of the field in the record */
    const char *unit;  /* NULL: dimensionless or ids */
} column;

static const column bond_cols[] = {
    {"ids", 1, 2, offsetof(jd_h5md_bond, id), NULL},
    {"type", 2, 1, offsetof(jd_h5md_bond, type), NULL},
    {"formed_step", 1, 1, offsetof(jd_h5md_bond, formed_step), NULL},
};

static const column break_cols[] = {
    {"step", 1, 1, offsetof(jd_h5md_bond_break, step), NULL},
    {"time", 0, 1, offsetof(jd_h5md_bond_break, time), "s"},
    {"ids", 1, 2, offsetof(jd_h5md_bond_break, id), NULL},
    {"mode", 2, 1, offsetof(jd_h5md_bond_break, mode), NULL},
    {"position", 0, 3, offsetof(jd_h5md_bond_break, position), "m"},
    {"normal_force", 0, 1, offsetof(jd_h5md_bond_break, normal_force), "N"},
    {"shear_force", 0, 1, offsetof(jd_h5md_bond_break, shear_force), "N"},
    {"twisting_moment", 0, 1, offsetof(jd_h5md_bond_break, twisting_moment), "N m"},
    {"bending_moment", 0, 1, offsetof(jd_h5md_bond_break, bending_moment), "N m"},
    {"sigma_max", 0, 1, offsetof(jd_h5md_bond_break, sigma_max), "Pa"},
    {"tau_max", 0, 1, offsetof(jd_h5md_bond_break, tau_max), "Pa"},
};

static size_t value_size(const column *c) {
    return c->is_int == 2 ? sizeof(int32_t) : c->is_int ? sizeof(int64_t) : sizeof(double);
}

/* H5MD tuple list: particles_group is an object reference to the particles' group. */
static int particles_group_ref(hid_t d) {
    hobj_ref_t ref;
    if (H5Rcreate(&ref, d, "/particles/all", H5R_OBJECT, -1) < 0) return -1;
    return h5md_attr_write(d, "particles_group", H5T_STD_REF_OBJ, H5T_STD_REF_OBJ, 0, NULL, &ref);
}

static int link_tuple_list(hid_t d, const char *tuples) {
    hid_t lcpl = H5Pcreate(H5P_LINK_CREATE);
    int rc = -1;
    if (lcpl >= 0 && H5Pset_create_intermediate_group(lcpl, 1) >= 0 &&
        H5Lcreate_hard(d, ".", d, tuples, lcpl, H5P_DEFAULT) >= 0)
        rc = 0;
    if (lcpl >= 0) H5Pclose(lcpl);
    return rc;
}

/* Open the column's dataset in group g, creating it (with its attributes) if absent.  The id
 * pairs are also the H5MD tuple list TUPLES (a hard link: one dataset, two names). */
static hid_t open_column(hid_t g, const column *c, const char *tuples) {
    if (H5Lexists(g, c->name, H5P_DEFAULT) > 0) return H5Dopen2(g, c->name, H5P_DEFAULT);
    const hid_t ftype = c->is_int == 2 ? H5T_STD_I32LE : c->is_int ? H5T_STD_I64LE
                                                                   : H5T_IEEE_F64LE;
    const hsize_t rest[1] = {(hsize_t)c->width};
    const hsize_t chunk[2] = {256, (hsize_t)c->width};
    hid_t d = h5md_dset_extendible(g, c->name, ftype, c->width > 1 ? 2 : 1, rest, chunk);
    if (d < 0) return d;
    const int pairs = c->width == 2;
    if ((c->unit && h5md_attr_str(d, "unit", c->unit) < 0) ||
        (pairs && (particles_group_ref(d) < 0 || link_tuple_list(d, tuples) < 0))) {
        H5Dclose(d);
        return H5I_INVALID_HID;
    }
    return d;
}

/* Append n records of size rec_size to the columns under group path. */
static int append_table(jd_h5md *h, const char *path, const char *tuples, const column *cols,
                        size_t ncols, const void *recs, size_t rec_size, size_t n, char *err,
                        size_t errlen) {
    if (!h) {
        h5md_set_err(err, errlen, "h5md: no writer");
        return -1;
    }
    h5md_view v = h5md_view_of(h);
    if (*v.broken) {
        h5md_set_err(err, errlen, "h5md: '%s' is unusable after an earlier write error", v.part);
        return -1;
    }
    unsigned char *buf = malloc(n ? n * 3 * sizeof(double) : 1);
    if (!buf) {
        h5md_set_err(err, errlen, "h5md: out of memory");
        return -1;
    }
    quiet_t q;
    h5md_quiet_on(&q, v.detail);
    const char *what = path;
    int appended = 0; /* a column already has the new rows: a failure now is inconsistent */
    hid_t g = H5Lexists(v.file, path, H5P_DEFAULT) > 0 ? H5Gopen2(v.file, path, H5P_DEFAULT)
                                                       : h5md_group_create(v.file, path);
    if (g < 0) goto fail;
    for (size_t k = 0; k < ncols; k++) {
        const column *c = &cols[k];
        what = c->name;
        const size_t vs = value_size(c) * (size_t)c->width;
        for (size_t i = 0; i < n; i++)
            memcpy(buf + i * vs, (const unsigned char *)recs + i * rec_size + c->offset, vs);
        hid_t d = open_column(g, c, tuples);
        if (d < 0) goto fail;
        const hid_t mtype = c->is_int == 2 ? H5T_NATIVE_INT32 : c->is_int ? H5T_NATIVE_INT64
                                                                          : H5T_NATIVE_DOUBLE;
        hsize_t dims[2];
        hid_t sp = H5Dget_space(d);
        int ok = sp >= 0 && H5Sget_simple_extent_dims(sp, dims, NULL) >= 0;
        if (sp >= 0) H5Sclose(sp);
        const hsize_t rest[1] = {(hsize_t)c->width};
        ok = ok && h5md_append_rows(d, dims[0], n, c->width > 1 ? 2 : 1, rest, mtype, buf) >= 0;
        H5Dclose(d);
        if (!ok) goto fail;
        appended = n > 0;
    }
    H5Gclose(g);
    free(buf);
    if (H5Fflush(v.file, H5F_SCOPE_LOCAL) < 0) {
        h5md_err(v.detail, err, errlen, "cannot flush '%s'", v.part);
        *v.broken = 1;
        h5md_quiet_off(&q);
        return -1;
    }
    h5md_quiet_off(&q);
    return 0;
fail:
    h5md_err(v.detail, err, errlen, "cannot write /%s (%s) in '%s'", path, what, v.part);
    if (appended) *v.broken = 1;
    if (g >= 0) H5Gclose(g);
    free(buf);
    h5md_quiet_off(&q);
    return -1;
}

int jd_h5md_write_bonds(jd_h5md *h, size_t n, const jd_h5md_bond *bonds, char *err,
                        size_t errlen) {
    return append_table(h, "jdem/bonds", "/connectivity/bonds", bond_cols, sizeof bond_cols / sizeof *bond_cols, bonds,
                        sizeof *bonds, n, err, errlen);
}

int jd_h5md_write_bond_breaks(jd_h5md *h, size_t n, const jd_h5md_bond_break *events, char *err,
                              size_t errlen) {
    return append_table(h, "jdem/broken_bonds", "/connectivity/broken_bonds", break_cols,
                        sizeof break_cols / sizeof *break_cols, events, sizeof *events, n, err,
                        errlen);
}
