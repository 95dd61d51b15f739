/*
 * h5md.c — H5MD 1.1 trajectory writer with an XDMF 3 sidecar (see h5md.h for the layout): create,
 * frames, observables, close.  The error capture and the small HDF5 helpers are in h5md_util.c,
 * the sidecar in xdmf.c.
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
#include <pwd.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "h5md_internal.h"

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
    char *sidecar, *sidecar_part; /* PATH's .xdmf and its .part */
    int fd;     /* PATH.part, open while the writer lives: it holds the lock (h5md_file.c) */
    hid_t file;
    hid_t all; /* /particles/all */
    h5md_rows rows;          /* the particle rows (h5md_rows.c) */
    h5md_wall_mesh walls;    /* the walls (h5md_walls.c) */
    int decided;             /* groups fixed at the first frame */
    int present[TD_COUNT];   /* which time-dependent groups this run writes */
    hid_t grp[TD_COUNT];     /* group ids (H5I_INVALID_HID when absent) */
    hid_t value[TD_COUNT];   /* value datasets */
    hid_t step_ds, time_ds;  /* shared step/time (position/), hard-linked elsewhere */
    hsize_t nframes;
    double *times; /* per frame, for the XDMF sidecar */
    int64_t *steps; /* per frame, for the bond lines */
    size_t cap;
    obs *obs;
    size_t nobs, obs_cap;
    int broken; /* a failed write left datasets inconsistent: refuse further writes */
    char h5detail[256]; /* innermost HDF5 error of the current call (see capture_cb, h5md_util.c) */
    int obs_dirty;      /* observable samples written since the last flush ... */
    int64_t obs_step;   /* ... all of them at this step (the current batch) */
};

/* ------------------------------------------------------------------------------------------ */

int jd_h5md_flush(jd_h5md *h) {
    if (!h || h->broken || H5Fflush(h->file, H5F_SCOPE_LOCAL) < 0) return -1;
    h->obs_dirty = 0;
    return 0;
}

h5md_view h5md_view_of(jd_h5md *h) {
    return (h5md_view){h->file, h->part, h->h5detail, &h->broken};
}

/* Every HDF5 object of the writer but the file; what the sidecar needs stays. */
static void free_objects(jd_h5md *h) {
    for (size_t i = 0; i < h->nobs; ++i) {
        h5md_close_id(&h->obs[i].step);
        h5md_close_id(&h->obs[i].time);
        h5md_close_id(&h->obs[i].value);
        h5md_close_id(&h->obs[i].grp);
        free(h->obs[i].name);
    }
    for (int k = 0; k < TD_COUNT; ++k) {
        h5md_close_id(&h->value[k]);
        h5md_close_id(&h->grp[k]);
    }
    h5md_close_id(&h->step_ds);
    h5md_close_id(&h->time_ds);
    h5md_close_id(&h->all);
    h5md_rows_close(&h->rows);
    h5md_close_id(&h->walls.position);
    free(h->obs);
    h->obs = NULL;
    h->nobs = 0;
}

static void free_handle(jd_h5md *h) {
    free_objects(h);
    h5md_close_id(&h->file);
    free(h->times);
    free(h->steps);
    h5md_rows_free(&h->rows);
    h5md_walls_free(&h->walls);
    free(h->path);
    free(h->part);
    free(h->sidecar);
    free(h->sidecar_part);
    if (h->fd >= 0) close(h->fd);
    free(h);
}

/* /h5md/author/name: the scene's author, else $JDEM_AUTHOR, else the user running the program. */
static const char *author_name(const jd_h5md_meta *meta) {
    if (meta && meta->author && *meta->author) return meta->author;
    const char *env = getenv("JDEM_AUTHOR");
    if (env && *env) return env;
    const struct passwd *pw = getpwuid(getuid());
    if (pw && pw->pw_name && *pw->pw_name) return pw->pw_name;
    env = getenv("USER");
    return env && *env ? env : "unknown";
}

/* /jdem/vertex_index [N] = 0..N-1: the sidecar's Polyvertex connectivity (Xdmf3 makes no cells
 * of its own), 8 bytes a row; written at close, when the rows are known. */
static int write_vertex_index(hid_t file, size_t n) {
    int64_t *idx = malloc((n ? n : 1) * sizeof *idx);
    if (!idx) return -1;
    for (size_t i = 0; i < n; ++i) idx[i] = (int64_t)i;
    hid_t g = H5Lexists(file, "jdem", H5P_DEFAULT) > 0 ? H5Gopen2(file, "jdem", H5P_DEFAULT)
                                                      : h5md_group_create(file, "jdem");
    int rc = g >= 0 ? h5md_dset_fixed(g, "vertex_index", H5T_STD_I64LE, H5T_NATIVE_INT64, n, idx,
                                      NULL)
                    : -1;
    h5md_close_id(&g);
    free(idx);
    return rc;
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
        if (h5md_attr_write(g, "version", H5T_STD_I32LE, H5T_NATIVE_INT, 1, &two, version) < 0)
            goto fail;
    }
    where = "/h5md/author";
    g2 = H5Gcreate2(g, "author", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    if (g2 < 0 || h5md_attr_str(g2, "name", author_name(meta)) < 0) goto fail;
    h5md_close_id(&g2);
    /* the units module: every `unit` attribute is an SI unit string of that module */
    where = "/h5md/modules/units";
    g2 = h5md_group_create(g, "modules/units");
    if (g2 < 0 || h5md_attr_str(g2, "system", "SI") < 0) goto fail;
    {
        int version[2] = {1, 0};
        hsize_t two = 2;
        if (h5md_attr_write(g2, "version", H5T_STD_I32LE, H5T_NATIVE_INT, 1, &two, version) < 0)
            goto fail;
    }
    h5md_close_id(&g2);
    where = "/h5md/creator";
    g2 = H5Gcreate2(g, "creator", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    if (g2 < 0 || h5md_attr_str(g2, "name", creator) < 0 || h5md_attr_str(g2, "version", cver) < 0)
        goto fail;
    h5md_close_id(&g2);
    h5md_close_id(&g);

    /* /parameters */
    where = "/parameters";
    g = H5Gcreate2(h->file, "parameters", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    if (g < 0) goto fail;
    if (meta) {
        if (meta->creator && h5md_attr_str(g, "engine", meta->creator) < 0) goto fail;
        if (meta->scene_name && h5md_attr_str(g, "scene_name", meta->scene_name) < 0) goto fail;
        if (meta->case_name && h5md_attr_str(g, "case_name", meta->case_name) < 0) goto fail;
        if (h5md_attr_double(g, "dt", meta->dt) < 0) goto fail;
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
            h5md_close_id(&d);
            h5md_close_id(&sp);
            h5md_close_id(&t);
            if (rc < 0) goto fail;
        }
    }
    h5md_close_id(&g);

    /* /particles/all and its box */
    where = "/particles/all";
    h->all = h5md_group_create(h->file, "particles/all");
    if (h->all < 0) goto fail;
    where = "/particles/all/box";
    g = H5Gcreate2(h->all, "box", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    if (g < 0 || h5md_attr_int(g, "dimension", 3) < 0) goto fail;
    {
        char boundary[3][5] = {"none", "none", "none"};
        hsize_t three = 3;
        hid_t t = h5md_str_type(4);
        int rc = t >= 0 ? h5md_attr_write(g, "boundary", t, t, 1, &three, boundary) : -1;
        h5md_close_id(&t);
        if (rc < 0) goto fail;
    }
    h5md_close_id(&g);

    /* time-independent per-particle data */
    where = "/particles/all/{id, species, radius, mass}";
    if (h5md_rows_create(&h->rows, h->all, p) < 0) goto fail;
    return 0;

fail:
    h5md_err(h->h5detail, err, errlen, "cannot write %s in '%s'", where, h->part);
    h5md_close_id(&g2);
    h5md_close_id(&g);
    return -1;
}

jd_h5md *jd_h5md_create(const char *path, const jd_h5md_meta *meta,
                        const jd_h5md_particles *particles, char *err, size_t errlen) {
    /* HDF5's exit-time clean-up closes what is still open; after a failed H5Fclose (disk full,
     * out of memory) the file stays registered half-closed and that clean-up crashes in
     * HDF5 1.10.  Every file is closed explicitly here, so the clean-up is not needed.  Only
     * effective before the library's first use (a later call fails harmlessly). */
    H5dont_atexit();
    if (!path || !*path || !particles) {
        h5md_set_err(err, errlen, "h5md: missing path or particle description");
        return NULL;
    }
    if (particles->n > 0 && (!particles->id || !particles->species || !particles->radius ||
                             !particles->mass)) {
        h5md_set_err(err, errlen, "h5md: particle arrays id/species/radius/mass must all be given");
        return NULL;
    }
    for (size_t i = 1; !particles->growing && i < particles->n; ++i)
        if (particles->id[i] <= particles->id[i - 1]) {
            h5md_set_err(err, errlen,
                         "h5md: particle ids must be sorted ascending and unique (id %lld at index "
                         "%zu follows %lld)",
                         (long long)particles->id[i], i, (long long)particles->id[i - 1]);
            return NULL;
        }
    jd_h5md *h = calloc(1, sizeof *h);
    if (!h) {
        h5md_set_err(err, errlen, "h5md: out of memory");
        return NULL;
    }
    h->fd = -1;
    h->file = h->all = h->step_ds = h->time_ds = H5I_INVALID_HID;
    for (int k = 0; k < TD_COUNT; ++k) h->grp[k] = h->value[k] = H5I_INVALID_HID;
    h->rows.species = h->rows.radius = h->rows.mass = H5I_INVALID_HID;
    h->rows.id_grp = h->rows.id_value = H5I_INVALID_HID;
    h->walls.position = H5I_INVALID_HID;
    size_t len = strlen(path);
    h->path = malloc(len + 1);
    h->part = malloc(len + 6);
    h->sidecar = xdmf_path(path);
    h->sidecar_part = h->sidecar ? malloc(strlen(h->sidecar) + 6) : NULL;
    if (!h->path || !h->part || !h->sidecar_part) {
        h5md_set_err(err, errlen, "h5md: out of memory");
        free_handle(h);
        return NULL;
    }
    memcpy(h->path, path, len + 1);
    snprintf(h->part, len + 6, "%s.part", path);
    snprintf(h->sidecar_part, strlen(h->sidecar) + 6, "%s.part", h->sidecar);

    if (h5md_part_open(h->path, h->part, h->sidecar, &h->fd, err, errlen) != 0) {
        free_handle(h); /* PATH.part is not ours (or not usable): left as it is */
        return NULL;
    }
    quiet_t q;
    h5md_quiet_on(&q, h->h5detail);
    h->file = h5md_part_create(h->part, h->fd, err, errlen, h->h5detail);
    if (h->file < 0) goto fail;
    if (write_header(h, meta, particles, err, errlen) < 0) goto fail;
    if (H5Fflush(h->file, H5F_SCOPE_LOCAL) < 0) {
        h5md_err(h->h5detail, err, errlen, "cannot flush '%s'", h->part);
        goto fail;
    }
    h5md_quiet_off(&q);
    return h;

fail:
    /* nothing useful in a half-created file; it is ours (locked), so it is removed */
    unlink(h->part);
    free_handle(h);
    h5md_quiet_off(&q);
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
    hsize_t vchunk[3], schunk[1] = {512};
    const int wide = h->rows.growing && h->rows.n < GROWING_CHUNK_ROWS;
    value_chunk(wide ? GROWING_CHUNK_ROWS : h->rows.n, vchunk);
    if (h->rows.growing && vchunk[0] > GROWING_CHUNK_FRAMES) vchunk[0] = GROWING_CHUNK_FRAMES;
    for (int k = 0; k < TD_COUNT; ++k) {
        h->present[k] = arr[k] != NULL;
        if (!h->present[k]) continue;
        const char *what = "group";
        h->grp[k] = H5Gcreate2(h->all, td_name[k], H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
        if (h->grp[k] < 0) goto fail;
        what = "value";
        h->value[k] = h5md_rows_value(&h->rows, h->grp[k], vchunk);
        if (h->value[k] < 0 || h5md_attr_str(h->value[k], "unit", td_unit[k]) < 0) goto fail;
        if (k == TD_POSITION) {
            what = "step";
            h->step_ds = h5md_dset_extendible(h->grp[k], "step", H5T_STD_I64LE, 1, NULL, schunk);
            if (h->step_ds < 0) goto fail;
            what = "time";
            h->time_ds = h5md_dset_extendible(h->grp[k], "time", H5T_IEEE_F64LE, 1, NULL, schunk);
            if (h->time_ds < 0 || h5md_attr_str(h->time_ds, "unit", "s") < 0) goto fail;
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
        h5md_err(h->h5detail, err, errlen, "cannot create %s of /particles/all/%s in '%s'", what,
                 td_name[k], h->part);
        h->broken = 1;
        return -1;
    }
    if (h5md_rows_setup(&h->rows, h->all, h->grp[TD_POSITION]) < 0) {
        h5md_err(h->h5detail, err, errlen, "cannot create /particles/all/id in '%s'", h->part);
        h->broken = 1;
        return -1;
    }
    h->decided = 1;
    return 0;
}

int jd_h5md_write_frame(jd_h5md *h, const jd_h5md_frame *frame, char *err, size_t errlen) {
    if (!h || !frame) {
        h5md_set_err(err, errlen, "h5md: no writer or frame");
        return -1;
    }
    if (h->broken) {
        h5md_set_err(err, errlen, "h5md: '%s' is unusable after an earlier write error", h->part);
        return -1;
    }
    if (!frame->position) {
        h5md_set_err(err, errlen, "h5md: frame at step %lld has no positions",
                     (long long)frame->step);
        return -1;
    }
    const double *arr[TD_COUNT] = {frame->position, frame->velocity, frame->angular_velocity,
                                   frame->force, frame->torque};
    if (h->decided) {
        for (int k = 0; k < TD_COUNT; ++k)
            if (h->present[k] != (arr[k] != NULL)) {
                h5md_set_err(err, errlen,
                             "h5md: frame at step %lld %s %s, unlike the first frame of '%s'",
                             (long long)frame->step, h->present[k] ? "lacks" : "adds", td_name[k],
                             h->part);
                return -1;
            }
    }
    if (h->nframes == h->cap) { /* grow the in-memory time list (XDMF needs it) */
        size_t cap = h->cap ? 2 * h->cap : 64;
        double *t = realloc(h->times, cap * sizeof *t);
        if (t) h->times = t;
        int64_t *st = realloc(h->steps, cap * sizeof *st);
        if (st) h->steps = st;
        if (!t || !st) goto oom;
        h->cap = cap;
    }

    quiet_t q;
    h5md_quiet_on(&q, h->h5detail);
    if (!h->decided && setup_groups(h, frame, err, errlen) < 0) {
        h5md_quiet_off(&q);
        return -1;
    }
    char why[256];
    if (h5md_rows_frame(&h->rows, frame, h->nframes, why, sizeof why) < 0) {
        h5md_err(h->h5detail, err, errlen, "h5md: %s in '%s'", why, h->part);
        h->broken = 1;
        h5md_quiet_off(&q);
        return -1;
    }
    hsize_t rest[2] = {(hsize_t)h->rows.n, 3};
    const char *what = "wall vertices";
    if (h5md_walls_frame(&h->walls, h->nframes, frame->time) < 0) goto fail;
    what = "value";
    for (int k = 0; k < TD_COUNT; ++k) {
        if (!h->present[k]) continue;
        if (h5md_append_row(h->value[k], h->nframes, 3, rest, H5T_NATIVE_DOUBLE,
                            h5md_rows_vector(&h->rows, arr[k])) < 0) {
            what = td_name[k];
            goto fail;
        }
    }
    /* step/time last: a reader that trusts len(step) never sees a half-written frame */
    what = "step";
    if (h5md_append_row(h->step_ds, h->nframes, 1, NULL, H5T_NATIVE_INT64, &frame->step) < 0)
        goto fail;
    what = "time";
    if (h5md_append_row(h->time_ds, h->nframes, 1, NULL, H5T_NATIVE_DOUBLE, &frame->time) < 0)
        goto fail;
    if (H5Fflush(h->file, H5F_SCOPE_LOCAL) < 0) {
        h5md_err(h->h5detail, err, errlen, "cannot flush '%s' after step %lld", h->part,
                 (long long)frame->step);
        h->broken = 1;
        h5md_quiet_off(&q);
        return -1;
    }
    h->times[h->nframes] = frame->time;
    h->steps[h->nframes] = frame->step;
    h->nframes++;
    h->obs_dirty = 0; /* the flush covered pending observable samples too */
    h5md_quiet_off(&q);
    return 0;

fail:
    h5md_err(h->h5detail, err, errlen, "cannot append %s of step %lld to '%s'", what,
             (long long)frame->step, h->part);
    h->broken = 1;
    h5md_quiet_off(&q);
    return -1;
oom:
    h5md_set_err(err, errlen, "h5md: out of memory");
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
        h5md_set_err(err, errlen, "h5md: no writer");
        return -1;
    }
    if (!valid_obs_name(name)) {
        h5md_set_err(err, errlen, "h5md: invalid observable name '%s'", name ? name : "(null)");
        return -1;
    }
    if (h->broken) {
        h5md_set_err(err, errlen, "h5md: '%s' is unusable after an earlier write error", h->part);
        return -1;
    }
    obs *o = NULL;
    for (size_t i = 0; i < h->nobs; ++i)
        if (strcmp(h->obs[i].name, name) == 0) {
            o = &h->obs[i];
            break;
        }
    quiet_t q;
    h5md_quiet_on(&q, h->h5detail);
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
                h5md_set_err(err, errlen, "h5md: out of memory");
                h5md_quiet_off(&q);
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
            h5md_set_err(err, errlen, "h5md: out of memory");
            h5md_quiet_off(&q);
            return -1;
        }
        strcpy(o->name, name);
        h->nobs++; /* registered now so that free_handle closes whatever gets opened */
        char gname[1024];
        snprintf(gname, sizeof gname, "observables/%s", name);
        hsize_t chunk[1] = {256};
        o->grp = h5md_group_create(h->file, gname);
        if (o->grp < 0) goto fail_create;
        what = "step";
        o->step = h5md_dset_extendible(o->grp, "step", H5T_STD_I64LE, 1, NULL, chunk);
        if (o->step < 0) goto fail_create;
        what = "time";
        o->time = h5md_dset_extendible(o->grp, "time", H5T_IEEE_F64LE, 1, NULL, chunk);
        if (o->time < 0 || h5md_attr_str(o->time, "unit", "s") < 0) goto fail_create;
        what = "value";
        o->value = h5md_dset_extendible(o->grp, "value", H5T_IEEE_F64LE, 1, NULL, chunk);
        if (o->value < 0) goto fail_create;
    }
    what = "value";
    if (h5md_append_row(o->value, o->count, 1, NULL, H5T_NATIVE_DOUBLE, &value) < 0) goto fail;
    what = "step";
    if (h5md_append_row(o->step, o->count, 1, NULL, H5T_NATIVE_INT64, &step) < 0) goto fail;
    what = "time";
    if (h5md_append_row(o->time, o->count, 1, NULL, H5T_NATIVE_DOUBLE, &time) < 0) goto fail;
    o->count++;
    h->obs_dirty = 1;
    h->obs_step = step;
    h5md_quiet_off(&q);
    return 0;

fail_create:
    /* nothing appended yet: forget this observable, the writer stays usable */
    h5md_err(h->h5detail, err, errlen, "cannot create /observables/%s (%s) in '%s'", name, what,
             h->part);
    h5md_close_id(&o->step);
    h5md_close_id(&o->time);
    h5md_close_id(&o->value);
    h5md_close_id(&o->grp);
    free(o->name);
    h->nobs--;
    h5md_quiet_off(&q);
    return -1;
fail:
    h5md_err(h->h5detail, err, errlen, "cannot write /observables/%s %s at step %lld in '%s'",
             name, what, (long long)step, h->part);
    h->broken = 1;
    h5md_quiet_off(&q);
    return -1;
}

/* What the sidecar needs that is known only at the end: /jdem/vertex_index over the final rows
 * and the bond lines of every frame.  *range (malloc'd) holds the bond lines' start and count
 * per frame. */
static int close_extras(jd_h5md *h, hid_t file, xdmf_info *xi, hsize_t **range, char *err,
                        size_t errlen) {
    if (write_vertex_index(file, h->rows.n) < 0) {
        h5md_err(h->h5detail, err, errlen, "cannot write /jdem/vertex_index in '%s'", h->part);
        return -1;
    }
    if (H5Lexists(file, "jdem/bonds", H5P_DEFAULT) <= 0) return 0;
    *range = malloc(2 * (h->nframes ? h->nframes : 1) * sizeof **range);
    if (!*range) {
        h5md_set_err(err, errlen, "h5md: out of memory");
        return -1;
    }
    if (h5md_bond_lines(file, h->rows.row_id, h->rows.n, h->steps, h->nframes, *range,
                        *range + h->nframes, &xi->bond_rows) != 0) {
        h5md_err(h->h5detail, err, errlen, "cannot write /jdem/bond_lines in '%s'", h->part);
        return -1;
    }
    xi->bonds = 1;
    xi->bond_start = *range;
    xi->bond_count = *range + h->nframes;
    return 0;
}

int jd_h5md_set_walls(jd_h5md *h, size_t n, const jd_h5md_wall *walls, char *err, size_t errlen) {
    if (!h || h->walls.present || h->nframes > 0) {
        h5md_set_err(err, errlen, "h5md: walls are set once, before the first frame");
        return -1;
    }
    quiet_t q;
    h5md_quiet_on(&q, h->h5detail);
    const int rc = h5md_walls_write(h->file, n, walls, &h->walls);
    if (rc != 0) {
        h5md_err(h->h5detail, err, errlen, "cannot write /jdem/walls in '%s'", h->part);
        h->broken = 1;
    }
    h5md_quiet_off(&q);
    return rc;
}

h5md_wall_mesh *h5md_walls_of(jd_h5md *h) { return &h->walls; }

size_t h5md_rows_count(const jd_h5md *h) { return h->rows.n; }

int h5md_set_continues(jd_h5md *h, const char *creators) {
    const hid_t g = H5Gopen2(h->file, "/h5md/creator", H5P_DEFAULT);
    const int rc = g >= 0 && h5md_attr_str(g, "continues", creators) == 0 ? 0 : -1;
    if (g >= 0) H5Gclose(g);
    return rc;
}

int jd_h5md_move_mesh(jd_h5md *h, size_t wall, const double (*triangles)[3][3], char *err,
                      size_t errlen) {
    const size_t n = h && wall < h->walls.n_walls ? h->walls.n_vertices[wall] / 3 : 0;
    if (!h || h5md_walls_move_mesh(&h->walls, wall, triangles, n) != 0) {
        h5md_set_err(err, errlen, "h5md: wall %zu is not a mesh wall given with moved = 1", wall);
        return -1;
    }
    return 0;
}

int jd_h5md_close(jd_h5md *h, int ok, char *err, size_t errlen) {
    if (!h) return 0;
    if (err && errlen) err[0] = '\0';
    quiet_t q;
    h5md_quiet_on(&q, h->h5detail);
    int rc = 0, clean = !h->broken;
    /* Close every object, then the file itself (H5Fclose does the final flush and reports its
     * failure). */
    hid_t file = h->file;
    h->file = H5I_INVALID_HID;
    free_objects(h);
    hsize_t *bond_range = NULL;
    xdmf_info xi = {.path = h->path, .n = h->rows.n, .growing = h->rows.growing,
                    .nframes = h->nframes, .times = h->times, .present = h->present,
                    .runs = h->rows.runs, .frame_runs = h->rows.frame_runs, .walls = &h->walls};
    if (file >= 0 && ok && !h->broken &&
        close_extras(h, file, &xi, &bond_range, err, errlen) != 0) {
        rc = -1;
        clean = 0;
    }
    if (file >= 0 && H5Fclose(file) < 0) {
        h5md_err(h->h5detail, err, errlen, "cannot close '%s'", h->part);
        rc = -1;
        clean = 0;
    }
    if (rc == 0 && ok && h->broken) {
        h5md_set_err(err, errlen, "'%s' is incomplete after an earlier write error", h->part);
        rc = -1;
    }
    /* the sidecar first: PATH and its sidecar replace the previous pair only when both exist */
    if (rc == 0 && ok && xdmf_write(&xi, h->sidecar_part, err, errlen) != 0) {
        char why[512];
        snprintf(why, sizeof why, "%s", err ? err : "");
        h5md_set_err(err, errlen, "%s; the trajectory is complete in '%s' (without its sidecar); "
                     "the previous result is unchanged", why, h->part);
        rc = -1;
    }
    if (rc == 0 && ok)
        rc = h5md_publish(h->part, h->path, h->sidecar_part, h->sidecar, err, errlen);
    else if ((ok || !clean) && h5md_part_keep_or_remove(h->part, clean, err, errlen) != 0)
        rc = -1;
    h5md_quiet_off(&q);
    free(bond_range);
    free_handle(h);
    return rc;
}
