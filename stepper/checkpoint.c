/*
 * checkpoint.c — the checkpoint file: its identity (format, version, scene hash, thread count,
 * reference options), the atomic write and the checked read.  The state itself is
 * checkpoint_state.c.
 */
#include <errno.h>
#include <fcntl.h>
#include <inttypes.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "checkpoint_io.h"
#include "mesh_walls.h"

#define FORMAT_NAME "jdem checkpoint"
#define VALID_CHECKPOINT "valid: a checkpoint written by 'jdem run --checkpoint' for this scene"

void jd_checkpointer_init(jd_checkpointer *ck, const char *path, int64_t every_steps,
                          double every_seconds, uint64_t scene_hash, const char *scene_name,
                          const char *case_name) {
    *ck = (jd_checkpointer){.path = path, .every_steps = every_steps,
                            .every_seconds = every_seconds, .scene_hash = scene_hash,
                            .scene_name = scene_name, .case_name = case_name,
                            .t_last = sim_clock(), .last_step = -1, .resumed_step = -1};
}

uint64_t jd_checkpoint_scene_hash(const char *resolved_yaml) {
    return ck_fnv1a(resolved_yaml, strlen(resolved_yaml));
}

/* The run's identity: what must match for a resumed run to compute the same bits. */
typedef struct identity {
    int64_t version, scene_hash, threads, options[4];
} identity;

static identity identity_of(const jd_sim *s, const jd_checkpointer *ck) {
    return (identity){.version = JD_CHECKPOINT_VERSION, .scene_hash = (int64_t)ck->scene_hash,
                      .threads = s->threads.n,
                      .options = {s->opt.allpairs, s->opt.no_sort, s->opt.all_laws,
                                  s->opt.plain_loops}};
}

static int attr_str(hid_t obj, const char *name, const char *value) {
    hid_t t = H5Tcopy(H5T_C_S1), sp = H5Screate(H5S_SCALAR), a = H5I_INVALID_HID;
    int ok = t >= 0 && sp >= 0 && H5Tset_size(t, strlen(value) + 1) >= 0 &&
             (a = H5Acreate2(obj, name, t, sp, H5P_DEFAULT, H5P_DEFAULT)) >= 0 &&
             H5Awrite(a, t, value) >= 0;
    if (a >= 0) H5Aclose(a);
    if (sp >= 0) H5Sclose(sp);
    if (t >= 0) H5Tclose(t);
    return ok ? 0 : -1;
}

/* A string attribute into buf ("" when absent or not a string). */
static void attr_read_str(hid_t obj, const char *name, char *buf, size_t len) {
    buf[0] = '\0';
    if (H5Aexists(obj, name) <= 0) return;
    hid_t a = H5Aopen(obj, name, H5P_DEFAULT), ft = a >= 0 ? H5Aget_type(a) : H5I_INVALID_HID;
    if (ft >= 0 && H5Tget_class(ft) == H5T_STRING && H5Tget_size(ft) < len) {
        hid_t t = H5Tcopy(H5T_C_S1);
        H5Tset_size(t, H5Tget_size(ft));
        if (H5Aread(a, t, buf) < 0) buf[0] = '\0';
        buf[len - 1] = '\0';
        H5Tclose(t);
    }
    if (ft >= 0) H5Tclose(ft);
    if (a >= 0) H5Aclose(a);
}

/* What the resume needs besides the state: the progress so far. */
static void ck_progress(ck_io *io, double *elapsed, double *particle_steps) {
    ck_double(io, "progress/elapsed", elapsed);
    ck_double(io, "progress/particle_steps", particle_steps);
}

static void ck_identity(ck_io *io, identity *id) {
    ck_array(io, "identity/format_version", H5T_NATIVE_INT64, 1, &id->version);
    ck_array(io, "identity/scene_hash", H5T_NATIVE_INT64, 1, &id->scene_hash);
    ck_array(io, "identity/threads", H5T_NATIVE_INT64, 1, &id->threads);
    ck_array(io, "identity/options", H5T_NATIVE_INT64, 4, id->options);
}

static int write_file(ck_io *io, const jd_sim *s, const jd_checkpointer *ck, double elapsed,
                      double particle_steps) {
    identity id = identity_of(s, ck);
    if (attr_str(io->file, "format", FORMAT_NAME) != 0 ||
        attr_str(io->file, "scene_name", ck->scene_name) != 0 ||
        attr_str(io->file, "case_name", ck->case_name) != 0)
        ck_fail(io, "cannot write the attributes of '%s'", io->path);
    ck_identity(io, &id);
    ck_progress(io, &elapsed, &particle_steps);
    /* the traversal only reads s when writing */
    ck_state(io, (jd_sim *)s);
    uint64_t digest = io->digest;
    ck_array(io, "digest", H5T_NATIVE_UINT64, 1, &digest);
    return io->failed ? -1 : 0;
}

/* fsync of a file or directory by name: 0 or -1 (errno set). */
static int sync_path(const char *path, int flags) {
    const int fd = open(path, flags);
    if (fd < 0) return -1;
    const int rc = fsync(fd);
    const int e = errno;
    close(fd);
    errno = e;
    return rc;
}

/* A checkpoint file, created (truncated) or opened read-only, without HDF5's file locks: the
 * file is this run's alone, and locking fails on some network file systems. */
static hid_t open_unlocked(const char *path, int create) {
    hid_t fapl = H5Pcreate(H5P_FILE_ACCESS);
    if (fapl >= 0) H5Pset_file_locking(fapl, 0, 1);
    const hid_t f = create ? H5Fcreate(path, H5F_ACC_TRUNC, H5P_DEFAULT, fapl)
                           : H5Fopen(path, H5F_ACC_RDONLY, fapl);
    if (fapl >= 0) H5Pclose(fapl);
    return f;
}

static void directory_of(const char *path, char *dir, size_t len) {
    const char *slash = strrchr(path, '/');
    if (!slash) snprintf(dir, len, ".");
    else if (slash == path) snprintf(dir, len, "/");
    else snprintf(dir, len, "%.*s", (int)(slash - path), path);
}

int jd_checkpoint_write(const jd_sim *s, const jd_checkpointer *ck, double elapsed,
                        double particle_steps, char *err, size_t errlen) {
    char tmp[4200], why[9000] = "", dir[4200];
    snprintf(tmp, sizeof tmp, "%s.tmp", ck->path);
    H5E_auto2_t fn;
    void *data;
    H5Eget_auto2(H5E_DEFAULT, &fn, &data);
    H5Eset_auto2(H5E_DEFAULT, NULL, NULL);
    ck_io io = {.reading = 0, .path = tmp, .err = why, .errlen = sizeof why};
    io.file = open_unlocked(tmp, 1);
    int rc = -1;
    if (io.file < 0) {
        snprintf(why, sizeof why, "cannot create '%s': %s", tmp, errno ? strerror(errno) : "HDF5 error");
    } else {
        const int wrote = write_file(&io, s, ck, elapsed, particle_steps);
        const int closed = H5Fclose(io.file) >= 0;
        if (wrote == 0 && !closed) snprintf(why, sizeof why, "cannot close '%s' (disk full?)", tmp);
        errno = 0;
        if (wrote == 0 && closed && sync_path(tmp, O_RDONLY) != 0)
            snprintf(why, sizeof why, "cannot sync '%s': %s", tmp, strerror(errno));
        else if (wrote == 0 && closed && rename(tmp, ck->path) != 0)
            snprintf(why, sizeof why, "cannot rename '%s' to '%s': %s", tmp, ck->path, strerror(errno));
        else if (wrote == 0 && closed)
            rc = 0;
    }
    H5Eset_auto2(H5E_DEFAULT, fn, data);
    if (rc != 0) {
        unlink(tmp);
        snprintf(err, errlen, "checkpoint at step %lld failed: %s; the previous checkpoint '%s' "
                 "is unchanged", (long long)s->step, why, ck->path);
        return -1;
    }
    directory_of(ck->path, dir, sizeof dir);
    (void)sync_path(dir, O_RDONLY | O_DIRECTORY); /* the rename's durability; not all file
                                                     systems sync a directory */
    return 0;
}

/* The identity of the file against this run's: 0, or -1 with the reason. */
static int check_identity(ck_io *io, const identity *want, const jd_checkpointer *ck) {
    identity have;
    char scene[256], case_name[256];
    ck_array(io, "identity/format_version", H5T_NATIVE_INT64, 1, &have.version);
    if (io->failed) return -1;
    if (have.version != want->version) {
        ck_fail(io, "cannot resume: checkpoint '%s' has format version %lld; this jdem reads "
                "version %d", io->path, (long long)have.version, JD_CHECKPOINT_VERSION);
        return -1;
    }
    io->digest = 0; /* as at the write, which passes the version once */
    ck_identity(io, &have);
    if (io->failed) return -1;
    attr_read_str(io->file, "scene_name", scene, sizeof scene);
    attr_read_str(io->file, "case_name", case_name, sizeof case_name);
    if (have.scene_hash != want->scene_hash) {
        ck_fail(io, "cannot resume: checkpoint '%s' is of another scene (scene '%s', case '%s', "
                "resolved-scene hash %016" PRIx64 "); this run is scene '%s', case '%s', hash "
                "%016" PRIx64 "; valid: the scene and case the checkpoint was written for, "
                "unchanged", io->path, scene, case_name, (uint64_t)have.scene_hash,
                ck->scene_name, ck->case_name, (uint64_t)want->scene_hash);
        return -1;
    }
    if (have.threads != want->threads) {
        ck_fail(io, "cannot resume: checkpoint '%s' was written with --threads %lld, this run has "
                "%lld; valid: --threads %lld (another count sums the forces in another order)",
                io->path, (long long)have.threads, (long long)want->threads,
                (long long)have.threads);
        return -1;
    }
    if (memcmp(have.options, want->options, sizeof have.options) != 0) {
        ck_fail(io, "cannot resume: checkpoint '%s' was written with other reference options "
                "(JDEM_NEIGHBOUR=allpairs, --no-sort, --all-laws, --plain-loops: %lld %lld %lld "
                "%lld, this run %lld %lld %lld %lld); valid: the same options", io->path,
                (long long)have.options[0], (long long)have.options[1], (long long)have.options[2],
                (long long)have.options[3], (long long)want->options[0],
                (long long)want->options[1], (long long)want->options[2],
                (long long)want->options[3]);
        return -1;
    }
    return 0;
}

/* After the state is in place: what the run derives from it (the fast paths' view of the
 * particles, the threads' shares, the wall-force room), as a neighbour build leaves it. */
static int derive(jd_sim *s, char *err, size_t errlen) {
    s->lists.n_built = s->particles.n; /* a checkpoint is written between steps, after any build */
    sim_particle_kinds(&s->fast, &s->particles, s->run.n_materials, s->opt.plain_loops);
    if (sim_forces_partition(&s->threads, &s->lists, s->particles.n) != 0) {
        snprintf(err, errlen, "out of memory for the force buffers of %d threads", s->threads.n);
        return -1;
    }
    if (s->meshes && sim_mesh_walls_restored(s->meshes, err, errlen) != 0) return -1;
    return sim_walls_reserve(&s->walls, s->lists.wall_pairs.n, err, errlen);
}

static int read_file(ck_io *io, jd_sim *s, jd_checkpointer *ck) {
    char format[64];
    attr_read_str(io->file, "format", format, sizeof format);
    if (strcmp(format, FORMAT_NAME) != 0) {
        ck_fail(io, "cannot resume: '%s' is not a jdem checkpoint (it has no format attribute "
                "'" FORMAT_NAME "'); " VALID_CHECKPOINT, io->path);
        return -1;
    }
    const identity want = identity_of(s, ck);
    if (check_identity(io, &want, ck) != 0) return -1;
    ck_progress(io, &ck->elapsed, &ck->particle_steps);
    ck_state(io, s);
    const uint64_t computed = io->digest;
    uint64_t stored = 0;
    ck_array(io, "digest", H5T_NATIVE_UINT64, 1, &stored);
    if (!io->failed && stored != computed)
        ck_fail(io, "cannot resume: checkpoint '%s' is corrupt (its values do not match their "
                "digest); " VALID_CHECKPOINT, io->path);
    return io->failed ? -1 : 0;
}

int jd_checkpoint_read(jd_sim *s, jd_checkpointer *ck, const char *path, char *err,
                       size_t errlen) {
    if (access(path, R_OK) != 0) {
        snprintf(err, errlen, "cannot resume: checkpoint '%s': %s; " VALID_CHECKPOINT, path,
                 strerror(errno));
        return JD_CHECKPOINT_REFUSED;
    }
    H5E_auto2_t fn;
    void *data;
    H5Eget_auto2(H5E_DEFAULT, &fn, &data);
    H5Eset_auto2(H5E_DEFAULT, NULL, NULL);
    ck_io io = {.reading = 1, .path = path, .err = err, .errlen = errlen};
    io.file = open_unlocked(path, 0);
    int rc = 0;
    if (io.file < 0) {
        snprintf(err, errlen, "cannot resume: '%s' is not a readable HDF5 file (truncated or "
                 "corrupt); " VALID_CHECKPOINT, path);
        rc = JD_CHECKPOINT_REFUSED;
    } else {
        if (read_file(&io, s, ck) != 0)
            rc = io.no_memory ? JD_CHECKPOINT_NO_MEMORY : JD_CHECKPOINT_REFUSED;
        H5Fclose(io.file);
    }
    H5Eset_auto2(H5E_DEFAULT, fn, data);
    if (rc == 0 && derive(s, err, errlen) != 0) rc = JD_CHECKPOINT_NO_MEMORY;
    if (rc == 0) {
        ck->resumed_step = ck->last_step = s->step;
        ck->t_last = sim_clock();
    }
    return rc;
}
