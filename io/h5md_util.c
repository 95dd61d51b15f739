/*
 * h5md_util.c — the H5MD writer's error capture and its small HDF5 helpers (see h5md_internal.h).
 */
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "h5md_internal.h"

/* ------------------------------------------------------------------------------------------ */
/* error handling */

/* While a public call runs, HDF5's automatic error handler is replaced by capture_cb, which
 * prints nothing and records the innermost description of the first failure into the writer's
 * `h5detail` (client data, no globals); the caller's handler is restored on return.  Capturing
 * at the API boundary matters: the cleanup calls after a failure reset HDF5's error stack. */
static herr_t walk_cb(unsigned n, const H5E_error2_t *e, void *data) {
    char *buf = data;
    if (n == 0 && e && e->desc) {
        /* a failed system call: HDF5's description carries the time, the buffer address and
         * the sizes; the system's message is the part a user needs */
        const char *sys = strstr(e->desc, "error message = '");
        if (sys) {
            sys += strlen("error message = '");
            snprintf(buf, 256, "%.*s", (int)strcspn(sys, "'"), sys);
        } else {
            snprintf(buf, 256, "%s", e->desc);
        }
        return 1; /* the innermost message is enough */
    }
    return 0;
}

static herr_t capture_cb(hid_t estack, void *data) {
    char *buf = data;
    if (buf[0] == '\0') H5Ewalk2(estack, H5E_WALK_UPWARD, walk_cb, buf);
    return 0;
}

void h5md_quiet_on(quiet_t *q, char *detail) {
    q->fn = NULL;
    q->data = NULL;
    q->saved = H5Eget_auto2(H5E_DEFAULT, &q->fn, &q->data) >= 0;
    detail[0] = '\0';
    H5Eset_auto2(H5E_DEFAULT, capture_cb, detail);
}

void h5md_quiet_off(const quiet_t *q) {
    if (q->saved)
        H5Eset_auto2(H5E_DEFAULT, q->fn, q->data);
    else
        H5Eset_auto2(H5E_DEFAULT, NULL, NULL);
}

void h5md_set_err(char *err, size_t errlen, const char *fmt, ...) {
    if (!err || errlen == 0) return;
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(err, errlen, fmt, ap);
    va_end(ap);
    for (char *p = err; *p; ++p) /* keep it one line */
        if (*p == '\n' || *p == '\r') *p = ' ';
}

/* Message: "<what> (HDF5: <innermost description of the failure>)" or just "<what>". */
void h5md_err(const char *detail, char *err, size_t errlen, const char *fmt, ...) {
    char what[512];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(what, sizeof what, fmt, ap);
    va_end(ap);
    if (detail && detail[0])
        h5md_set_err(err, errlen, "%s (HDF5: %s)", what, detail);
    else
        h5md_set_err(err, errlen, "%s", what);
}

void h5md_close_id(hid_t *id) {
    if (*id < 0) return;
    switch (H5Iget_type(*id)) {
    case H5I_FILE: H5Fclose(*id); break;
    case H5I_GROUP: H5Gclose(*id); break;
    case H5I_DATASET: H5Dclose(*id); break;
    case H5I_DATASPACE: H5Sclose(*id); break;
    case H5I_DATATYPE: H5Tclose(*id); break;
    case H5I_ATTR: H5Aclose(*id); break;
    case H5I_GENPROP_LST: H5Pclose(*id); break;
    default: break;
    }
    *id = H5I_INVALID_HID;
}

/* ------------------------------------------------------------------------------------------ */
/* small HDF5 helpers; each returns 0 / -1 and leaves the HDF5 error stack for h5md_err */

hid_t h5md_str_type(size_t len) {
    return h5md_str_type_cset(len, H5T_CSET_UTF8);
}

hid_t h5md_str_type_cset(size_t len, H5T_cset_t cset) {
    hid_t t = H5Tcopy(H5T_C_S1);
    if (t < 0) return t;
    if (H5Tset_size(t, len + 1) < 0 || H5Tset_strpad(t, H5T_STR_NULLTERM) < 0 ||
        H5Tset_cset(t, cset) < 0) {
        H5Tclose(t);
        return H5I_INVALID_HID;
    }
    return t;
}

int h5md_attr_write(hid_t obj, const char *name, hid_t ftype, hid_t mtype, int rank,
                    const hsize_t *dims, const void *buf) {
    hid_t sp = rank ? H5Screate_simple(rank, dims, NULL) : H5Screate(H5S_SCALAR);
    if (sp < 0) return -1;
    hid_t a = H5Acreate2(obj, name, ftype, sp, H5P_DEFAULT, H5P_DEFAULT);
    int rc = (a >= 0 && H5Awrite(a, mtype, buf) >= 0) ? 0 : -1;
    if (a >= 0) H5Aclose(a);
    H5Sclose(sp);
    return rc;
}

/* ASCII when the text is (the units module requires ASCII unit strings), else UTF-8. */
int h5md_attr_str(hid_t obj, const char *name, const char *s) {
    H5T_cset_t cset = H5T_CSET_ASCII;
    for (const unsigned char *p = (const unsigned char *)s; *p; ++p)
        if (*p >= 0x80) cset = H5T_CSET_UTF8;
    hid_t t = h5md_str_type_cset(strlen(s), cset);
    if (t < 0) return -1;
    int rc = h5md_attr_write(obj, name, t, t, 0, NULL, s);
    H5Tclose(t);
    return rc;
}

int h5md_attr_read_str(hid_t obj, const char *name, char *out, size_t len) {
    if (len == 0 || H5Aexists(obj, name) <= 0) return -1;
    const hid_t a = H5Aopen(obj, name, H5P_DEFAULT);
    const hid_t t = a >= 0 ? H5Aget_type(a) : -1;
    const size_t n = t >= 0 && H5Tget_class(t) == H5T_STRING && H5Tis_variable_str(t) == 0
                         ? H5Tget_size(t) : 0;
    char *buf = n ? malloc(n + 1) : NULL;
    const int ok = buf && H5Aread(a, t, buf) >= 0;
    if (ok) {
        buf[n] = '\0';
        snprintf(out, len, "%s", buf);
    }
    free(buf);
    if (t >= 0) H5Tclose(t);
    if (a >= 0) H5Aclose(a);
    return ok ? 0 : -1;
}

int h5md_attr_int(hid_t obj, const char *name, int v) {
    return h5md_attr_write(obj, name, H5T_STD_I32LE, H5T_NATIVE_INT, 0, NULL, &v);
}

int h5md_attr_double(hid_t obj, const char *name, double v) {
    return h5md_attr_write(obj, name, H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, 0, NULL, &v);
}

hid_t h5md_group_create(hid_t loc, const char *name) {
    hid_t lcpl = H5Pcreate(H5P_LINK_CREATE);
    if (lcpl < 0) return lcpl;
    hid_t g = H5I_INVALID_HID;
    if (H5Pset_create_intermediate_group(lcpl, 1) >= 0)
        g = H5Gcreate2(loc, name, lcpl, H5P_DEFAULT, H5P_DEFAULT);
    H5Pclose(lcpl);
    return g;
}

/* Fixed-size 1-D dataset [n] written in one go. */
int h5md_dset_fixed(hid_t loc, const char *name, hid_t ftype, hid_t mtype, size_t n,
                    const void *buf, const char *unit) {
    hsize_t dims[1] = {(hsize_t)n};
    hid_t sp = H5Screate_simple(1, dims, NULL);
    if (sp < 0) return -1;
    hid_t d = H5Dcreate2(loc, name, ftype, sp, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    int rc = -1;
    if (d >= 0 && (n == 0 || buf == NULL || H5Dwrite(d, mtype, H5S_ALL, H5S_ALL, H5P_DEFAULT,
                                                     buf) >= 0))
        rc = 0;
    if (rc == 0 && unit) rc = h5md_attr_str(d, "unit", unit);
    if (d >= 0) H5Dclose(d);
    H5Sclose(sp);
    return rc;
}

/* Extendible dataset with zero frames: dims [0, rest...], maxdims [UNLIMITED, rest...]. */
hid_t h5md_dset_extendible(hid_t loc, const char *name, hid_t ftype, int rank,
                           const hsize_t *rest, const hsize_t *chunk) {
    hsize_t dims[3], maxd[3];
    dims[0] = 0;
    maxd[0] = H5S_UNLIMITED;
    for (int i = 1; i < rank; ++i) {
        dims[i] = rest[i - 1];
        /* a zero-sized fixed axis cannot be chunked; let it be unlimited then */
        maxd[i] = rest[i - 1] ? rest[i - 1] : H5S_UNLIMITED;
    }
    hid_t sp = H5Screate_simple(rank, dims, maxd);
    if (sp < 0) return sp;
    hid_t dcpl = H5Pcreate(H5P_DATASET_CREATE);
    hid_t d = H5I_INVALID_HID;
    if (dcpl >= 0 && H5Pset_chunk(dcpl, rank, chunk) >= 0)
        d = H5Dcreate2(loc, name, ftype, sp, H5P_DEFAULT, dcpl, H5P_DEFAULT);
    if (dcpl >= 0) H5Pclose(dcpl);
    H5Sclose(sp);
    return d;
}

/* Append one row (row index `at`) to an extendible dataset of rank 1..3. */
int h5md_append_row(hid_t d, hsize_t at, int rank, const hsize_t *rest, hid_t mtype,
                    const void *buf) {
    return h5md_append_rows(d, at, 1, rank, rest, mtype, buf);
}

int h5md_append_rows(hid_t d, hsize_t at, hsize_t n, int rank, const hsize_t *rest, hid_t mtype,
                     const void *buf) {
    hsize_t dims[3], start[3] = {0, 0, 0}, count[3];
    dims[0] = at + n;
    start[0] = at;
    count[0] = n;
    for (int i = 1; i < rank; ++i) dims[i] = count[i] = rest[i - 1];
    if (H5Dset_extent(d, dims) < 0) return -1;
    if (n == 0) return 0;
    hid_t fs = H5Dget_space(d);
    if (fs < 0) return -1;
    int rc = -1;
    hid_t ms = H5Screate_simple(rank, count, NULL);
    if (ms >= 0 && H5Sselect_hyperslab(fs, H5S_SELECT_SET, start, NULL, count, NULL) >= 0 &&
        H5Dwrite(d, mtype, ms, fs, H5P_DEFAULT, buf) >= 0)
        rc = 0;
    if (ms >= 0) H5Sclose(ms);
    H5Sclose(fs);
    return rc;
}
