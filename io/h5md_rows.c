/*
 * h5md_rows.c — the particle rows of the H5MD writer: the time-independent per-particle data
 * and, for a set that changes during the run, H5MD 1.1's time-dependent particle count.
 *
 * Fixed set: id, species, radius, mass are datasets [N].  Growing set: id is a time-dependent
 * element (id/value [F][N], HDF5 fill value -1, -1 in every empty row), species, radius and
 * mass are datasets [N] extended when rows are added (a row's particle never changes, so they
 * stay time-independent), and every per-particle value dataset is extendible along the particle
 * axis with fill value NaN: frames written before a row existed read NaN there, and so does an
 * empty row of a later frame (the writer writes NaN, whatever the caller's array holds).
 * For the sidecar each frame's live rows are kept as runs of consecutive rows.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "h5md_internal.h"


static hid_t growing_1d(hid_t loc, const char *name, hid_t ftype, hid_t mtype, const void *fill,
                        const char *unit) {
    const hsize_t dims[1] = {0}, maxd[1] = {H5S_UNLIMITED}, chunk[1] = {GROWING_CHUNK_ROWS};
    hid_t sp = H5Screate_simple(1, dims, maxd), dcpl = H5Pcreate(H5P_DATASET_CREATE);
    hid_t d = H5I_INVALID_HID;
    if (sp >= 0 && dcpl >= 0 && H5Pset_chunk(dcpl, 1, chunk) >= 0 &&
        H5Pset_fill_value(dcpl, mtype, fill) >= 0)
        d = H5Dcreate2(loc, name, ftype, sp, H5P_DEFAULT, dcpl, H5P_DEFAULT);
    h5md_close_id(&dcpl);
    h5md_close_id(&sp);
    if (d >= 0 && unit && h5md_attr_str(d, "unit", unit) < 0) h5md_close_id(&d);
    return d;
}

/* Write rows [from, to) of a 1-D dataset extended to `to`. */
static int write_1d(hid_t d, hsize_t from, hsize_t to, hid_t mtype, const void *buf) {
    if (H5Dset_extent(d, &to) < 0) return -1;
    if (to == from) return 0;
    const hsize_t count = to - from;
    hid_t fs = H5Dget_space(d), ms = H5Screate_simple(1, &count, NULL);
    int rc = (fs >= 0 && ms >= 0 &&
              H5Sselect_hyperslab(fs, H5S_SELECT_SET, &from, NULL, &count, NULL) >= 0 &&
              H5Dwrite(d, mtype, ms, fs, H5P_DEFAULT, buf) >= 0) ? 0 : -1;
    h5md_close_id(&ms);
    h5md_close_id(&fs);
    return rc;
}

int h5md_rows_create(h5md_rows *r, hid_t all, const jd_h5md_particles *p) {
    memset(r, 0, sizeof *r);
    r->species = r->radius = r->mass = r->id_grp = r->id_value = H5I_INVALID_HID;
    r->growing = p->growing;
    r->n = p->n;
    r->row_id = malloc((p->n ? p->n : 1) * sizeof *r->row_id);
    if (!r->row_id) return -1;
    if (p->n) memcpy(r->row_id, p->id, p->n * sizeof *r->row_id);
    if (!r->growing)
        return h5md_dset_fixed(all, "id", H5T_STD_I64LE, H5T_NATIVE_INT64, p->n, p->id, NULL) |
               h5md_dset_fixed(all, "species", H5T_STD_I32LE, H5T_NATIVE_INT32, p->n, p->species,
                               NULL) |
               h5md_dset_fixed(all, "radius", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, p->n, p->radius,
                               "m") |
               h5md_dset_fixed(all, "mass", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, p->n, p->mass,
                               "kg");
    const int32_t no_species = -1;
    const double nan = NAN;
    r->species = growing_1d(all, "species", H5T_STD_I32LE, H5T_NATIVE_INT32, &no_species, NULL);
    r->radius = growing_1d(all, "radius", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, &nan, "m");
    r->mass = growing_1d(all, "mass", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, &nan, "kg");
    if (r->species < 0 || r->radius < 0 || r->mass < 0) return -1;
    return write_1d(r->species, 0, p->n, H5T_NATIVE_INT32, p->species) |
           write_1d(r->radius, 0, p->n, H5T_NATIVE_DOUBLE, p->radius) |
           write_1d(r->mass, 0, p->n, H5T_NATIVE_DOUBLE, p->mass);
}

hid_t h5md_rows_value(const h5md_rows *r, hid_t grp, const hsize_t chunk[3]) {
    if (!r->growing) {
        const hsize_t rest[2] = {(hsize_t)r->n, 3};
        return h5md_dset_extendible(grp, "value", H5T_IEEE_F64LE, 3, rest, chunk);
    }
    const hsize_t dims[3] = {0, r->n, 3}, maxd[3] = {H5S_UNLIMITED, H5S_UNLIMITED, 3};
    const double nan = NAN;
    hid_t sp = H5Screate_simple(3, dims, maxd), dcpl = H5Pcreate(H5P_DATASET_CREATE);
    hid_t d = H5I_INVALID_HID;
    if (sp >= 0 && dcpl >= 0 && H5Pset_chunk(dcpl, 3, chunk) >= 0 &&
        H5Pset_fill_value(dcpl, H5T_NATIVE_DOUBLE, &nan) >= 0)
        d = H5Dcreate2(grp, "value", H5T_IEEE_F64LE, sp, H5P_DEFAULT, dcpl, H5P_DEFAULT);
    h5md_close_id(&dcpl);
    h5md_close_id(&sp);
    return d;
}

int h5md_rows_setup(h5md_rows *r, hid_t all, hid_t position) {
    if (!r->growing) return 0;
    r->id_grp = H5Gcreate2(all, "id", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    if (r->id_grp < 0) return -1;
    const hsize_t dims[2] = {0, r->n}, maxd[2] = {H5S_UNLIMITED, H5S_UNLIMITED};
    const hsize_t chunk[2] = {16, r->n > GROWING_CHUNK_ROWS ? r->n : GROWING_CHUNK_ROWS};
    const int64_t none = -1;
    hid_t sp = H5Screate_simple(2, dims, maxd), dcpl = H5Pcreate(H5P_DATASET_CREATE);
    if (sp >= 0 && dcpl >= 0 && H5Pset_chunk(dcpl, 2, chunk) >= 0 &&
        H5Pset_fill_value(dcpl, H5T_NATIVE_INT64, &none) >= 0)
        r->id_value = H5Dcreate2(r->id_grp, "value", H5T_STD_I64LE, sp, H5P_DEFAULT, dcpl,
                                 H5P_DEFAULT);
    h5md_close_id(&dcpl);
    h5md_close_id(&sp);
    if (r->id_value < 0) return -1;
    return H5Lcreate_hard(position, "step", r->id_grp, "step", H5P_DEFAULT, H5P_DEFAULT) < 0 ||
                   H5Lcreate_hard(position, "time", r->id_grp, "time", H5P_DEFAULT,
                                  H5P_DEFAULT) < 0
               ? -1
               : 0;
}

/* The frame's live runs, appended to r->runs. */
static int record_runs(h5md_rows *r, const int64_t *id, size_t n) {
    if (r->nframes + 2 > r->frame_cap) {
        const size_t cap = r->frame_cap ? 2 * r->frame_cap : 64;
        size_t *fr = realloc(r->frame_runs, cap * sizeof *fr);
        if (!fr) return -1;
        r->frame_runs = fr;
        r->frame_cap = cap;
        if (r->nframes == 0) r->frame_runs[0] = 0;
    }
    for (size_t i = 0; i < n;) {
        if (id && id[i] < 0) {
            i++;
            continue;
        }
        size_t j = i + 1;
        while (j < n && !(id && id[j] < 0)) j++;
        if (r->nruns == r->runs_cap) {
            const size_t cap = r->runs_cap ? 2 * r->runs_cap : 64;
            xdmf_run *more = realloc(r->runs, cap * sizeof *more);
            if (!more) return -1;
            r->runs = more;
            r->runs_cap = cap;
        }
        r->runs[r->nruns++] = (xdmf_run){i, j - i};
        i = j;
    }
    r->frame_runs[++r->nframes] = r->nruns;
    return 0;
}

int h5md_rows_frame(h5md_rows *r, const jd_h5md_frame *f, hsize_t frame, char *why,
                    size_t whylen) {
    if (!r->growing) return record_runs(r, NULL, r->n);
    const jd_h5md_particles *p = f->rows;
    if (!p || p->n < r->n || (p->n && !p->id)) {
        snprintf(why, whylen, "frame at step %lld of a growing set %s", (long long)f->step,
                 !p ? "has no rows" : p->n < r->n ? "has fewer rows than the previous frame"
                                                  : "has no ids");
        return -1;
    }
    for (size_t i = 0; i < r->n; i++)
        if (p->id[i] >= 0 && p->id[i] != r->row_id[i]) {
            snprintf(why, whylen, "row %zu holds particle %lld at step %lld, particle %lld before "
                     "(a row keeps its particle)", i, (long long)p->id[i], (long long)f->step,
                     (long long)r->row_id[i]);
            return -1;
        }
    const size_t from = r->n;
    if (p->n > from) {
        int64_t *ids = realloc(r->row_id, p->n * sizeof *ids);
        double *scratch = realloc(r->scratch, 3 * p->n * sizeof *scratch);
        if (ids) r->row_id = ids;
        if (scratch) r->scratch = scratch;
        if (!ids || !scratch || !p->species || !p->radius || !p->mass) {
            snprintf(why, whylen, "%s", !ids || !scratch ? "out of memory" :
                     "new rows without species, radius or mass");
            return -1;
        }
        memcpy(r->row_id + from, p->id + from, (p->n - from) * sizeof *ids);
        if (write_1d(r->species, from, p->n, H5T_NATIVE_INT32, p->species + from) < 0 ||
            write_1d(r->radius, from, p->n, H5T_NATIVE_DOUBLE, p->radius + from) < 0 ||
            write_1d(r->mass, from, p->n, H5T_NATIVE_DOUBLE, p->mass + from) < 0) {
            snprintf(why, whylen, "cannot add rows to species/radius/mass");
            return -1;
        }
        r->n = p->n;
    } else if (!r->scratch && !(r->scratch = malloc(3 * (r->n ? r->n : 1) * sizeof *r->scratch))) {
        snprintf(why, whylen, "out of memory");
        return -1;
    }
    const hsize_t rest[1] = {r->n};
    if (h5md_append_row(r->id_value, frame, 2, rest, H5T_NATIVE_INT64, p->id) < 0) {
        snprintf(why, whylen, "cannot append id");
        return -1;
    }
    if (record_runs(r, p->id, r->n) < 0) {
        snprintf(why, whylen, "out of memory");
        return -1;
    }
    r->frame_id = p->id;
    return 0;
}

const double *h5md_rows_vector(h5md_rows *r, const double *v) {
    if (!r->growing) return v;
    memcpy(r->scratch, v, 3 * r->n * sizeof *v);
    for (size_t i = 0; i < r->n; i++)
        if (r->frame_id[i] < 0) r->scratch[3 * i] = r->scratch[3 * i + 1] = r->scratch[3 * i + 2] = NAN;
    return r->scratch;
}

void h5md_rows_close(h5md_rows *r) {
    h5md_close_id(&r->species);
    h5md_close_id(&r->radius);
    h5md_close_id(&r->mass);
    h5md_close_id(&r->id_value);
    h5md_close_id(&r->id_grp);
}

void h5md_rows_free(h5md_rows *r) {
    h5md_rows_close(r);
    free(r->row_id);
    free(r->scratch);
    free(r->runs);
    free(r->frame_runs);
    memset(r, 0, sizeof *r);
}
