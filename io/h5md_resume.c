/*
 * h5md_resume.c — the trajectory of a resumed run, in both engines (h5md_resume.h;
 * docs/output.md "Resumed runs").
 *
 * The resumed run writes the same file the uninterrupted run would: OUT.part from the start,
 * renamed to OUT at the end.  Its prefix, everything the killed run wrote up to the checkpoint,
 * is copied from the killed run's OUT.part through the writer's own calls (frames, observables,
 * bond tables), so the writer's state (rows, live runs, wall vertices, sidecar) is what it
 * would have been; what the killed run wrote after the checkpoint (frames, samples, bonds and
 * a stop frame) is left out.  The source is first renamed OUT.resume, so that a resume that is
 * itself interrupted during the copy can start again from it.
 */
#include <errno.h>
#include <fcntl.h>
#include <hdf5.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/file.h>
#include <unistd.h>

#include "h5md_internal.h"
#include "h5md_resume.h"

static const char *const vector_groups[5] = {"position", "velocity", "angular_velocity", "force",
                                              "torque"};

static hid_t open_ro(const char *path) {
    hid_t fapl = H5Pcreate(H5P_FILE_ACCESS);
    if (fapl >= 0) H5Pset_file_locking(fapl, 0, 1);
    const hid_t f = H5Fopen(path, H5F_ACC_RDONLY, fapl);
    if (fapl >= 0) H5Pclose(fapl);
    return f;
}

/* Rows of the first axis of dataset `name` (-1: absent). */
static hssize_t rows_of(hid_t f, const char *name, hsize_t dims[3]) {
    hid_t d = H5Oexists_by_name(f, name, H5P_DEFAULT) > 0 ? H5Dopen2(f, name, H5P_DEFAULT) : -1;
    if (d < 0) return -1;
    hid_t sp = H5Dget_space(d);
    hsize_t tmp[3] = {0, 0, 0};
    if (!dims) dims = tmp;
    const int rank = sp >= 0 ? H5Sget_simple_extent_dims(sp, dims, NULL) : -1;
    if (sp >= 0) H5Sclose(sp);
    H5Dclose(d);
    return rank >= 1 ? (hssize_t)dims[0] : -1;
}

/* Read the whole dataset `name` of n values into a malloc'd buffer (NULL on failure). */
static void *read_all(hid_t f, const char *name, hid_t memtype, size_t n) {
    void *buf = malloc((n ? n : 1) * H5Tget_size(memtype));
    hid_t d = buf ? H5Dopen2(f, name, H5P_DEFAULT) : -1;
    const int ok = d >= 0 && (n == 0 || H5Dread(d, memtype, H5S_ALL, H5S_ALL, H5P_DEFAULT, buf) >= 0);
    if (d >= 0) H5Dclose(d);
    if (!ok) {
        free(buf);
        return NULL;
    }
    return buf;
}

/* 1 when the trajectory at path opens and holds the frames up to frame_step. */
static int holds_prefix(const char *path, int64_t frame_step) {
    if (access(path, R_OK) != 0) return 0;
    hid_t f = open_ro(path);
    if (f < 0) return 0;
    int ok = frame_step < 0 && H5Lexists(f, "/h5md", H5P_DEFAULT) > 0;
    const hssize_t nf = rows_of(f, "/particles/all/position/step", NULL);
    if (!ok && nf > 0) {
        int64_t *steps = read_all(f, "/particles/all/position/step", H5T_NATIVE_INT64, (size_t)nf);
        ok = steps && steps[nf - 1] >= frame_step;
        free(steps);
    }
    H5Fclose(f);
    return ok;
}

/* 0 when no run holds the writer's lock on part (h5md_file.c), else -1 with err. */
static int not_in_use(const char *part, char *err, size_t errlen) {
    const int fd = open(part, O_RDONLY | O_NOFOLLOW);
    if (fd < 0) return 0;
    const int busy = flock(fd, LOCK_EX | LOCK_NB) != 0 && errno == EWOULDBLOCK;
    close(fd);
    if (busy)
        snprintf(err, errlen, "cannot resume: '%s' is being written by another run (it holds "
                 "the file's lock); wait for it to end", part);
    return busy ? -1 : 0;
}

int jd_h5md_resume_source(const char *out, int64_t frame_step, char *src,
                                    size_t srclen, char *err, size_t errlen) {
    char part[4200];
    snprintf(part, sizeof part, "%s.part", out);
    snprintf(src, srclen, "%s.resume", out);
    if (not_in_use(part, err, errlen) != 0) return -1;
    H5E_auto2_t fn;
    void *data;
    H5Eget_auto2(H5E_DEFAULT, &fn, &data);
    H5Eset_auto2(H5E_DEFAULT, NULL, NULL);
    int rc = 0;
    if (holds_prefix(part, frame_step)) {
        if (rename(part, src) != 0) {
            snprintf(err, errlen, "cannot resume: cannot rename '%s' to '%s': %s", part, src,
                     strerror(errno));
            rc = -1;
        }
    } else if (!holds_prefix(src, frame_step)) {
        snprintf(err, errlen, "cannot resume: neither '%s' nor '%s' holds the trajectory up to "
                 "step %lld of the checkpoint; valid: resume with the output (-o) of the run that "
                 "wrote the checkpoint, whose OUT.part is kept when it stops", part, src,
                 (long long)frame_step);
        rc = -1;
    }
    H5Eset_auto2(H5E_DEFAULT, fn, data);
    return rc;
}

/* One frame f of src into h: its vectors and, for a growing set, its ids. */
static int copy_frame(hid_t f, hsize_t frame, int64_t step, double time, size_t n, int growing,
                      double *vec, int64_t *ids, jd_h5md *h, char *err, size_t errlen) {
    jd_h5md_frame fr = {.step = step, .time = time};
    const double **dst[5] = {&fr.position, &fr.velocity, &fr.angular_velocity, &fr.force,
                             &fr.torque};
    char name[128];
    for (int k = 0; k < 5; k++) {
        snprintf(name, sizeof name, "/particles/all/%s", vector_groups[k]);
        if (H5Lexists(f, name, H5P_DEFAULT) <= 0) continue;
        snprintf(name, sizeof name, "/particles/all/%s/value", vector_groups[k]);
        hid_t d = H5Dopen2(f, name, H5P_DEFAULT), fs = d >= 0 ? H5Dget_space(d) : -1;
        const hsize_t start[3] = {frame, 0, 0}, count[3] = {1, n, 3}, mdim[1] = {3 * n};
        hid_t ms = H5Screate_simple(1, mdim, NULL);
        const int ok = fs >= 0 && ms >= 0 &&
                       H5Sselect_hyperslab(fs, H5S_SELECT_SET, start, NULL, count, NULL) >= 0 &&
                       H5Dread(d, H5T_NATIVE_DOUBLE, ms, fs, H5P_DEFAULT, vec + 3 * n * (size_t)k) >= 0;
        if (ms >= 0) H5Sclose(ms);
        if (fs >= 0) H5Sclose(fs);
        if (d >= 0) H5Dclose(d);
        if (!ok) return -1;
        *dst[k] = vec + 3 * n * (size_t)k;
    }
    jd_h5md_particles rows = {.n = n, .id = ids};
    if (growing) {
        hid_t d = H5Dopen2(f, "/particles/all/id/value", H5P_DEFAULT), fs = d >= 0 ? H5Dget_space(d) : -1;
        const hsize_t start[2] = {frame, 0}, count[2] = {1, n}, mdim[1] = {n};
        hid_t ms = H5Screate_simple(1, mdim, NULL);
        const int ok = fs >= 0 && ms >= 0 &&
                       H5Sselect_hyperslab(fs, H5S_SELECT_SET, start, NULL, count, NULL) >= 0 &&
                       H5Dread(d, H5T_NATIVE_INT64, ms, fs, H5P_DEFAULT, ids) >= 0;
        if (ms >= 0) H5Sclose(ms);
        if (fs >= 0) H5Sclose(fs);
        if (d >= 0) H5Dclose(d);
        if (!ok) return -1;
        fr.rows = &rows;
    }
    return jd_h5md_write_frame(h, &fr, err, errlen) == 0 ? 0 : -2;
}

/* The first id each of the n rows of a growing set's id/value [nf][n] shows over its frames
 * [0, upto) (-1: none); returns the rows live in those frames (rows are added in order, so they
 * are the first ones), or (size_t)-1 when the ids cannot be read. */
static size_t first_row_ids(hid_t f, hsize_t nf, hsize_t upto, size_t n, int64_t *first) {
    int64_t *ids = read_all(f, "/particles/all/id/value", H5T_NATIVE_INT64, (size_t)nf * n);
    if (!ids) return (size_t)-1;
    size_t live = 0;
    for (size_t r = 0; r < n; r++) {
        first[r] = -1;
        for (hsize_t k = 0; k < upto && first[r] < 0; k++) first[r] = ids[k * n + r];
        if (first[r] >= 0) live = r + 1;
    }
    free(ids);
    return live;
}

/* The number of frames up to frame_step (steps: the nf frames' steps, ascending). */
static hsize_t prefix_frames(const int64_t *steps, hssize_t nf, int64_t frame_step) {
    hsize_t k = 0;
    while (steps && (hssize_t)k < nf && steps[k] <= frame_step) k++;
    return k;
}

/* Frame `frame`'s vertices of the moved meshes (src's vertex_position) as where they are now in
 * h, so that the copied frame draws them where the interrupted run did.  0 / -1. */
static int moved_mesh_vertices(hid_t f, hsize_t frame, h5md_wall_mesh *m) {
    const char *name = "/jdem/walls/mesh/vertex_position";
    hsize_t dims[3];
    int any = 0;
    for (size_t j = 0; m->given && j < m->nv; j++) any |= m->given[j];
    if (!any) return 0;
    if (rows_of(f, name, dims) <= (hssize_t)frame || dims[1] != m->nv) return -1;
    double *row = malloc(3 * m->nv * sizeof *row);
    hid_t d = row ? H5Dopen2(f, name, H5P_DEFAULT) : -1, fs = d >= 0 ? H5Dget_space(d) : -1;
    const hsize_t start[3] = {frame, 0, 0}, count[3] = {1, m->nv, 3}, mdim[1] = {3 * m->nv};
    hid_t ms = H5Screate_simple(1, mdim, NULL);
    const int ok = fs >= 0 && ms >= 0 &&
                   H5Sselect_hyperslab(fs, H5S_SELECT_SET, start, NULL, count, NULL) >= 0 &&
                   H5Dread(d, H5T_NATIVE_DOUBLE, ms, fs, H5P_DEFAULT, row) >= 0;
    if (ms >= 0) H5Sclose(ms);
    if (fs >= 0) H5Sclose(fs);
    if (d >= 0) H5Dclose(d);
    for (size_t j = 0; ok && j < m->nv; j++)
        if (m->given[j]) memcpy(m->now + 3 * j, row + 3 * j, 3 * sizeof *row);
    free(row);
    return ok ? 0 : -1;
}

static int copy_frames(hid_t f, jd_h5md *h, int64_t frame_step, char *err, size_t errlen) {
    hsize_t dims[3];
    const hssize_t nf = rows_of(f, "/particles/all/position/step", NULL);
    if (nf <= 0) return 0;
    if (rows_of(f, "/particles/all/position/value", dims) != nf) return -1;
    size_t n = (size_t)dims[1];
    int64_t *steps = read_all(f, "/particles/all/position/step", H5T_NATIVE_INT64, (size_t)nf);
    double *times = read_all(f, "/particles/all/position/time", H5T_NATIVE_DOUBLE, (size_t)nf);
    double *vec = malloc(15 * (n ? n : 1) * sizeof *vec);
    int64_t *ids = malloc((n ? n : 1) * sizeof *ids);
    H5O_info_t info;
    const int growing = H5Lexists(f, "/particles/all/id", H5P_DEFAULT) > 0 &&
                        H5Oget_info_by_name(f, "/particles/all/id", &info, H5P_DEFAULT) >= 0 &&
                        info.type == H5O_TYPE_GROUP;
    int rc = steps && times && vec && ids ? 0 : -1;
    if (rc == 0 && growing) {
        /* the rows live in the prefix's frames, or the writer's own (build/jdem makes every row
         * at the start): the rows the interrupted run added later follow its later frames,
         * which the resumed run assigns again */
        const size_t live =
            first_row_ids(f, (hsize_t)nf, prefix_frames(steps, nf, frame_step), n, ids);
        const size_t own = h5md_rows_count(h);
        rc = live == (size_t)-1 || own > n ? -1 : 0;
        if (rc == 0) n = live > own ? live : own;
    }
    h5md_wall_mesh *walls = h5md_walls_of(h);
    double *now = walls->now ? malloc((walls->nv ? walls->nv : 1) * 3 * sizeof *now) : NULL;
    if (now) memcpy(now, walls->now, walls->nv * 3 * sizeof *now); /* where they are at the resume */
    for (hssize_t k = 0; rc == 0 && k < nf && steps[k] <= frame_step; k++) {
        rc = moved_mesh_vertices(f, (hsize_t)k, walls);
        if (rc == 0)
            rc = copy_frame(f, (hsize_t)k, steps[k], times[k], n, growing, vec, ids, h, err, errlen);
    }
    if (now) memcpy(walls->now, now, walls->nv * 3 * sizeof *now);
    free(now);
    free(steps);
    free(times);
    free(vec);
    free(ids);
    return rc;
}

/* An observable of src: its name below /observables and its samples. */
typedef struct series {
    char name[256];
    size_t n, at;
    int64_t *step;
    double *time, *value;
} series;

typedef struct series_list {
    series *s;
    size_t n, cap;
    hid_t file;
    int failed;
} series_list;

/* H5Ovisit callback: every dataset NAME/value is a series NAME. */
static herr_t find_series(hid_t obj, const char *name, const H5O_info_t *info, void *data) {
    (void)obj;
    series_list *l = data;
    const size_t len = strlen(name);
    if (info->type != H5O_TYPE_DATASET || len < 6 || strcmp(name + len - 6, "/value") != 0 ||
        len - 6 >= sizeof l->s->name)
        return 0;
    if (l->n == l->cap) {
        const size_t cap = l->cap ? 2 * l->cap : 32;
        series *ns = realloc(l->s, cap * sizeof *ns);
        if (!ns) {
            l->failed = 1;
            return 1;
        }
        l->s = ns;
        l->cap = cap;
    }
    series *s = &l->s[l->n++];
    memset(s, 0, sizeof *s);
    snprintf(s->name, sizeof s->name, "%.*s", (int)(len - 6), name);
    char path[400];
    snprintf(path, sizeof path, "/observables/%s/step", s->name);
    const hssize_t ns = rows_of(l->file, path, NULL);
    s->n = ns > 0 ? (size_t)ns : 0;
    s->step = read_all(l->file, path, H5T_NATIVE_INT64, s->n);
    snprintf(path, sizeof path, "/observables/%s/time", s->name);
    s->time = read_all(l->file, path, H5T_NATIVE_DOUBLE, s->n);
    snprintf(path, sizeof path, "/observables/%s/value", s->name);
    s->value = read_all(l->file, path, H5T_NATIVE_DOUBLE, s->n);
    if (!s->step || !s->time || !s->value) l->failed = 1;
    return l->failed;
}

/* The samples up to step, step by step as the run writes them (the writer flushes per step). */
static int copy_observables(hid_t f, jd_h5md *h, int64_t step, char *err, size_t errlen) {
    if (H5Lexists(f, "/observables", H5P_DEFAULT) <= 0) return 0;
    series_list l = {.file = f};
    hid_t g = H5Gopen2(f, "/observables", H5P_DEFAULT);
    if (g < 0 || H5Ovisit(g, H5_INDEX_NAME, H5_ITER_INC, find_series, &l) < 0)
        l.failed = 1;
    if (g >= 0) H5Gclose(g);
    int rc = l.failed ? -1 : 0;
    for (;;) {
        int64_t next = INT64_MAX;
        for (size_t k = 0; k < l.n; k++)
            if (l.s[k].at < l.s[k].n && l.s[k].step[l.s[k].at] < next) next = l.s[k].step[l.s[k].at];
        if (rc != 0 || next > step) break;
        for (size_t k = 0; k < l.n && rc == 0; k++) {
            series *s = &l.s[k];
            if (s->at < s->n && s->step[s->at] == next &&
                jd_h5md_write_observable(h, s->name, next, s->time[s->at], s->value[s->at], err,
                                         errlen) != 0)
                rc = -2;
            if (s->at < s->n && s->step[s->at] == next) s->at++;
        }
    }
    for (size_t k = 0; k < l.n; k++) {
        free(l.s[k].step);
        free(l.s[k].time);
        free(l.s[k].value);
    }
    free(l.s);
    return rc;
}

/* The rows of the bond table `group`, counted on its dataset `column`, into *n: 1, or 0 when
 * the run wrote no such table, or -1 when it cannot be read. */
static int table_rows(hid_t f, const char *group, const char *column, size_t *n) {
    if (H5Lexists(f, group, H5P_DEFAULT) <= 0) return 0;
    const hssize_t rows = rows_of(f, column, NULL);
    if (rows < 0) return -1;
    *n = (size_t)rows;
    return 1;
}

/* /jdem/bonds rows formed up to step. */
static int copy_bonds(hid_t f, jd_h5md *h, int64_t step, char *err, size_t errlen) {
    size_t n;
    const int present = table_rows(f, "/jdem/bonds", "/jdem/bonds/formed_step", &n);
    if (present <= 0) return present;
    int64_t *ids = read_all(f, "/jdem/bonds/ids", H5T_NATIVE_INT64, 2 * n);
    int32_t *type = read_all(f, "/jdem/bonds/type", H5T_NATIVE_INT32, n);
    int64_t *formed = read_all(f, "/jdem/bonds/formed_step", H5T_NATIVE_INT64, n);
    jd_h5md_bond *b = malloc((n ? n : 1) * sizeof *b);
    int rc = ids && type && formed && b ? 0 : -1;
    size_t m = 0;
    for (size_t k = 0; rc == 0 && k < n; k++)
        if (formed[k] <= step)
            b[m++] = (jd_h5md_bond){{ids[2 * k], ids[2 * k + 1]}, type[k], formed[k]};
    if (rc == 0 && jd_h5md_write_bonds(h, m, b, err, errlen) != 0) rc = -2;
    free(ids);
    free(type);
    free(formed);
    free(b);
    return rc;
}

/* /jdem/broken_bonds rows up to step. */
static int copy_breaks(hid_t f, jd_h5md *h, int64_t step, char *err, size_t errlen) {
    size_t n;
    const int present = table_rows(f, "/jdem/broken_bonds", "/jdem/broken_bonds/step", &n);
    if (present <= 0) return present;
    static const char *const scalar[] = {"normal_force", "shear_force", "twisting_moment",
                                         "bending_moment", "sigma_max", "tau_max", "time"};
    double *col[7];
    char path[96];
    int rc = 0;
    for (int c = 0; c < 7; c++) {
        snprintf(path, sizeof path, "/jdem/broken_bonds/%s", scalar[c]);
        if (!(col[c] = read_all(f, path, H5T_NATIVE_DOUBLE, n))) rc = -1;
    }
    int64_t *steps = read_all(f, "/jdem/broken_bonds/step", H5T_NATIVE_INT64, n);
    int64_t *ids = read_all(f, "/jdem/broken_bonds/ids", H5T_NATIVE_INT64, 2 * n);
    int32_t *mode = read_all(f, "/jdem/broken_bonds/mode", H5T_NATIVE_INT32, n);
    double *pos = read_all(f, "/jdem/broken_bonds/position", H5T_NATIVE_DOUBLE, 3 * n);
    jd_h5md_bond_break *e = malloc((n ? n : 1) * sizeof *e);
    if (!steps || !ids || !mode || !pos || !e) rc = -1;
    size_t m = 0;
    for (size_t k = 0; rc == 0 && k < n; k++) {
        if (steps[k] > step) continue;
        e[m++] = (jd_h5md_bond_break){
            .step = steps[k], .time = col[6][k], .id = {ids[2 * k], ids[2 * k + 1]},
            .mode = mode[k], .position = {pos[3 * k], pos[3 * k + 1], pos[3 * k + 2]},
            .normal_force = col[0][k], .shear_force = col[1][k], .twisting_moment = col[2][k],
            .bending_moment = col[3][k], .sigma_max = col[4][k], .tau_max = col[5][k]};
    }
    if (rc == 0 && jd_h5md_write_bond_breaks(h, m, e, err, errlen) != 0) rc = -2;
    for (int c = 0; c < 7; c++) free(col[c]);
    free(steps);
    free(ids);
    free(mode);
    free(pos);
    free(e);
    return rc;
}

/* The creators of the source's frames, earliest first: its "continues" list, then its own
 * version, on the new file's /h5md/creator ("continues"), so a result names every binary that
 * computed it. */
static int copy_creators(hid_t f, jd_h5md *h) {
    char version[128] = "", earlier[1024] = "", all[1200];
    const hid_t g = H5Gopen2(f, "/h5md/creator", H5P_DEFAULT);
    if (g < 0) return -1;
    const int rc = h5md_attr_read_str(g, "version", version, sizeof version);
    if (h5md_attr_read_str(g, "continues", earlier, sizeof earlier) != 0) earlier[0] = '\0';
    H5Gclose(g);
    if (rc != 0) return -1;
    snprintf(all, sizeof all, "%s%s%s", earlier, earlier[0] ? ", " : "", version);
    return h5md_set_continues(h, all);
}

int jd_h5md_resume_copy(const char *src, jd_h5md *h, int64_t frame_step, int64_t step,
                                  char *err, size_t errlen) {
    H5E_auto2_t fn;
    void *data;
    H5Eget_auto2(H5E_DEFAULT, &fn, &data);
    H5Eset_auto2(H5E_DEFAULT, NULL, NULL);
    hid_t f = open_ro(src);
    int rc = f < 0 ? -1 : copy_frames(f, h, frame_step, err, errlen);
    if (rc == 0) rc = copy_observables(f, h, step, err, errlen);
    if (rc == 0) rc = copy_bonds(f, h, step, err, errlen);
    if (rc == 0) rc = copy_breaks(f, h, step, err, errlen);
    if (rc == 0) rc = copy_creators(f, h);
    if (f >= 0) H5Fclose(f);
    H5Eset_auto2(H5E_DEFAULT, fn, data);
    if (rc == -1) /* a read failed (rc -2: the writer's message is in err) */
        snprintf(err, errlen, "cannot resume: the trajectory '%s' of the interrupted run cannot "
                 "be read back up to step %lld (damaged?); it is kept", src, (long long)step);
    return rc ? -1 : 0;
}

int jd_h5md_resume_rows(const char *src, int64_t frame_step, jd_h5md_particles *rows, char *err,
                        size_t errlen) {
    memset(rows, 0, sizeof *rows);
    H5E_auto2_t fn;
    void *data;
    H5Eget_auto2(H5E_DEFAULT, &fn, &data);
    H5Eset_auto2(H5E_DEFAULT, NULL, NULL);
    hid_t f = open_ro(src);
    hsize_t dims[3] = {0, 0, 0};
    const hssize_t n_static = f >= 0 ? rows_of(f, "/particles/all/radius", NULL) : -1;
    H5O_info_t info;
    rows->growing = f >= 0 && H5Lexists(f, "/particles/all/id", H5P_DEFAULT) > 0 &&
                    H5Oget_info_by_name(f, "/particles/all/id", &info, H5P_DEFAULT) >= 0 &&
                    info.type == H5O_TYPE_GROUP;
    int ok = n_static >= 0;
    size_t n = ok ? (size_t)n_static : 0;
    int64_t *id = malloc((n ? n : 1) * sizeof *id);
    ok = ok && id;
    if (ok && rows->growing) {
        const hssize_t nf = rows_of(f, "/particles/all/id/value", dims);
        int64_t *steps =
            nf > 0 ? read_all(f, "/particles/all/id/step", H5T_NATIVE_INT64, (size_t)nf) : NULL;
        const size_t live =
            nf > 0 && steps && dims[1] == n
                ? first_row_ids(f, (hsize_t)nf, prefix_frames(steps, nf, frame_step), n, id)
                : (size_t)-1;
        ok = nf == 0 || live != (size_t)-1;
        n = nf > 0 && ok ? live : 0;
        free(steps);
    } else if (ok) {
        int64_t *all = read_all(f, "/particles/all/id", H5T_NATIVE_INT64, n);
        ok = all != NULL;
        if (ok) memcpy(id, all, n * sizeof *id);
        free(all);
    }
    int32_t *species = ok ? read_all(f, "/particles/all/species", H5T_NATIVE_INT32, (size_t)n_static) : NULL;
    double *radius = ok ? read_all(f, "/particles/all/radius", H5T_NATIVE_DOUBLE, (size_t)n_static) : NULL;
    double *mass = ok ? read_all(f, "/particles/all/mass", H5T_NATIVE_DOUBLE, (size_t)n_static) : NULL;
    ok = ok && species && radius && mass;
    if (f >= 0) H5Fclose(f);
    H5Eset_auto2(H5E_DEFAULT, fn, data);
    rows->n = n;
    rows->id = id;
    rows->species = species;
    rows->radius = radius;
    rows->mass = mass;
    if (!ok) {
        jd_h5md_resume_rows_free(rows);
        snprintf(err, errlen, "cannot resume: the particle rows of the trajectory '%s' of the "
                 "interrupted run cannot be read (damaged?); it is kept", src);
        return -1;
    }
    return 0;
}

void jd_h5md_resume_rows_free(jd_h5md_particles *rows) {
    free((void *)rows->id);
    free((void *)rows->species);
    free((void *)rows->radius);
    free((void *)rows->mass);
    const int growing = rows->growing;
    memset(rows, 0, sizeof *rows);
    rows->growing = growing;
}
