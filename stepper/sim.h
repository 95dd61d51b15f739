/*
 * sim.h — the standalone engine: state of one run and the functions that advance it.
 *
 * One file per mechanism (REBOUND style):
 *   sim.c          set-up from a resolved scene, the run loop with output, tear-down
 *   neighbour.c    cell list -> half Verlet list with skin, wall candidates, history carry-over
 *   reorder.c      spatial sorting of the particles at rebuilds (remapping what holds indices)
 *   walls.c        wall set-up and rigid translation
 *   geometry.h     contact geometry (kernel/jdem_geometry.h) plus material fields (inline)
 *   forces.c       force loops, specialised at compile time for the scene's feature set
 *   integrate.c    one velocity-Verlet step exactly as LIGGGHTS fix nve/sphere
 *   observables.c  energies and contact counts
 *   guard.c        the time-step guard
 *   bonds.c        parallel bonds: list, rules, bond loop, events, observables (bonds.h)
 *   loads.c        held particles and constant external forces, with their work
 *   watchdog.c     the run-time watchdog: non-finite state, excessive overlap, energy jumps
 *   progress.c     the progress line on stderr
 *
 * Data layout.  Particle vectors (x, v, omega, f, torque) are arrays of 3n doubles, x0 y0 z0 x1
 * ...: the kernel takes double[3] arguments, so a contact passes &x[3i] without gathering; the
 * three components of one particle share a cache line (a contact reads all three at once); and
 * the H5MD writer takes exactly this layout, so frames are written without a copy.  Per-particle
 * constants are separate arrays (structure of arrays) so that each loop streams only what it
 * uses.  Pairs are always i < j.
 *
 * Parts.  A run (jd_sim) is a set of parts that each hold one kind of thing: the particles
 * (jd_particles), the run's constants (jd_run_constants), the options of the reference paths
 * (jd_sim_options), what the fast paths may assume (jd_fast_paths), the threads' shares of the
 * loops (jd_thread_layout), the contact lists and their neighbour search (jd_neighbour_lists),
 * the walls (jd_walls), the accounts of time and energy (jd_accounts), what the watchdog has
 * seen (jd_watch), and the optional modules (bonds, loads, inlets).  A pass takes pointers to
 * the parts it reads (const) and writes; only the passes that drive others (sim_run, sim_step,
 * sim_compute_forces, sim_neighbour_build with its renumbering, the inlets) take the whole run.
 * docs/architecture.md lists which pass touches which part.
 *
 * Particle order.  At every full neighbour build the particles are renumbered in the order of
 * their neighbour cells (reorder.c), so that the particles of one cell, and the neighbours a
 * contact loop visits, lie close in memory.  orig[i] is the scene index (position in the scene,
 * sorted by id) of the particle now at index i; everything the engine shows (frames, watchdog
 * messages) is translated back to scene order.  Every other holder of particle indices that
 * outlives a rebuild (bonds, loads) is remapped by sim_reorder through its permute function
 * (sim_bonds_permute, sim_loads_permute), and reads scene data through orig.
 *
 * Threads (OpenMP).  At every neighbour build the particles are split into one contiguous range
 * per thread, so that the threads get about equal estimated work: pair entries that touched at
 * the build, the cheaper ones that did not, and wall entries (jd_thread_share).  A thread
 * zeroes the forces of its particles, evaluates their pairs and walls and adds straight into f
 * and torque, except for a pair partner j beyond its range: that goes into the thread's
 * overflow buffer, which covers only the few particles past the range that
 * its pairs reach (pairs list j > i in cell order).  After one barrier each thread adds the
 * earlier threads' overflow into its own particles, in thread order.  No two threads write the
 * same memory, no atomics, and no full-size buffer to reduce.  For a given thread count the
 * sums are always taken in the same order, so a run is reproducible bit for bit, and runs with
 * different thread counts differ only by the round-off of that order; with one thread the
 * loops are exactly the serial ones.  Integration loops are split by particle.
 */
#ifndef JDEM_SIM_H
#define JDEM_SIM_H

#include <signal.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include "bonds.h"
#include "jdem_geometry.h"
#include "jdem_guard.h"
#include "jdem_kernel.h"
#include "jdem_laws.h"
#include "jdem_observable_names.h"
#include "jdem_watchdog.h"
#include "scene.h"

/* Material constants of a particle pair (sim_pair_constants).  The force loops compute them per
 * contact from the particles' constants, or, when all particles are alike, take the scene's
 * single set (jd_fast_paths.pc_alike); the lists store none, which keeps an entry at 40 bytes (56
 * with rolling) instead of 56 (88). */
typedef struct jd_pair_const {
    double k_n;       /* Hertz prefactor of the pair (eq. 5) [N/m^1.5] */
    double m_eff;     /* effective mass [kg] */
} jd_pair_const;

/* The rolling law's constants of a pair (scenes with rolling resistance only). */
typedef struct jd_pair_const_roll {
    double i_eff;     /* effective moment of inertia [kg m^2] */
    double r_roll;    /* rolling radius R_a R_b/(R_a + R_b) [m] */
} jd_pair_const_roll;

/* Run options that are not part of the scene (command line): the reference paths. */
typedef struct jd_sim_options {
    int allpairs;     /* debugging reference: every pair listed, never sorted; the list is built
                         again whenever the default one would be, so that its entries are split
                         alike (jd_contact_list) and the forces summed in the same order */
    int no_sort;      /* keep the scene's particle order (reference for the sorted path) */
    int all_laws;     /* evaluate every law even where its coefficient makes it vanish (the
                         general loop; reference for the feature-specialised ones) */
    int plain_loops;  /* the reference for the fast paths: one contact at a time instead of
                       * SIMD batches, gravity in a pass of its own, the integration constants
                       * read per particle, the rebuild check against x_build at every step */
} jd_sim_options;

/* Wall-clock seconds spent in each part of the time loop (CLOCK_MONOTONIC). */
typedef struct jd_timing {
    double neighbour;   /* rebuild check and rebuilds, including the reordering */
    double pairs;       /* particle-pair force loop, zeroing and the reduction of the buffers */
    double walls;       /* particle-wall force loop */
    double integration; /* half kicks, drift, non-finite probes, wall motion, and the weight
                         * when the kicks add it (weight_in_kick) */
    double output;      /* frames, observables and the energy watchdog */
    double loop;        /* the whole time loop (sim_run), the parts above and what they leave
                         * out: the bonds' events, the per-step watchdog, progress; what
                         * LIGGGHTS reports as "Loop time" */
} jd_timing;

/* A list of contact candidates (i, j), with the history of each contact stored alongside.  For
 * particle pairs j is a particle index (> i); for wall candidates a wall index.  The entries
 * [0, n_touch) and [n_touch, n) are each sorted by (i, j).  A wall list, and a pair list between
 * renumbering and rebuilding, is one sorted run (n_touch = n); a pair list as built has the
 * candidates whose spheres touched at the build first, those within their half skins but apart
 * second:
 * the force loop evaluates the first in every SIMD lane and tests the second before packing the
 * few that touch into lanes (forces.c), so that no lane is spent on a gap that stays a gap.
 * Buffers grow geometrically and are reused across rebuilds (no allocation per contact).
 *
 * The history of entry c is the first hw doubles of the kernel's jd_contact_state (xi and flags;
 * all of it with the energy bookkeeping) at hist + hw c, and the first rw doubles of
 * jd_rolling_state (theta; with the bookkeeping also m_prev; rw = 0 without rolling resistance)
 * at rhist + rw c: a scene stores only the history its laws use (jd_contact reads and writes
 * the energy fields only with JD_F_ENERGY). */
typedef struct jd_contact_list {
    size_t n, cap;
    size_t n_touch;         /* entries of the first sorted run (see above) */
    int32_t *i, *j;
    int hw, rw;             /* doubles of history per entry */
    double *hist;           /* cap x hw */
    double *rhist;          /* cap x rw; NULL without rolling resistance */
} jd_contact_list;

/* The history of entry c as the kernel's structs (fields the list does not keep are zero); r may
 * be NULL.  The records' layout is the kernel's (jdem_laws.h, jd_record_*). */
static inline void sim_hist_get(const jd_contact_list *l, size_t c, jd_contact_state *st,
                                jd_rolling_state *r) {
    jd_record_load(l->hist + (size_t)l->hw * c, l->hw, l->rw ? l->rhist + (size_t)l->rw * c : NULL,
                   l->rw, st, r);
}

/* Store the kept fields of st (and r, if the list has rolling history) as entry c's history. */
static inline void sim_hist_set(jd_contact_list *l, size_t c, const jd_contact_state *st,
                                const jd_rolling_state *r) {
    jd_record_store(l->hist + (size_t)l->hw * c, l->hw,
                    r && l->rw ? l->rhist + (size_t)l->rw * c : NULL, r ? l->rw : 0, st, r);
}

/* A wall as the engine moves it: the kernel's shape (translated in place) plus what the engine
 * needs around it. */
typedef struct jd_sim_wall {
    int type;          /* jd_wall_type: which of plane / cyl is used */
    int material;      /* index into the scene's materials */
    double v[3];       /* translation velocity [m/s] */
    jd_plane plane;
    jd_cylinder cyl;
    double spin;       /* cylinder: angular velocity about its axis [rad/s]
                          (jd_cylinder_surface_velocity) */
    double disp[3];    /* translation since the last neighbour build [m] */
    double force[3];   /* the particles' total force on the wall at the last evaluation [N]
                          (scenes with a servo wall: wall_forces) */
    /* servo (the scene's has_servo): v = speed n, set from the stress after every evaluation */
    int servo;
    jd_servo_spec spec;     /* hold_steps from the scene's hold and dt */
    jd_servo_state state;
    double area;            /* [m^2] */
    double stress;          /* measured at the last evaluation [Pa] */
    double speed;           /* along n, for the next step [m/s] */
    double position;        /* displacement along n since the start [m] */
    /* a wall that vanishes (the scene's until): gone from the forces of step until_step on */
    int64_t until_step;     /* JD_WALL_ALWAYS: never */
    int gone;               /* set by sim_walls_retire for the forces being evaluated */
} jd_sim_wall;

/* A thread's share of the force loops (see "Threads" above; forces.c). */
typedef struct jd_thread_share {
    size_t pair_lo, pair_hi; /* pair list entries [pair_lo, pair_hi) that touched at the build */
    size_t near_lo, near_hi; /* and [near_lo, near_hi) that did not (jd_contact_list) */
    size_t wall_lo, wall_hi; /* wall list entries */
    size_t p_lo, p_hi;       /* the particles it owns: every entry above has i in [p_lo, p_hi) */
    size_t win;              /* its pairs reach particles [p_hi, p_hi + win) as j */
    size_t span;             /* the largest j - i of its pairs (how far ahead of i the loop
                              * first touches a particle) */
    size_t cap;              /* room of ovf, in particles (>= win) */
    double *ovf;             /* 6 cap: forces (3 cap) then torques on those particles, zero
                              * between force evaluations */
} jd_thread_share;

/* The largest overlap beyond the watchdog's limit in one force evaluation (fraction 0: none). */
typedef struct jd_overlap_trip {
    double fraction;   /* overlap / the smaller radius [-] */
    int32_t i, j;      /* particle indices; j < 0: wall -j - 1 */
} jd_overlap_trip;

/* The particles: their state and per-particle constants.  The arrays (and the neighbour
 * search's x_build, half_skin, cell_of, cell_items) are slices of one block (sim.c, hugepages.h); with
 * conveyor inlets they have room for every particle the run can hold, and n counts the active
 * prefix. */
typedef struct jd_particles {
    size_t n;          /* particles */
    /* state, 3n each */
    double *x;         /* position [m] */
    double *v;         /* velocity [m/s] */
    double *omega;     /* angular velocity [rad/s] */
    double *f;         /* force [N] */
    double *torque;    /* [N m] */
    /* constants, n each */
    int32_t *orig;     /* scene index of the particle at each index (see "Particle order") */
    int sorted;        /* 1 once the particles have been renumbered (orig is not the identity) */
    int32_t *species;  /* material index */
    double *radius;    /* [m] */
    double *mass;      /* [kg] */
    double *inertia;   /* moment of inertia [kg m^2] */
    double *kp;        /* Hertz prefactor jd_hertz_prefactor(E, nu, R) [N/m^1.5] */
    double *kw;        /* wall prefactor jd_kn_wall(rule, E, nu, R) [N/m^1.5] */
    double *dtfm;      /* 0.5 dt / m, as fix nve/sphere [s/kg] */
    double *dtirot;    /* (0.5 dt / 0.4) / (r r m), as fix nve/sphere [s/(kg m^2)] */
    const int64_t *ids; /* id of each scene index: scene->id, or the inlets' table */
    double *scratch;   /* 3n doubles: reordering and frames in scene order */
} jd_particles;

/* The run's constants, fixed at set-up (sim_init). */
typedef struct jd_run_constants {
    const jd_scene *scene;
    double dt;         /* [s] (the scene's) */
    double g[3];       /* gravity [m/s^2] (the scene's) */
    unsigned features; /* JD_F_* bits of the force loops (the law set) */
    size_t n_materials;
    jd_pair_coeffs *coeffs; /* n_materials^2, row-major: coefficients of (material a, material b) */
    double max_overlap; /* the scene's max_overlap_fraction [-]; INFINITY with the watchdog off,
                           so that the force loops test it without a branch on it */
} jd_run_constants;

/* What the fast paths may assume of the particles (sim_particle_kinds, after the set changed)
 * and of the forces (set-up). */
typedef struct jd_fast_paths {
    int32_t pair_row;  /* the row of coeffs every particle pair uses when all particles share one
                        * material (the pair loop then reads no species), else -1 */
    int alike;         /* 1 when all particles also share one radius: every pair then has the
                        * constants pc_alike, pcr_alike and radii r_alike, which the pair loop
                        * uses instead of computing them per pair */
    double r_alike;            /* [m] */
    jd_pair_const pc_alike;
    jd_pair_const_roll pcr_alike;
    int uniform_mass;  /* every particle has particle 0's mass, dtfm and dtirot, bit for bit: the
                          integration passes read them once */
    int weight_in_kick; /* gravity acts and no post-force load comes after it: the weight m g is
                           added by the half kick that follows each force evaluation
                           (integrate.c) rather than by a pass of its own; the step-0 evaluation
                           still adds it (sim_gravity) */
} jd_fast_paths;

/* How the force loops are split between the threads (see "Threads"). */
typedef struct jd_thread_layout {
    int n;                   /* threads used (the requested count, at least 1) */
    jd_thread_share *shares; /* one per thread, set at every neighbour build */
    jd_overlap_trip *trips;  /* one per thread, merged into jd_watch.overlap_trip */
} jd_thread_layout;

/* One thread's part of a pair list being built (neighbour.c): the entries (i, j) of its range of
 * i, joined in thread order. */
typedef struct jd_pair_part {
    int32_t *i, *j;
    size_t n, cap;
} jd_pair_part;

/* The contact lists and the neighbour search that builds them (neighbour.c). */
typedef struct jd_neighbour_lists {
    jd_contact_list pairs, wall_pairs;
    /* the buffers each build fills before its swap (and sim_reorder uses), kept from one build to
     * the next: a fresh list would grow from empty, copying and faulting in its pages every build */
    jd_contact_list spare, wall_spare;
    double skin;       /* [m] */
    double *x_build;   /* each particle's position at its last search (every build's if full,
                          only the moved particles' at a partial one), 3n [m] */
    double *half_skin; /* [m] each particle's half skin, set when it is searched (neighbour.c,
                          half_skin_of): skin/2, or more for a fast particle */
    int64_t skin_steps; /* the scene's neighbour.skin_steps (half_skin_of) */
    double drift_bound; /* [m] the largest distance of a kept particle from x_build at the last
                           build, plus the sum over the steps since of dt times the largest
                           speed: no particle is further from its x_build (integrate.c, the
                           rebuild check) */
    int64_t n_builds;
    int64_t n_partial;  /* of them partial: only the pairs of the particles that moved redone */
    size_t n_built;     /* particles at the last build (those beyond were inserted since) */
    int renumbered;     /* particles deleted or renumbered since the last build: the next is full */
    int32_t *moved;     /* a partial build's particles, ascending (n) */
    uint8_t *in_moved;  /* 1 for the particles in moved (n) */
    int64_t *keys;      /* a partial build's new entries, (i << 32) | j (keys_cap) */
    size_t keys_cap;
    int32_t *cell_of, *cell_items, *cell_start; /* cell of each particle, particles by cell, and
                                                   each cell's first item (cell_cap + 1) */
    size_t cell_cap;   /* capacity of cell_start */
    jd_pair_part *parts; /* one per thread of the pair search, kept from one build to the next */
    int n_parts;
} jd_neighbour_lists;

/* The walls (walls.c). */
typedef struct jd_walls {
    size_t n;
    jd_sim_wall *wall;
    /* Wall forces, for a scene with a servo wall: per wall-list entry the force on the wall [N]
     * and the contact point [m] (3 each, zero unless it carries force), written by the wall
     * loops and summed in list order after them, so the sums are the same bits whatever the
     * threads; the boundary stress of those contacts [Pa] (jd_stress_tensor). */
    int forces;
    double *f, *x;
    size_t cap;        /* entries f and x have room for */
    double stress_tensor[9];
} jd_walls;

/* What the run has spent and dissipated outside the contact lists. */
typedef struct jd_accounts {
    jd_timing timing;
    double e_damp_dropped, e_fric_dropped; /* damping and friction dissipation of contacts
                                              dropped from the lists [J] */
    double wall_work;  /* work done on the particles by the walls [J] */
} jd_accounts;

/* What the run-time watchdog (watchdog.c) has seen. */
typedef struct jd_watch {
    jd_overlap_trip overlap_trip; /* of the last force evaluation */
    int nonfinite;              /* the last step left a non-finite x (it then stopped before
                                   the neighbour search), v or omega (a non-finite force or
                                   torque shows up in v or omega) */
    int has_energy_ref;         /* energy_ref holds the previous observable sample */
    jd_energy_terms energy_ref;
    int64_t energy_ref_step;
} jd_watch;

/* One run: its parts, and where it stands.  Each pass takes the parts it reads (const) and
 * writes (docs/architecture.md, "The stepper's parts"). */
typedef struct jd_sim {
    jd_particles particles;
    jd_run_constants run;
    jd_sim_options opt;
    jd_fast_paths fast;
    jd_thread_layout threads;
    jd_neighbour_lists lists;
    jd_walls walls;
    jd_accounts accounts;
    jd_watch watch;

    int64_t step;      /* steps done */
    int64_t frame_step; /* step of the last frame written by sim_run, -1 before the first */
    int in_setup;      /* the step-0 force evaluation (LIGGGHTS `setup`) is running */
    int kick_pending;  /* the last step's final half kick is not applied yet: v and omega are at
                          the half step (sim_step, sim_finish_step) */

    /* the block the per-particle arrays are slices of */
    void *particle_block;
    size_t particle_block_bytes;

    /* the optional modules; NULL when the scene has none */
    jd_bonds *bonds;   /* parallel bonds (bonds.h) */
    struct jd_loads *loads; /* held particles and external forces (loads.c) */
    struct jd_sim_inlets *inlets; /* conveyor inlets (inlet.c) */
    struct jd_mesh_walls *meshes; /* STL mesh walls (mesh_walls.c) */

    /* set by the caller (e.g. a signal handler) to stop the run at the next step; NULL: never */
    const volatile sig_atomic_t *stop;
} jd_sim;

/* Results of sim_run besides 0.  JD_RUN_OUTPUT: the trajectory writer failed (jd_h5md_*). */
enum { JD_RUN_ERROR = -1, JD_RUN_TRIPPED = -2, JD_RUN_STOPPED = -3, JD_RUN_OUTPUT = -4 };

/* sim.c */
/* Set up from a loaded scene (kept by pointer; it must outlive the sim) and compute the forces
 * of step 0 (LIGGGHTS `setup`).  opt may be NULL (no reference path); threads: OpenMP threads
 * of the force and integration loops (<= 0: 1).  Returns 0, or -1 with a reason in err. */
int sim_init(jd_sim *s, const jd_scene *scene, const jd_sim_options *opt, int threads, char *err,
             size_t errlen);
void sim_free(jd_sim *s);

struct jd_h5md;
/* Run scene->steps steps writing frames and observables to h (which may be NULL: no output).
 * show_progress: print the progress line on stderr.  Returns 0; JD_RUN_ERROR with a reason in
 * err (a diverged state, or "out of memory ..."); JD_RUN_OUTPUT when a write failed (its
 * message in err); JD_RUN_TRIPPED when the watchdog stopped the run (its message in err);
 * JD_RUN_STOPPED when *s->stop was set.  On the last two the frame of the step reached is
 * written (unless its state is not finite), so the trajectory ends where the run stopped. */
int sim_run(jd_sim *s, struct jd_h5md *h, int show_progress, char *err, size_t errlen);

/* Bytes the engine holds for the run (particle arrays, contact lists at their capacity, cells,
 * thread buffers, bonds): its memory apart from the scene and the libraries. */
size_t sim_memory_bytes(const jd_sim *s);

/* Per-particle constants of particle i (mass, inertia, Hertz and wall prefactors, the
 * integration factors) from its material and radius [m]. */
void sim_particle_constants(jd_particles *ps, const jd_run_constants *run, size_t i,
                            int32_t material, double radius);
/* How alike the particles are (pair_row, alike, uniform_mass), after the set changed; plain:
 * the reference path (--plain-loops), which reads the integration constants per particle. */
void sim_particle_kinds(jd_fast_paths *fast, const jd_particles *ps, size_t n_materials,
                        int plain);

/* inlet.c: the conveyor inlets (docs/mixing.md 2.1). */
typedef struct jd_sim_inlets jd_sim_inlets;
enum { JD_INLET_FRAME_VECTORS = 5 }; /* position, velocity, angular velocity, force, torque */
/* Particles the run can hold: the scene's plus every copy that starts by the last step. */
size_t sim_inlets_capacity(const jd_scene *scene);
int sim_inlets_init(jd_sim *s, char *err, size_t errlen); /* 0, or -1 (out of memory) */
void sim_inlets_free(jd_sim *s);
/* Record every insertion as a CSV line "id,step,x,y,z,vx,vy,vz" (%.17g) on log (NULL: none). */
void sim_inlets_log(jd_sim *s, FILE *log);
/* Before the step s->step + 1: the deposit-height rule, and the particles due at s->step
 * (appended, then a neighbour build).  0, or -1 with err. */
int sim_inlets_step(jd_sim *s, char *err, size_t errlen);
int64_t sim_inlets_inserted(const jd_sim *s);
double sim_inlets_seconds(const jd_sim *s); /* wall time of the insertions [s] */
/* The particle-steps that the particles not yet inserted will add from their insertion to step
 * `last` (the progress line's ETA; jd_inlet_pending_particle_steps: a stream that a
 * deposit-height rule will end counts in full until the rule ends it). */
double sim_inlets_pending_particle_steps(const jd_sim *s, int64_t last);
double sim_inlets_energy(const jd_sim *s);  /* kinetic + gravitational energy brought in [J] */
/* The trajectory's rows (every particle the run can hold, sorted by id) and their constants
 * (arrays of sim_inlets_rows entries). */
size_t sim_inlets_rows(const jd_sim *s);
int sim_inlets_particles(const jd_sim *s, int64_t *id, int32_t *species, double *radius,
                         double *mass);
/* Vector k of a frame (3 per active particle, scene order) spread onto the rows, NaN for the
 * particles not inserted (yet). */
double *sim_inlets_frame_rows(const jd_sim *s, int k, const double *scene_ordered);
/* The id of each row at this frame: -1 for the particles not inserted (yet) or deleted. */
const int64_t *sim_inlets_frame_ids(const jd_sim *s);
/* The rows also serve a scene with a domain and no inlets (its particle set shrinks).  After
 * domain.c deleted `gone` particles (gone_scene[p]: scene index p of the n before), close the
 * scene indices up and book them with the energy they took [J]. */
void sim_inlets_close_up(jd_sim *s, const unsigned char *gone_scene, size_t n, size_t gone,
                         double energy);
int64_t sim_lost_particles(const jd_sim *s);
/* Particles the inlets skipped: their place was occupied (kernel/jdem_inlet.h). */
int64_t sim_skipped_particles(const jd_sim *s);
double sim_lost_energy(const jd_sim *s); /* [J] */

/* neighbour.c */
int sim_neighbour_build(jd_sim *s, char *err, size_t errlen);
/* Drop the pair and wall entries of the particles at indices >= keep (deleted, domain.c),
 * booking what they dissipated. */
void sim_lists_drop_from(jd_sim *s, size_t keep);
void sim_neighbour_parts_free(jd_neighbour_lists *lists);
/* 1 when some wall moved more than skin/2 [m] since the last build (the particles' part of the
 * rebuild criterion rides in the drift, integrate.c) */
int sim_neighbour_walls_moved(const jd_walls *walls, double skin);
/* How near a wall (plane, cylinder or mesh) particle i must come to be its candidate [m]: its
 * own half skin and the wall's, skin/2 (a wall triggers a build once it has moved skin/2). */
static inline double sim_wall_margin(const jd_neighbour_lists *lists, size_t i) {
    return 0.5 * lists->skin + lists->half_skin[i];
}
/* The kind of list a law set's history needs: the bits its record lengths depend on
 * (jdem_laws.h). */
static inline unsigned sim_list_kind(unsigned features) {
    return features & (unsigned)(JD_F_ROLLING | JD_F_ENERGY | JD_F_MEPA);
}
/* Capacity for `need` entries of a list of this kind (sim_list_kind).  Returns 0 or -1. */
int sim_list_reserve(jd_contact_list *l, size_t need, unsigned kind);
void sim_contact_list_free(jd_contact_list *l);

/* reorder.c */
/* Renumber the particles into the order old_of_new (new index k holds old particle
 * old_of_new[k]): the per-particle arrays, the contact lists (re-keyed and re-sorted, with the
 * history of a pair whose ends swap turned around), orig, the bonds and the loads.  Returns 0 or
 * -1 (out of memory; nothing changed). */
int sim_reorder(jd_sim *s, const int32_t *old_of_new, char *err, size_t errlen);
/* Put x, v, omega, f and torque into scene order (for a frame), and back. */
void sim_vectors_to_scene_order(jd_particles *ps);
void sim_vectors_to_sim_order(jd_particles *ps);
/* A per-particle array in scene order: out[orig[i]] = a[i]. */
void sim_scalars_in_scene_order(const jd_particles *ps, const double *a, double *out);
/* Scene id of the particle at index i. */
static inline long long sim_particle_id(const jd_particles *ps, size_t i) {
    return (long long)ps->ids[ps->orig[i]];
}

/* walls.c */
int sim_walls_init(jd_walls *walls, const jd_run_constants *run, char *err, size_t errlen);
/* Translate every wall by its velocity times dt [s]. */
void sim_walls_move(jd_walls *walls, double dt);
/* Mark the walls gone whose until_step is at or before `step`, the step whose forces are about
 * to be evaluated.  A gone wall's contacts end in the force loops, their stored elastic energy
 * booked as work the vanishing wall did (wall_work), and the neighbour search skips it. */
void sim_walls_retire(jd_walls *walls, int64_t step);
void sim_walls_free(jd_walls *walls);
/* With walls->forces: room for an entry record per wall-list entry (n of them; after every
 * list build). */
int sim_walls_reserve(jd_walls *walls, size_t n, char *err, size_t errlen);
/* With wall_forces, after the wall loops: each wall's force, the boundary stress, and each
 * servo wall's measured stress and speed for the next step (kernel/jdem_servo.h); the records
 * are zeroed for the next evaluation. */
void sim_walls_sum(jd_walls *walls, const jd_contact_list *wall_pairs);
/* With walls->forces: the wall observables of jdem_observable_names.h at this step (sim.c). */
struct jd_h5md;
int sim_walls_write_observables(const jd_walls *walls, const jd_run_constants *run, int64_t step,
                                struct jd_h5md *h, char *err, size_t errlen);

/* forces.c: zero f and torque, then pair forces, wall forces, bonds, gravity (unless
 * s->fast.weight_in_kick), loads. */
void sim_compute_forces(jd_sim *s);
/* mesh_walls.c: the STL mesh walls' forces, serially after the contact loops (mesh_walls.h). */
void sim_mesh_walls_forces(jd_sim *s);
/* Add every particle's weight m g to its force. */
void sim_gravity(jd_particles *ps, const jd_run_constants *run, const jd_thread_layout *threads);
/* The force loops' per-thread state for threads->n threads (sim_init), and its release. */
int sim_forces_init(jd_thread_layout *threads);
void sim_forces_free(jd_thread_layout *threads);
/* Split the current lists of n particles between the threads (jd_thread_share); after every
 * neighbour build.  Returns 0, or -1 when out of memory. */
int sim_forces_partition(jd_thread_layout *threads, const jd_neighbour_lists *lists, size_t n);
/* Monotonic wall clock [s]. */
double sim_clock(void);

/* loads.c: set up (0 or -1 with err), free, and apply after every other force (forces.c). */
typedef struct jd_loads jd_loads;
/* *loads stays NULL when the scene has none. */
int sim_loads_init(jd_loads **loads, const jd_scene *scene, char *err, size_t errlen);
void sim_loads_free(jd_loads **loads);
/* The loads' forces on the particles, and their work booked in accounts (not at step 0,
 * in_setup: LIGGGHTS `setup`). */
void sim_loads_apply(jd_loads *l, jd_particles *ps, const jd_run_constants *run,
                     jd_accounts *accounts, int in_setup);
/* Remap the loaded particles after a re-sort (reorder.c): particle k is now new_index[k]. */
void sim_loads_permute(jd_loads *l, const int32_t *new_index);
/* Forget the loaded particles at indices >= keep (deleted, domain.c). */
void sim_loads_drop_from(jd_loads *l, size_t keep);

/* domain.c: the scene's domain (kernel/jdem_domain.h).  Before a neighbour build: delete the
 * particles whose centre is outside it, booking what they take (sim_inlets_close_up).
 * half_step: called inside sim_step, where v and omega are half-step values.  0, or -1 with err
 * (out of memory; nothing changed). */
int sim_domain_delete(jd_sim *s, int half_step, char *err, size_t errlen);

/* integrate.c: one full step.  seen: the state at the step's end is looked at (frame,
 * observables); else the step's final half kick is left pending (s->kick_pending) and done in
 * the next step's first pass.  Returns 0, or -1 with a reason in err. */
int sim_step(jd_sim *s, int seen, char *err, size_t errlen);
/* Apply a pending final half kick, so that v and omega are those at s->step. */
void sim_finish_step(jd_sim *s);

/* observables.c */
typedef struct jd_observables {
    double kinetic_energy, rotational_energy, elastic_energy, gravitational_energy;
    double damping_dissipation, friction_dissipation, wall_work;
    double contacts, wall_contacts;
    jd_bond_observables bond;  /* scenes with bond types only (sim_bonds_observables) */
} jd_observables;
/* Every field but bond. */
void sim_observables(const jd_particles *ps, const jd_run_constants *run,
                     const jd_neighbour_lists *lists, const jd_walls *walls,
                     const jd_accounts *accounts, jd_observables *o);
void sim_observables_values(const jd_observables *o, double out[JD_N_OBSERVABLES]);

/* guard.c: the kernel's time-step guard (kernel/jdem_guard.h) applied to a scene.  Fills *in
 * (its species array is malloc'ed into *species: free it) and *r; returns 0, or -1 when out of
 * memory. */
int sim_guard(const jd_scene *scene, jd_guard_input *in, jd_guard_species **species,
              jd_guard_result *r);
/* dt of a scene without dt (or `dt: auto`): this multiple of the guard's largest safe dt.  The
 * work-precision study (`make accuracy`, docs/model.md "Default time step") finds every measured
 * error <= 1 % up to 2.7x the guard's dt, so the guard's dt itself, with that margin. */
#define JD_DT_AUTO_FACTOR 1.0

/* watchdog.c.  The force loops call sim_watchdog_overlap() (out of line: the rare case) for a
 * contact with jd_overlap_excessive(); the run loop calls the checks below, which return 0 or
 * JD_RUN_TRIPPED with "watchdog: step N: QUANTITY VALUE for particle(s) IDS exceeds LIMIT ..."
 * in msg. */
void sim_watchdog_overlap(jd_overlap_trip *t, int32_t i, int32_t j, double delta, double rmin);
/* every step (step: steps done) */
int sim_watchdog_step(const jd_watch *watch, const jd_particles *ps, const jd_run_constants *run,
                      int64_t step, char *msg, size_t len);
/* at every observable sample; inlet_energy: what the inlets brought in so far [J] */
int sim_watchdog_energy(jd_watch *watch, const jd_particles *ps, const jd_run_constants *run,
                        int64_t step, double inlet_energy, const jd_observables *o, char *msg,
                        size_t len);

/* progress.c */
typedef struct jd_progress {
    int enabled, tty;
    int64_t total;
    size_t n;               /* particles in the run now (an inlet's stream grows it) */
    double particle_steps;  /* sum of n over the steps done: the rate of a growing set */
    double t_start, t_last; /* CLOCK_MONOTONIC seconds */
    int printed;
    /* the particle-steps still to come beyond the present particles' (an inlet's stream), or
     * NULL: the ETA is the remaining work over the measured particle-steps per second */
    double (*pending)(const void *ctx, int64_t total_steps);
    const void *ctx;
} jd_progress;
void progress_start(jd_progress *p, int enabled, int64_t total_steps);
/* After each step: step done, its time [s], the particles it had. */
void progress_update(jd_progress *p, int64_t step, double sim_time, size_t n_particles);
void progress_finish(jd_progress *p);

#endif /* JDEM_SIM_H */
