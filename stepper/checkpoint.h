/*
 * checkpoint.h — checkpoints of a run and resuming from one (docs/scenes.md "Checkpoints",
 * docs/output.md "Resumed runs", docs/architecture.md "What a checkpoint stores").
 *
 * A checkpoint is an HDF5 file holding every piece of state that changes the arithmetic of the
 * steps still to come, taken at the top of the run loop after the output of step N and before
 * step N + 1 is computed: a run resumed from it computes the same bits as the uninterrupted run
 * (same scene, same thread count, same reference options).  Derived state (the threads' shares,
 * what the fast paths may assume, the wall-force room) is recomputed from the restored parts by
 * the functions that compute it during a run; scratch (overflow buffers, the cell arrays, the
 * spare lists) is not stored, since every use overwrites it first.
 *
 * The file is written as PATH.tmp, flushed to disk (fsync) and renamed over PATH, then the
 * directory is synced: a failure or a signal during the write leaves the previous checkpoint
 * as it was.
 */
#ifndef JDEM_CHECKPOINT_H
#define JDEM_CHECKPOINT_H

#include <stddef.h>
#include <stdint.h>

#include "sim.h"

/* The checkpoint file format this build writes and reads (attribute `format_version`); 2 added
 * each particle's half skin (lists/half_skin). */
#define JD_CHECKPOINT_VERSION 2

/* When to write checkpoints, where, and (after a resume) what the run did before. */
typedef struct jd_checkpointer {
    const char *path;          /* checkpoint file */
    int64_t every_steps;       /* a checkpoint at every multiple of this step count (0: none) */
    double every_seconds;      /* and whenever this much wall time has passed since the last
                                  one or the start (0: none) [s] */
    /* the run's identity, written into the file and checked at a resume */
    uint64_t scene_hash;       /* jd_checkpoint_scene_hash of the resolved scene */
    const char *scene_name, *case_name;
    /* where the run stands */
    double t_last;             /* sim_clock() at the last checkpoint or the start [s] */
    int64_t last_step;         /* step of the last checkpoint written, -1: none */
    int64_t resumed_step;      /* step the run resumed at (its output is in the trajectory
                                  already), -1: a fresh run */
    double elapsed;            /* wall time of the time loop before the resume [s] (progress) */
    double particle_steps;     /* sum of the particles over the steps before the resume */
} jd_checkpointer;

/* A fresh checkpointer (no resume, nothing written yet). */
void jd_checkpointer_init(jd_checkpointer *ck, const char *path, int64_t every_steps,
                          double every_seconds, uint64_t scene_hash, const char *scene_name,
                          const char *case_name);

/* FNV-1a (64 bit) of the resolved scene text (scene_yaml_string): the run's identity. */
uint64_t jd_checkpoint_scene_hash(const char *resolved_yaml);

/* sim_run with checkpoints (ck may be NULL: sim_run).  A checkpoint is written when one is due
 * (every_steps, every_seconds) and, before the run stops, when *s->stop is set.  A failed
 * checkpoint write stops the run with JD_RUN_OUTPUT and its message in err; the previous
 * checkpoint is intact.  After jd_checkpoint_read, the run continues from the checkpoint's
 * step without writing that step's output again. */
int sim_run_checkpointed(jd_sim *s, struct jd_h5md *h, int show_progress, jd_checkpointer *ck,
                         char *err, size_t errlen);

/* Write the state of s (set up by sim_init, stopped at the top of the run loop) to ck->path
 * atomically.  elapsed, particle_steps: the progress so far.  0, or -1 with err. */
int jd_checkpoint_write(const jd_sim *s, const jd_checkpointer *ck, double elapsed,
                        double particle_steps, char *err, size_t errlen);

/* Results of jd_checkpoint_read besides 0. */
enum { JD_CHECKPOINT_REFUSED = -1, JD_CHECKPOINT_NO_MEMORY = -2 };
/* Restore the state of checkpoint `path` into s, set up by sim_init from the same scene: the
 * file must exist, be a checkpoint of this format version, of the scene ck->scene_hash, and of
 * the same thread count and reference options.  Fills ck's resume fields.  0, or
 * JD_CHECKPOINT_REFUSED / JD_CHECKPOINT_NO_MEMORY with err (the file and what is wrong). */
int jd_checkpoint_read(jd_sim *s, jd_checkpointer *ck, const char *path, char *err,
                       size_t errlen);

/* What the checkpoint needs of the modules whose state is private to their files. */
/* loads.c: the loaded particles (n), their indices and the 6 n forces of the last evaluation */
size_t sim_loads_state(jd_loads *l, int32_t **index, int32_t **scene, double **f_prev);
/* A checkpoint's count of loaded particles, n <= the current one (the domain deletes some). */
void sim_loads_set_count(jd_loads *l, size_t n);
/* bonds.c: room for need bonds (0 or -1) */
int sim_bonds_reserve(jd_bonds *b, size_t need);
/* inlet.c: the streams' state (n_inlets of them) */
typedef struct jd_inlet_state_view {
    size_t n_inlets;
    int64_t *next_step;        /* the smallest next_step of the streams */
    double *energy_in, *seconds;
    int64_t *lost;             /* particles deleted outside the domain (domain.c) */
    double *energy_lost;       /* the energy they took [J] */
    int64_t *id;               /* [capacity] id of each scene index */
    int32_t *slot;             /* [capacity] its trajectory row */
} jd_inlet_state_view;
void sim_inlets_state(jd_sim *s, jd_inlet_state_view *v);
/* stream k: its counters and its cursors (*n of them) */
struct jd_inlet_stream;
struct jd_inlet_stream *sim_inlets_stream(jd_sim *s, size_t k, size_t *n);

#endif /* JDEM_CHECKPOINT_H */
