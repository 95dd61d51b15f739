/*
 * h5md_internal.h — internal to the H5MD writer (io/h5md.c, io/h5md_util.c, io/xdmf.c): the
 * time-dependent groups, the error capture and the small HDF5 helpers, and the XDMF sidecar.
 */
#ifndef JDEM_IO_H5MD_INTERNAL_H
#define JDEM_IO_H5MD_INTERNAL_H

#include <hdf5.h>
#include <stddef.h>

#include "h5md.h"

/* The time-dependent groups under /particles/all. */
enum { TD_POSITION, TD_VELOCITY, TD_ANGVEL, TD_FORCE, TD_TORQUE, TD_COUNT };

/* h5md_util.c: error handling */
typedef struct {
    H5E_auto2_t fn;
    void *data;
    int saved; /* 0 if the caller's handler could not be read (e.g. set with H5Eset_auto1) */
} quiet_t;

void h5md_quiet_on(quiet_t *q, char *detail);
void h5md_quiet_off(const quiet_t *q);
void h5md_set_err(char *err, size_t errlen, const char *fmt, ...);
void h5md_err(const char *detail, char *err, size_t errlen, const char *fmt, ...);
void h5md_close_id(hid_t *id);

/* h5md_util.c: small HDF5 helpers; each returns 0 / -1 (or an invalid id) and leaves the HDF5
 * error stack for h5md_err */
hid_t h5md_str_type(size_t len);
hid_t h5md_str_type_cset(size_t len, H5T_cset_t cset);
int h5md_attr_write(hid_t obj, const char *name, hid_t ftype, hid_t mtype, int rank,
                    const hsize_t *dims, const void *buf);
int h5md_attr_str(hid_t obj, const char *name, const char *s);
/* A fixed-length string attribute into out (truncated to len - 1 characters); 0, or -1 when it
 * is absent or not such a string. */
int h5md_attr_read_str(hid_t obj, const char *name, char *out, size_t len);
int h5md_attr_int(hid_t obj, const char *name, int v);
int h5md_attr_double(hid_t obj, const char *name, double v);
hid_t h5md_group_create(hid_t loc, const char *name);
int h5md_dset_fixed(hid_t loc, const char *name, hid_t ftype, hid_t mtype, size_t n,
                    const void *buf, const char *unit);
hid_t h5md_dset_extendible(hid_t loc, const char *name, hid_t ftype, int rank,
                           const hsize_t *rest, const hsize_t *chunk);
int h5md_append_row(hid_t d, hsize_t at, int rank, const hsize_t *rest, hid_t mtype,
                    const void *buf);

/* h5md.c: hand everything written so far to the OS (a checkpoint then matches the file on
 * disk: stepper/checkpoint.h).  0 or -1. */
int jd_h5md_flush(jd_h5md *h);

/* h5md.c: what io/h5md_bonds.c needs of a writer.  A write that fails part-way sets *broken. */
typedef struct h5md_view {
    hid_t file;
    const char *part;   /* the file's current name (PATH.part) */
    char *detail;       /* HDF5 error capture buffer for h5md_quiet_on */
    int *broken;        /* set to 1 when a failed write left datasets inconsistent */
} h5md_view;
h5md_view h5md_view_of(jd_h5md *h);

/* h5md_util.c: append n rows (from `at`) to an extendible dataset of rank 1..3. */
int h5md_append_rows(hid_t d, hsize_t at, hsize_t n, int rank, const hsize_t *rest, hid_t mtype,
                     const void *buf);

/* h5md_file.c: the file on disk.  h5md_part_open refuses a directory at PATH or SIDECAR and a
 * link or non-regular file at PART, takes an exclusive lock on PART (another run holding it is
 * an error) and only then truncates it; the descriptor (*fd, kept open for the lock) is closed
 * by the caller after the final rename.  h5md_part_create has HDF5 create PART and checks that
 * it is the locked file.  h5md_publish renames PART to PATH, then SIDECAR_PART to SIDECAR. */
int h5md_part_open(const char *path, const char *part, const char *sidecar, int *fd, char *err,
                   size_t errlen);
hid_t h5md_part_create(const char *part, int fd, char *err, size_t errlen, char *detail);
int h5md_part_readable(const char *part);
int h5md_part_keep_or_remove(const char *part, int clean, char *err, size_t errlen);
int h5md_publish(const char *part, const char *path, const char *sidecar_part,
                 const char *sidecar, char *err, size_t errlen);

/* h5md_walls.c: the walls' surface mesh (quadrilaterals) */
typedef struct h5md_wall_mesh {
    int present;     /* jd_h5md_set_walls was called */
    int moving;      /* some wall moves: vertex_position holds the vertices per frame */
    size_t nv, nq;   /* vertices, quadrilaterals */
    double *vert0;   /* [nv][3] vertices at time 0 [m] */
    double *vel;     /* [nv][3] their velocity [m/s] */
    double *now;     /* [nv][3] where a moved mesh's vertices are (jd_h5md_move_mesh) [m] */
    unsigned char *given; /* [nv] 1: the vertex of a moved mesh (its position is `now`) */
    size_t n_walls;
    size_t *first_vertex; /* [n_walls] each wall's first vertex */
    size_t *n_vertices;   /* [n_walls] and its count; a moved mesh's vertices are `given` */
    hid_t position;  /* /jdem/walls/mesh/vertex_position [F][nv][3] when moving */
} h5md_wall_mesh;

/* Write /jdem/walls (description and mesh); fills m.  0 / -1. */
int h5md_walls_write(hid_t file, size_t n, const jd_h5md_wall *walls, h5md_wall_mesh *m);
/* Append the vertices of frame `frame` at `time` [s] (moving walls only).  0 / -1. */
int h5md_walls_frame(h5md_wall_mesh *m, hsize_t frame, double time);
void h5md_walls_free(h5md_wall_mesh *m);
/* The writer's walls (h5md.c), for the resumed run's copy of a prefix (h5md_resume.c). */
h5md_wall_mesh *h5md_walls_of(struct jd_h5md *h);
/* The writer's particle rows so far (h5md.c). */
size_t h5md_rows_count(const struct jd_h5md *h);
/* Record on /h5md/creator, attribute "continues", the creators of the frames a resumed run
 * copied (h5md_resume.c).  0 or -1. */
int h5md_set_continues(struct jd_h5md *h, const char *creators);
/* A moved mesh's triangles where they are now.  0 / -1 (wall k is not a moved mesh of n_tri). */
int h5md_walls_move_mesh(h5md_wall_mesh *m, size_t k, const double (*tri)[3][3], size_t n_tri);

/* A run of consecutive live rows [start, start + count) in one frame. */
typedef struct xdmf_run {
    hsize_t start, count;
} xdmf_run;

/* h5md_rows.c: the particle rows (time-independent data; the growing set's id per frame) */
typedef struct h5md_rows {
    int growing;          /* jd_h5md_particles.growing */
    size_t n;             /* rows so far */
    int64_t *row_id;      /* [n] the particle of each row */
    hid_t species, radius, mass; /* growing: extendible datasets [n] */
    hid_t id_grp, id_value;      /* growing: /particles/all/id and its value [F][n] */
    const int64_t *frame_id;     /* growing: the ids of the frame being written */
    double *scratch;             /* growing: one vector of the frame with NaN in empty rows */
    xdmf_run *runs;              /* live runs of every frame */
    size_t nruns, runs_cap;
    size_t *frame_runs;          /* [nframes + 1] */
    size_t nframes, frame_cap;
} h5md_rows;

/* Write id (fixed set), species, radius, mass under `all`.  0 / -1. */
int h5md_rows_create(h5md_rows *r, hid_t all, const jd_h5md_particles *p);
/* Least rows per chunk along the particle axis of a growing set (its final size is unknown,
 * so a chunk holds the initial rows or this many, whichever is more), and most frames: a small
 * set's file stays small whatever it grows to. */
#define GROWING_CHUNK_ROWS 64
#define GROWING_CHUNK_FRAMES 16
/* A per-particle value dataset [0][n][3] in grp (extendible along the particles too when
 * growing, fill NaN). */
hid_t h5md_rows_value(const h5md_rows *r, hid_t grp, const hsize_t chunk[3]);
/* At the first frame: the growing set's id element, step/time linked from position/. */
int h5md_rows_setup(h5md_rows *r, hid_t all, hid_t position);
/* Before a frame's vectors: add its new rows, append its ids, record its live runs.  0, or -1
 * with a reason in why. */
int h5md_rows_frame(h5md_rows *r, const jd_h5md_frame *f, hsize_t frame, char *why,
                    size_t whylen);
/* v, or (growing) a copy of it with NaN in the frame's empty rows; valid until the next call. */
const double *h5md_rows_vector(h5md_rows *r, const double *v);
void h5md_rows_close(h5md_rows *r); /* the HDF5 objects */
void h5md_rows_free(h5md_rows *r);  /* and the memory */

/* h5md_bond_lines.c: /jdem/bond_lines, the intact bonds of each frame as row pairs.  Reads the
 * bond tables back from the file; row_id [n] is the particle of each row.  Fills start/count
 * [nframes] (the frames' ranges of /jdem/bond_lines/rows); *total = its rows.  0 / -1. */
int h5md_bond_lines(hid_t file, const int64_t *row_id, size_t n, const int64_t *steps,
                    hsize_t nframes, hsize_t *start, hsize_t *count, hsize_t *total);

/* xdmf.c: what the sidecar needs of a closed writer */
typedef struct xdmf_info {
    const char *path; /* final .h5 path */
    size_t n;         /* rows (the particle axis of every per-particle dataset) */
    int growing;      /* id is /particles/all/id/value [F][n] */
    hsize_t nframes;
    const double *times;
    const int *present;
    const xdmf_run *runs;      /* the live runs of every frame, frame after frame */
    const size_t *frame_runs;  /* [nframes + 1]: frame f's runs are [frame_runs[f], frame_runs[f+1]) */
    const h5md_wall_mesh *walls;
    int bonds;                 /* /jdem/bond_lines exists */
    const hsize_t *bond_start, *bond_count; /* [nframes] */
    hsize_t bond_rows;         /* rows of /jdem/bond_lines/rows */
} xdmf_info;

/* PATH with its extension replaced by .xdmf (malloc'd; NULL when out of memory). */
char *xdmf_path(const char *path);
/* Write the sidecar of h to TMP (an existing TMP is replaced, never followed). */
int xdmf_write(const xdmf_info *h, const char *tmp, char *err, size_t errlen);

#endif
