/*
 * h5md.c — H5MD 1.1 trajectory writer with an XDMF 3 sidecar (see h5md.h for the layout).
 *
 * Engine-neutral: plain C11 on the serial HDF5 C API, no global state of its own (each jd_h5md
 * owns its handles; two writers may be open at once).  HDF5's automatic error printing is
 * replaced by a silent capturing handler for the duration of each public call (the caller's
 * handler is restored on return), so the only diagnostics are the one-line messages written
 * into `err`.
 *
 * Design notes
 *  - File format: default (earliest) library-version bounds.  That keeps superblock v0 without
 *    the v3 "file open for writing" status flag, so a PATH.part left by a killed run opens
 *    directly (no h5clear) in any HDF5 1.8+/1.10+ reader, including ParaView's bundled one.
 *  - Chunking of value [F][N][3]: rows of one frame are contiguous.  We aim at chunks of about
 *    256 KiB (well inside HDF5's default 1 MiB per-dataset chunk cache, so a chunk shared by
 *    several frames stays cached while it fills up): for small N up to 64 frames share
 *    a chunk (fewer, larger I/Os and B-tree entries, while a short run of a few particles does
 *    not allocate much: chunks are allocated whole), for N >= ~11k a chunk holds one frame, and
 *    for very large N (> 4 MiB per frame) the particle axis is split as well so a chunk stays
 *    below ~4 MiB (partial reads stay cheap).  step/time use 1-D chunks of 512 entries,
 *    observables 256.  No compression: DEM coordinates compress poorly and it would slow every
 *    flush.
 *  - step and time are written once under position/ and hard-linked into the other
 *    time-dependent groups (explicitly allowed by H5MD 1.1; readers see ordinary datasets).
 *  - Strings: attributes are fixed-length, NUL-terminated UTF-8 (the box boundary is a
 *    fixed-length string array [3]); /parameters/scene is a scalar variable-length UTF-8
 *    dataset (the YAML text can be arbitrarily long).
 *  - XDMF sidecar: Xdmf3 (unlike the old Xdmf2 reader) does not invent connectivity for a
 *    Polyvertex topology, so the 0..N-1 list is written inline once, in the first frame's
 *    grid, and the other frames xi:include that Topology.  Geometry and the vector attributes
 *    are HyperSlabs [frame, 0, 0] x [1, N, 3] of the .h5 (referenced by basename).
 *  - Every frame is followed by H5Fflush, and so is every observable batch (the samples that
 *    share one step): it is flushed when the next batch starts, with the next frame, or at
 *    close.  A killed run thus leaves a readable PATH.part with every frame and every complete
 *    observable batch (at most the batch being written at the time of the kill is missing).
 *    H5Fflush hands the data to the OS (no fsync): this protects against a killed process, not
 *    against a machine crash.
 */
#include "h5md.h"

#include <errno.h>
#include <fcntl.h>
#include <hdf5.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

enum { TD_POSITION, TD_VELOCITY, TD_ANGVEL, TD_FORCE, TD_TORQUE, TD_COUNT };

static const char *const td_name[TD_COUNT] = {"position", "velocity", "angular_velocity", "force",
                                              "torque"};
static const char *const td_unit[TD_COUNT] = {"m", "m s-1", "s-1", "N", "N m"};

typedef struct obs {
    char *name;
    hid_t grp, step, time, value;
    hsize_t count;
} obs;

struct jd_h5md {
    char *path; /* final name */
    char *part; /* PATH.part */
    hid_t file;
    hid_t all; /* /particles/all */
    size_t n;
    int decided;             /* groups fixed at the first frame */
    int present[TD_COUNT];   /* which time-dependent groups this run writes */
    hid_t grp[TD_COUNT];     /* group ids (H5I_INVALID_HID when absent) */
    hid_t value[TD_COUNT];   /* value datasets */
    hid_t step_ds, time_ds;  /* shared step/time (position/), hard-linked elsewhere */
    hsize_t nframes;
    double *times; /* per frame, for the XDMF sidecar */
    size_t cap;
    obs *obs;
    size_t nobs, obs_cap;
    int broken; /* a failed write left datasets inconsistent: refuse further writes */
    char h5detail[256]; /* innermost HDF5 error of the current call (see capture_cb) */
    int obs_dirty;      /* observable samples written since the last flush ... */
    int64_t obs_step;   /* ... all of them at this step (the current batch) */
};

/* ------------------------------------------------------------------------------------------ */
/* error handling */

/* While a public call runs, HDF5's automatic error handler is replaced by capture_cb, which
 * prints nothing and records the innermost description of the first failure into the writer's
 * `h5detail` (client data, no globals); the caller's handler is restored on return.  Capturing
 * at the API boundary matters: the cleanup calls after a failure reset HDF5's error stack. */
typedef struct {
    H5E_auto2_t fn;
    void *data;
    int saved; /* 0 if the caller's handler could not be read (e.g. set with H5Eset_auto1) */
} quiet_t;

static herr_t walk_cb(unsigned n, const H5E_error2_t *e, void *data) {
    char *buf = data;
    if (n == 0 && e && e->desc) {
        snprintf(buf, 256, "%s", e->desc);
        return 1; /* the innermost message is enough */
    }
    return 0;
}

static herr_t capture_cb(hid_t estack, void *data) {
    char *buf = data;
    if (buf[0] == '\0') H5Ewalk2(estack, H5E_WALK_UPWARD, walk_cb, buf);
    return 0;
}

static void quiet_on(quiet_t *q, char *detail) {
    q->fn = NULL;
    q->data = NULL;
    q->saved = H5Eget_auto2(H5E_DEFAULT, &q->fn, &q->data) >= 0;
    detail[0] = '\0';
    H5Eset_auto2(H5E_DEFAULT, capture_cb, detail);
}

static void quiet_off(const quiet_t *q) {
    if (q->saved)
        H5Eset_auto2(H5E_DEFAULT, q->fn, q->data);
    else
        H5Eset_auto2(H5E_DEFAULT, NULL, NULL);
}

static void set_err(char *err, size_t errlen, const char *fmt, ...) {
    if (!err || errlen == 0) return;
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(err, errlen, fmt, ap);
    va_end(ap);
    for (char *p = err; *p; ++p) /* keep it one line */
        if (*p == '\n' || *p == '\r') *p = ' ';
}

/* Message: "<what> (HDF5: <innermost description of the failure>)" or just "<what>". */
static void h5_err(const char *detail, char *err, size_t errlen, const char *fmt, ...) {
    char what[512];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(what, sizeof what, fmt, ap);
    va_end(ap);
    if (detail && detail[0])
        set_err(err, errlen, "%s (HDF5: %s)", what, detail);
    else
        set_err(err, errlen, "%s", what);
}

static void close_id(hid_t *id) {
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
/* small HDF5 helpers; each returns 0 / -1 and leaves the HDF5 error stack for h5_err */

static hid_t str_type(size_t len) {
    hid_t t = H5Tcopy(H5T_C_S1);
    if (t < 0) return t;
    if (H5Tset_size(t, len + 1) < 0 || H5Tset_strpad(t, H5T_STR_NULLTERM) < 0 ||
        H5Tset_cset(t, H5T_CSET_UTF8) < 0) {
        H5Tclose(t);
        return H5I_INVALID_HID;
    }
    return t;
}

static int attr_write(hid_t obj, const char *name, hid_t ftype, hid_t mtype, int rank,
                      const hsize_t *dims, const void *buf) {
    hid_t sp = rank ? H5Screate_simple(rank, dims, NULL) : H5Screate(H5S_SCALAR);
    if (sp < 0) return -1;
    hid_t a = H5Acreate2(obj, name, ftype, sp, H5P_DEFAULT, H5P_DEFAULT);
    int rc = (a >= 0 && H5Awrite(a, mtype, buf) >= 0) ? 0 : -1;
    if (a >= 0) H5Aclose(a);
    H5Sclose(sp);
    return rc;
}

static int attr_str(hid_t obj, const char *name, const char *s) {
    hid_t t = str_type(strlen(s));
    if (t < 0) return -1;
    int rc = attr_write(obj, name, t, t, 0, NULL, s);
    H5Tclose(t);
    return rc;
}

static int attr_int(hid_t obj, const char *name, int v) {
    return attr_write(obj, name, H5T_STD_I32LE, H5T_NATIVE_INT, 0, NULL, &v);
}

static int attr_double(hid_t obj, const char *name, double v) {
    return attr_write(obj, name, H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, 0, NULL, &v);
}

static hid_t group_create(hid_t loc, const char *name) {
    hid_t lcpl = H5Pcreate(H5P_LINK_CREATE);
    if (lcpl < 0) return lcpl;
    hid_t g = H5I_INVALID_HID;
    if (H5Pset_create_intermediate_group(lcpl, 1) >= 0)
        g = H5Gcreate2(loc, name, lcpl, H5P_DEFAULT, H5P_DEFAULT);
    H5Pclose(lcpl);
    return g;
}

/* Fixed-size 1-D dataset [n] written in one go. */
static int dset_fixed(hid_t loc, const char *name, hid_t ftype, hid_t mtype, size_t n,
                      const void *buf, const char *unit) {
    hsize_t dims[1] = {(hsize_t)n};
    hid_t sp = H5Screate_simple(1, dims, NULL);
    if (sp < 0) return -1;
    hid_t d = H5Dcreate2(loc, name, ftype, sp, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    int rc = -1;
    if (d >= 0 && (n == 0 || buf == NULL || H5Dwrite(d, mtype, H5S_ALL, H5S_ALL, H5P_DEFAULT,
                                                     buf) >= 0))
        rc = 0;
    if (rc == 0 && unit) rc = attr_str(d, "unit", unit);
    if (d >= 0) H5Dclose(d);
    H5Sclose(sp);
    return rc;
}

/* Extendible dataset with zero frames: dims [0, rest...], maxdims [UNLIMITED, rest...]. */
static hid_t dset_extendible(hid_t loc, const char *name, hid_t ftype, int rank,
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
static int append_row(hid_t d, hsize_t at, int rank, const hsize_t *rest, hid_t mtype,
                      const void *buf) {
    hsize_t dims[3], start[3] = {0, 0, 0}, count[3];
    dims[0] = at + 1;
    start[0] = at;
    count[0] = 1;
    for (int i = 1; i < rank; ++i) dims[i] = count[i] = rest[i - 1];
    if (H5Dset_extent(d, dims) < 0) return -1;
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

/* ------------------------------------------------------------------------------------------ */

static void free_handle(jd_h5md *h) {
    for (size_t i = 0; i < h->nobs; ++i) {
        close_id(&h->obs[i].step);
        close_id(&h->obs[i].time);
        close_id(&h->obs[i].value);
        close_id(&h->obs[i].grp);
        free(h->obs[i].name);
    }
    for (int k = 0; k < TD_COUNT; ++k) {
        close_id(&h->value[k]);
        close_id(&h->grp[k]);
    }
    close_id(&h->step_ds);
    close_id(&h->time_ds);
    close_id(&h->all);
    close_id(&h->file);
    free(h->obs);
    free(h->times);
    free(h->path);
    free(h->part);
    free(h);
}

static int write_header(jd_h5md *h, const jd_h5md_meta *meta, const jd_h5md_particles *p,
                        char *err, size_t errlen) {
    const char *creator = (meta && meta->creator) ? meta->creator : "jdem";
    const char *cver = (meta && meta->creator_version) ? meta->creator_version : "unknown";
    const char *where = "/h5md";
    hid_t g = H5I_INVALID_HID, g2 = H5I_INVALID_HID;

    /* /h5md */
    g = H5Gcreate2(h->file, "h5md", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    if (g < 0) goto fail;
    {
        int version[2] = {1, 1};
        hsize_t two = 2;
        if (attr_write(g, "version", H5T_STD_I32LE, H5T_NATIVE_INT, 1, &two, version) < 0)
            goto fail;
    }
    where = "/h5md/author";
    g2 = H5Gcreate2(g, "author", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    if (g2 < 0 || attr_str(g2, "name", "jdem developers") < 0) goto fail;
    close_id(&g2);
    where = "/h5md/creator";
    g2 = H5Gcreate2(g, "creator", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    if (g2 < 0 || attr_str(g2, "name", creator) < 0 || attr_str(g2, "version", cver) < 0)
        goto fail;
    close_id(&g2);
    close_id(&g);

    /* /parameters */
    where = "/parameters";
    g = H5Gcreate2(h->file, "parameters", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    if (g < 0) goto fail;
    if (meta) {
        if (meta->creator && attr_str(g, "engine", meta->creator) < 0) goto fail;
        if (meta->scene_name && attr_str(g, "scene_name", meta->scene_name) < 0) goto fail;
        if (meta->case_name && attr_str(g, "case_name", meta->case_name) < 0) goto fail;
        if (attr_double(g, "dt", meta->dt) < 0) goto fail;
        if (meta->scene_yaml) {
            where = "/parameters/scene";
            hid_t t = H5Tcopy(H5T_C_S1);
            hid_t sp = H5Screate(H5S_SCALAR);
            hid_t d = H5I_INVALID_HID;
            int rc = -1;
            if (t >= 0 && sp >= 0 && H5Tset_size(t, H5T_VARIABLE) >= 0 &&
                H5Tset_cset(t, H5T_CSET_UTF8) >= 0) {
                d = H5Dcreate2(g, "scene", t, sp, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
                if (d >= 0 && H5Dwrite(d, t, H5S_ALL, H5S_ALL, H5P_DEFAULT, &meta->scene_yaml) >= 0)
                    rc = 0;
            }
            close_id(&d);
            close_id(&sp);
            close_id(&t);
            if (rc < 0) goto fail;
        }
    }
    close_id(&g);

    /* /particles/all and its box */
    where = "/particles/all";
    h->all = group_create(h->file, "particles/all");
    if (h->all < 0) goto fail;
    where = "/particles/all/box";
    g = H5Gcreate2(h->all, "box", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    if (g < 0 || attr_int(g, "dimension", 3) < 0) goto fail;
    {
        char boundary[3][5] = {"none", "none", "none"};
        hsize_t three = 3;
        hid_t t = str_type(4);
        int rc = t >= 0 ? attr_write(g, "boundary", t, t, 1, &three, boundary) : -1;
        close_id(&t);
        if (rc < 0) goto fail;
    }
    close_id(&g);

    /* time-independent per-particle data */
    where = "/particles/all/id";
    if (dset_fixed(h->all, "id", H5T_STD_I64LE, H5T_NATIVE_INT64, p->n, p->id, NULL) < 0)
        goto fail;
    where = "/particles/all/species";
    if (dset_fixed(h->all, "species", H5T_STD_I32LE, H5T_NATIVE_INT32, p->n, p->species, NULL) <
        0)
        goto fail;
    where = "/particles/all/radius";
    if (dset_fixed(h->all, "radius", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, p->n, p->radius, "m") <
        0)
        goto fail;
    where = "/particles/all/mass";
    if (dset_fixed(h->all, "mass", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, p->n, p->mass, "kg") < 0)
        goto fail;
    return 0;

fail:
    h5_err(h->h5detail, err, errlen, "cannot write %s in '%s'", where, h->part);
    close_id(&g2);
    close_id(&g);
    return -1;
}

jd_h5md *jd_h5md_create(const char *path, const jd_h5md_meta *meta,
                        const jd_h5md_particles *particles, char *err, size_t errlen) {
    if (!path || !*path || !particles) {
        set_err(err, errlen, "h5md: missing path or particle description");
        return NULL;
    }
    if (particles->n > 0 && (!particles->id || !particles->species || !particles->radius ||
                             !particles->mass)) {
        set_err(err, errlen, "h5md: particle arrays id/species/radius/mass must all be given");
        return NULL;
    }
    for (size_t i = 1; i < particles->n; ++i)
        if (particles->id[i] <= particles->id[i - 1]) {
            set_err(err, errlen,
                    "h5md: particle ids must be sorted ascending and unique (id %lld at index "
                    "%zu follows %lld)",
                    (long long)particles->id[i], i, (long long)particles->id[i - 1]);
            return NULL;
        }
    jd_h5md *h = calloc(1, sizeof *h);
    if (!h) {
        set_err(err, errlen, "h5md: out of memory");
        return NULL;
    }
    h->file = h->all = h->step_ds = h->time_ds = H5I_INVALID_HID;
    for (int k = 0; k < TD_COUNT; ++k) h->grp[k] = h->value[k] = H5I_INVALID_HID;
    h->n = particles->n;
    size_t len = strlen(path);
    h->path = malloc(len + 1);
    h->part = malloc(len + 6);
    if (!h->path || !h->part) {
        set_err(err, errlen, "h5md: out of memory");
        free_handle(h);
        return NULL;
    }
    memcpy(h->path, path, len + 1);
    memcpy(h->part, path, len);
    memcpy(h->part + len, ".part", 6);

    /* Probe with open(2) first: HDF5's own message for a missing directory is verbose. */
    int fd = open(h->part, O_WRONLY | O_CREAT | O_TRUNC, 0666);
    if (fd < 0) {
        set_err(err, errlen, "cannot create '%s': %s", h->part, strerror(errno));
        free_handle(h);
        return NULL;
    }
    close(fd);

    quiet_t q;
    quiet_on(&q, h->h5detail);
    h->file = H5Fcreate(h->part, H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
    if (h->file < 0) {
        h5_err(h->h5detail, err, errlen, "cannot create '%s'", h->part);
        goto fail;
    }
    if (write_header(h, meta, particles, err, errlen) < 0) goto fail;
    if (H5Fflush(h->file, H5F_SCOPE_LOCAL) < 0) {
        h5_err(h->h5detail, err, errlen, "cannot flush '%s'", h->part);
        goto fail;
    }
    quiet_off(&q);
    return h;

fail:
    {
        char *part = h->part;
        h->part = NULL;
        free_handle(h);
        unlink(part); /* nothing useful in a half-created file */
        free(part);
    }
    quiet_off(&q);
    return NULL;
}

/* Chunk of value [F][N][3]: ~256 KiB, see the note at the top. */
static void value_chunk(size_t n, hsize_t chunk[3]) {
    const size_t target = 256u * 1024u, maxbytes = 4u * 1024u * 1024u;
    size_t row = (n ? n : 1) * 3 * sizeof(double);
    size_t frames = row >= target ? 1 : target / row;
    if (frames > 64) frames = 64; /* short runs of few particles stay small */
    size_t pn = n ? n : 1;
    if (row > maxbytes) pn = maxbytes / (3 * sizeof(double));
    chunk[0] = frames;
    chunk[1] = pn;
    chunk[2] = 3;
}

static int setup_groups(jd_h5md *h, const jd_h5md_frame *f, char *err, size_t errlen) {
    const double *arr[TD_COUNT] = {f->position, f->velocity, f->angular_velocity, f->force,
                                   f->torque};
    hsize_t rest[2] = {(hsize_t)h->n, 3}, vchunk[3], schunk[1] = {512};
    value_chunk(h->n, vchunk);
    for (int k = 0; k < TD_COUNT; ++k) {
        h->present[k] = arr[k] != NULL;
        if (!h->present[k]) continue;
        const char *what = "group";
        h->grp[k] = H5Gcreate2(h->all, td_name[k], H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
        if (h->grp[k] < 0) goto fail;
        what = "value";
        h->value[k] = dset_extendible(h->grp[k], "value", H5T_IEEE_F64LE, 3, rest, vchunk);
        if (h->value[k] < 0 || attr_str(h->value[k], "unit", td_unit[k]) < 0) goto fail;
        if (k == TD_POSITION) {
            what = "step";
            h->step_ds = dset_extendible(h->grp[k], "step", H5T_STD_I64LE, 1, NULL, schunk);
            if (h->step_ds < 0) goto fail;
            what = "time";
            h->time_ds = dset_extendible(h->grp[k], "time", H5T_IEEE_F64LE, 1, NULL, schunk);
            if (h->time_ds < 0 || attr_str(h->time_ds, "unit", "s") < 0) goto fail;
        } else {
            what = "step/time links";
            if (H5Lcreate_hard(h->grp[TD_POSITION], "step", h->grp[k], "step", H5P_DEFAULT,
                               H5P_DEFAULT) < 0 ||
                H5Lcreate_hard(h->grp[TD_POSITION], "time", h->grp[k], "time", H5P_DEFAULT,
                               H5P_DEFAULT) < 0)
                goto fail;
        }
        continue;
    fail:
        h5_err(h->h5detail, err, errlen, "cannot create %s of /particles/all/%s in '%s'", what,
               td_name[k], h->part);
        h->broken = 1;
        return -1;
    }
    h->decided = 1;
    return 0;
}

int jd_h5md_write_frame(jd_h5md *h, const jd_h5md_frame *frame, char *err, size_t errlen) {
    if (!h || !frame) {
        set_err(err, errlen, "h5md: no writer or frame");
        return -1;
    }
    if (h->broken) {
        set_err(err, errlen, "h5md: '%s' is unusable after an earlier write error", h->part);
        return -1;
    }
    if (!frame->position) {
        set_err(err, errlen, "h5md: frame at step %lld has no positions", (long long)frame->step);
        return -1;
    }
    const double *arr[TD_COUNT] = {frame->position, frame->velocity, frame->angular_velocity,
                                   frame->force, frame->torque};
    if (h->decided) {
        for (int k = 0; k < TD_COUNT; ++k)
            if (h->present[k] != (arr[k] != NULL)) {
                set_err(err, errlen,
                        "h5md: frame at step %lld %s %s, unlike the first frame of '%s'",
                        (long long)frame->step, h->present[k] ? "lacks" : "adds", td_name[k],
                        h->part);
                return -1;
            }
    }
    if (h->nframes == h->cap) { /* grow the in-memory time list (XDMF needs it) */
        size_t cap = h->cap ? 2 * h->cap : 64;
        double *t = realloc(h->times, cap * sizeof *t);
        if (!t) goto oom;
        h->times = t;
        h->cap = cap;
    }

    quiet_t q;
    quiet_on(&q, h->h5detail);
    if (!h->decided && setup_groups(h, frame, err, errlen) < 0) {
        quiet_off(&q);
        return -1;
    }
    hsize_t rest[2] = {(hsize_t)h->n, 3};
    const char *what = "value";
    for (int k = 0; k < TD_COUNT; ++k) {
        if (!h->present[k]) continue;
        if (append_row(h->value[k], h->nframes, 3, rest, H5T_NATIVE_DOUBLE, arr[k]) < 0) {
            what = td_name[k];
            goto fail;
        }
    }
    /* step/time last: a reader that trusts len(step) never sees a half-written frame */
    what = "step";
    if (append_row(h->step_ds, h->nframes, 1, NULL, H5T_NATIVE_INT64, &frame->step) < 0)
        goto fail;
    what = "time";
    if (append_row(h->time_ds, h->nframes, 1, NULL, H5T_NATIVE_DOUBLE, &frame->time) < 0)
        goto fail;
    if (H5Fflush(h->file, H5F_SCOPE_LOCAL) < 0) {
        h5_err(h->h5detail, err, errlen, "cannot flush '%s' after step %lld", h->part,
               (long long)frame->step);
        h->broken = 1;
        quiet_off(&q);
        return -1;
    }
    h->times[h->nframes] = frame->time;
    h->nframes++;
    h->obs_dirty = 0; /* the flush covered pending observable samples too */
    quiet_off(&q);
    return 0;

fail:
    h5_err(h->h5detail, err, errlen, "cannot append %s of step %lld to '%s'", what,
           (long long)frame->step, h->part);
    h->broken = 1;
    quiet_off(&q);
    return -1;
oom:
    set_err(err, errlen, "h5md: out of memory");
    return -1;
}

static int valid_obs_name(const char *name) {
    if (!name || !*name || name[0] == '/' || name[strlen(name) - 1] == '/') return 0;
    if (strlen(name) > 900) return 0; /* fits "observables/NAME" in the path buffer */
    for (const char *p = name; *p; ++p) {
        if (*p == '/' && p[1] == '/') return 0;
        if ((p == name || p[-1] == '/') && p[0] == '.' && (p[1] == '/' || p[1] == '\0'))
            return 0; /* "." components */
    }
    return 1;
}

int jd_h5md_write_observable(jd_h5md *h, const char *name, int64_t step, double time,
                             double value, char *err, size_t errlen) {
    if (!h) {
        set_err(err, errlen, "h5md: no writer");
        return -1;
    }
    if (!valid_obs_name(name)) {
        set_err(err, errlen, "h5md: invalid observable name '%s'", name ? name : "(null)");
        return -1;
    }
    if (h->broken) {
        set_err(err, errlen, "h5md: '%s' is unusable after an earlier write error", h->part);
        return -1;
    }
    obs *o = NULL;
    for (size_t i = 0; i < h->nobs; ++i)
        if (strcmp(h->obs[i].name, name) == 0) {
            o = &h->obs[i];
            break;
        }
    quiet_t q;
    quiet_on(&q, h->h5detail);
    const char *what = "(flush of the previous batch)";
    /* A batch is the run of samples with one step.  A new step means the previous batch is
     * complete: flush it now (one flush per batch instead of per sample, ~4x cheaper). */
    if (h->obs_dirty && step != h->obs_step) {
        if (H5Fflush(h->file, H5F_SCOPE_LOCAL) < 0) goto fail;
        h->obs_dirty = 0;
    }
    what = "group";
    if (!o) {
        if (h->nobs == h->obs_cap) {
            size_t cap = h->obs_cap ? 2 * h->obs_cap : 8;
            obs *no = realloc(h->obs, cap * sizeof *no);
            if (!no) {
                set_err(err, errlen, "h5md: out of memory");
                quiet_off(&q);
                return -1;
            }
            h->obs = no;
            h->obs_cap = cap;
        }
        o = &h->obs[h->nobs];
        memset(o, 0, sizeof *o);
        o->grp = o->step = o->time = o->value = H5I_INVALID_HID;
        o->name = malloc(strlen(name) + 1);
        if (!o->name) {
            set_err(err, errlen, "h5md: out of memory");
            quiet_off(&q);
            return -1;
        }
        strcpy(o->name, name);
        h->nobs++; /* registered now so that free_handle closes whatever gets opened */
        char gname[1024];
        snprintf(gname, sizeof gname, "observables/%s", name);
        hsize_t chunk[1] = {256};
        o->grp = group_create(h->file, gname);
        if (o->grp < 0) goto fail_create;
        what = "step";
        o->step = dset_extendible(o->grp, "step", H5T_STD_I64LE, 1, NULL, chunk);
        if (o->step < 0) goto fail_create;
        what = "time";
        o->time = dset_extendible(o->grp, "time", H5T_IEEE_F64LE, 1, NULL, chunk);
        if (o->time < 0 || attr_str(o->time, "unit", "s") < 0) goto fail_create;
        what = "value";
        o->value = dset_extendible(o->grp, "value", H5T_IEEE_F64LE, 1, NULL, chunk);
        if (o->value < 0) goto fail_create;
    }
    what = "value";
    if (append_row(o->value, o->count, 1, NULL, H5T_NATIVE_DOUBLE, &value) < 0) goto fail;
    what = "step";
    if (append_row(o->step, o->count, 1, NULL, H5T_NATIVE_INT64, &step) < 0) goto fail;
    what = "time";
    if (append_row(o->time, o->count, 1, NULL, H5T_NATIVE_DOUBLE, &time) < 0) goto fail;
    o->count++;
    h->obs_dirty = 1;
    h->obs_step = step;
    quiet_off(&q);
    return 0;

fail_create:
    /* nothing appended yet: forget this observable, the writer stays usable */
    h5_err(h->h5detail, err, errlen, "cannot create /observables/%s (%s) in '%s'", name, what,
           h->part);
    close_id(&o->step);
    close_id(&o->time);
    close_id(&o->value);
    close_id(&o->grp);
    free(o->name);
    h->nobs--;
    quiet_off(&q);
    return -1;
fail:
    h5_err(h->h5detail, err, errlen, "cannot write /observables/%s %s at step %lld in '%s'",
           name, what, (long long)step, h->part);
    h->broken = 1;
    quiet_off(&q);
    return -1;
}

/* ------------------------------------------------------------------------------------------ */
/* XDMF sidecar */

static void xml_escaped(FILE *fp, const char *s) {
    for (; *s; ++s) {
        switch (*s) {
        case '&': fputs("&amp;", fp); break;
        case '<': fputs("&lt;", fp); break;
        case '>': fputs("&gt;", fp); break;
        case '"': fputs("&quot;", fp); break;
        case '\'': fputs("&apos;", fp); break;
        default: fputc(*s, fp);
        }
    }
}

/* PATH with its extension replaced by .xdmf (only the last one: a.jdem.h5 -> a.jdem.xdmf). */
static char *xdmf_path(const char *path) {
    const char *slash = strrchr(path, '/');
    const char *base = slash ? slash + 1 : path;
    const char *dot = strrchr(base, '.');
    size_t stem = (dot && dot != base) ? (size_t)(dot - path) : strlen(path);
    char *x = malloc(stem + 6);
    if (!x) return NULL;
    memcpy(x, path, stem);
    memcpy(x + stem, ".xdmf", 6);
    return x;
}

static void xdmf_hdf_item(FILE *fp, const char *file, const char *dset, const char *dims,
                          const char *ntype, int prec) {
    fprintf(fp, "<DataItem Dimensions=\"%s\" NumberType=\"%s\" Precision=\"%d\" Format=\"HDF\">",
            dims, ntype, prec);
    xml_escaped(fp, file);
    fprintf(fp, ":%s</DataItem>", dset);
}

typedef struct xdmf_info {
    const char *path; /* final .h5 path */
    size_t n;
    hsize_t nframes;
    const double *times;
    const int *present;
} xdmf_info;

static void xdmf_slab(FILE *fp, const xdmf_info *h, const char *file, const char *group,
                      hsize_t frame) {
    char dims[64], full[96], dset[96];
    snprintf(dims, sizeof dims, "%zu 3", h->n);
    snprintf(full, sizeof full, "%llu %zu 3", (unsigned long long)h->nframes, h->n);
    snprintf(dset, sizeof dset, "/particles/all/%s/value", group);
    fprintf(fp,
            "\n          <DataItem ItemType=\"HyperSlab\" Type=\"HyperSlab\" Dimensions=\"%s\">\n"
            "            <DataItem Dimensions=\"3 3\" NumberType=\"UInt\" Format=\"XML\">"
            "%llu 0 0 1 1 1 1 %zu 3</DataItem>\n            ",
            dims, (unsigned long long)frame, h->n);
    xdmf_hdf_item(fp, file, dset, full, "Float", 8);
    fprintf(fp, "\n          </DataItem>\n        ");
}

static int write_xdmf(const xdmf_info *h, char *err, size_t errlen) {
    char *xpath = xdmf_path(h->path);
    if (!xpath) {
        set_err(err, errlen, "h5md: out of memory");
        return -1;
    }
    size_t xl = strlen(xpath);
    char *tmp = malloc(xl + 6);
    if (!tmp) {
        free(xpath);
        set_err(err, errlen, "h5md: out of memory");
        return -1;
    }
    memcpy(tmp, xpath, xl);
    memcpy(tmp + xl, ".part", 6);
    const char *slash = strrchr(h->path, '/');
    const char *file = slash ? slash + 1 : h->path; /* relative: the pair moves together */

    FILE *fp = fopen(tmp, "w");
    if (!fp) {
        set_err(err, errlen, "cannot create '%s': %s", tmp, strerror(errno));
        free(tmp);
        free(xpath);
        return -1;
    }
    char n1[32];
    snprintf(n1, sizeof n1, "%zu", h->n);
    fprintf(fp, "<?xml version=\"1.0\" ?>\n<!DOCTYPE Xdmf SYSTEM \"Xdmf.dtd\" []>\n"
                "<Xdmf Version=\"3.0\" xmlns:xi=\"http://www.w3.org/2001/XInclude\">\n"
                "  <Domain>\n"
                "    <Grid Name=\"particles\" GridType=\"Collection\" "
                "CollectionType=\"Temporal\">\n");
    static const char *const vec[] = {"velocity", "angular_velocity", "force", "torque"};
    static const int veck[] = {TD_VELOCITY, TD_ANGVEL, TD_FORCE, TD_TORQUE};
    for (hsize_t i = 0; i < h->nframes; ++i) {
        fprintf(fp,
                "      <Grid Name=\"frame_%06llu\" GridType=\"Uniform\">\n"
                "        <Time Value=\"%.17g\"/>\n",
                (unsigned long long)i, h->times[i]);
        if (i == 0) {
            /* Xdmf3 needs explicit connectivity for Polyvertex; written once, included below */
            fprintf(fp,
                    "        <Topology TopologyType=\"Polyvertex\" NumberOfElements=\"%zu\" "
                    "NodesPerElement=\"1\">\n          <DataItem Dimensions=\"%zu\" "
                    "NumberType=\"Int\" Precision=\"8\" Format=\"XML\">",
                    h->n, h->n);
            for (size_t j = 0; j < h->n; ++j)
                fprintf(fp, (j % 16 == 15) ? "%zu\n" : "%zu ", j);
            fprintf(fp, "</DataItem>\n        </Topology>\n");
        } else {
            fprintf(fp, "        <xi:include xpointer=\"xpointer(/Xdmf/Domain/Grid/Grid[1]/"
                        "Topology)\"/>\n");
        }
        fprintf(fp, "        <Geometry GeometryType=\"XYZ\">");
        xdmf_slab(fp, h, file, "position", i);
        fprintf(fp, "</Geometry>\n");
        fprintf(fp, "        <Attribute Name=\"radius\" AttributeType=\"Scalar\" "
                    "Center=\"Node\">");
        xdmf_hdf_item(fp, file, "/particles/all/radius", n1, "Float", 8);
        fprintf(fp, "</Attribute>\n        <Attribute Name=\"id\" AttributeType=\"Scalar\" "
                    "Center=\"Node\">");
        xdmf_hdf_item(fp, file, "/particles/all/id", n1, "Int", 8);
        fprintf(fp, "</Attribute>\n        <Attribute Name=\"species\" AttributeType=\"Scalar\" "
                    "Center=\"Node\">");
        xdmf_hdf_item(fp, file, "/particles/all/species", n1, "Int", 4);
        fprintf(fp, "</Attribute>\n");
        for (int v = 0; v < 4; ++v) {
            if (!h->present[veck[v]]) continue;
            fprintf(fp, "        <Attribute Name=\"%s\" AttributeType=\"Vector\" "
                        "Center=\"Node\">", vec[v]);
            xdmf_slab(fp, h, file, vec[v], i);
            fprintf(fp, "</Attribute>\n");
        }
        fprintf(fp, "      </Grid>\n");
    }
    fprintf(fp, "    </Grid>\n  </Domain>\n</Xdmf>\n");
    int bad = ferror(fp);
    if (fclose(fp) != 0) bad = 1;
    if (bad) {
        set_err(err, errlen, "cannot write '%s': %s", tmp, strerror(errno));
        unlink(tmp);
        free(tmp);
        free(xpath);
        return -1;
    }
    if (rename(tmp, xpath) != 0) {
        set_err(err, errlen, "cannot rename '%s' to '%s': %s", tmp, xpath, strerror(errno));
        unlink(tmp);
        free(tmp);
        free(xpath);
        return -1;
    }
    free(tmp);
    free(xpath);
    return 0;
}

int jd_h5md_close(jd_h5md *h, int ok, char *err, size_t errlen) {
    if (!h) return 0;
    quiet_t q;
    char detail[256]; /* h is freed before the file is closed */
    quiet_on(&q, detail);
    int rc = 0;
    /* Keep what the sidecar needs, close every object, then the file itself (H5Fclose does
     * the final flush and reports its failure). */
    hid_t file = h->file;
    h->file = H5I_INVALID_HID;
    char *path = h->path, *part = h->part;
    double *times = h->times;
    int present[TD_COUNT];
    memcpy(present, h->present, sizeof present);
    xdmf_info xi = {path, h->n, h->nframes, times, present};
    h->path = h->part = NULL;
    h->times = NULL;
    free_handle(h);
    if (file >= 0 && H5Fclose(file) < 0) {
        h5_err(detail, err, errlen, "cannot close '%s'", part);
        rc = -1;
    }
    if (rc == 0 && ok) {
        if (rename(part, path) != 0) {
            set_err(err, errlen, "cannot rename '%s' to '%s': %s", part, path, strerror(errno));
            rc = -1;
        } else {
            rc = write_xdmf(&xi, err, errlen);
        }
    }
    free(times);
    free(path);
    free(part);
    quiet_off(&q);
    return rc;
}
