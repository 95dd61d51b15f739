/*
 * mesh_walls.h — triangle-mesh walls (STL, docs/scenes.md "Mesh walls") in the standalone
 * engine, still, moving (translation, rotation) or with a conveyor surface: the motion
 * (kernel/jdem_mesh_motion.h), each particle's candidate triangles, the kernel's per-sphere rule
 * (kernel/jdem_mesh.h: jd_mesh_sphere_contacts, jd_mesh_history_next) and the wall law of the
 * plane walls, evaluated serially after the parallel contact loops so that any number of threads
 * gives the same bits.  The order matches liggghts-jdem's fix wall/jiang mesh: the meshes in
 * scene order, the particles in ascending index, each particle's candidates in ascending
 * triangle, its contacts in that order.
 *
 * Candidates come from a grid of the mesh's triangles (mesh_cells.h), rebuilt with them; the
 * reference option JDEM_NEIGHBOUR=allpairs makes every triangle a candidate of every particle
 * instead, which must give the same bits (only triangles within R take part in a contact).
 *
 * A moving mesh moves its corners in the drift, as fix move/mesh does in LIGGGHTS' initial
 * integration, and rebuilds its topology from them (the vertex and edge ids follow the
 * coordinates, as the plugin's do).  Its candidates hold every triangle within R + skin/2 + h
 * of each particle's position at the last neighbour build (h its own half skin, neighbour.c),
 * from the triangles where they were at the candidates' build: they are rebuilt with the
 * neighbour list, and in between once some corner has moved more than skin / 2 since (the
 * particle has moved at most h since the neighbour build, so a triangle within R now was
 * within R + skin/2 + h then).
 */
#ifndef JDEM_MESH_WALLS_H
#define JDEM_MESH_WALLS_H

#include <stddef.h>
#include <stdint.h>

#include "jdem_mesh.h"
#include "mesh_cells.h"
#include "sim.h"

/* The contact history of one mesh wall: per particle, keyed by its scene index (orig[i], which
 * survives the renumbering), JD_MESH_SLOTS slots of `stride` doubles in the kernel's layout
 * (jdem_mesh.h: the contact's normal, then the law's record, jd_record_load/store).  The
 * whole state is the flat array `slots` (n x JD_MESH_SLOTS x stride doubles), so a checkpoint
 * carries it as one block. */
typedef struct jd_mesh_history {
    size_t stride;  /* 3 + the law set's contact and rolling records [doubles]     */
    size_t n;       /* scene indices with room, 0 .. n - 1 (grows with the inlets) */
    double *slots;  /* [n][JD_MESH_SLOTS][stride]                                  */
} jd_mesh_history;

/* One mesh wall as the engine holds it. */
typedef struct jd_sim_mesh {
    int material;            /* the wall's material (index into materials)          */
    jd_mesh_motion motion;   /* how it moves (still, translating, rotating)          */
    double (*corner)[3][3];  /* [ntri] the triangles' corners now [m]                */
    double (*vnode)[3][3];   /* [ntri] the wall's velocity at each corner [m/s]; NULL: at rest */
    double (*corner_at_build)[3][3]; /* moving: the corners at the candidates' build [m] */
    jd_mesh topo;            /* the kernel's topology (vertices, edges, valences)   */
    jd_mesh_storage storage; /* the arrays topo points into (one allocation each)   */
    jd_mesh_history hist;
    double force[3];         /* the particles' total force on the wall at the last evaluation [N] */
} jd_sim_mesh;

/* All mesh walls of a run, and each particle's candidate triangles since the last neighbour
 * build (every triangle within R + skin/2 + its half skin of the particle's position at the
 * build). */
typedef struct jd_mesh_walls {
    size_t n;
    jd_sim_mesh *mesh;
    int64_t built_at;        /* lists.n_builds of the candidates, -1: none yet       */
    int moved_far;           /* a moving mesh's corner moved more than skin / 2 since the build */
    size_t n_particles;      /* particles the candidates were built for              */
    size_t *cand_start;      /* [n][n_particles + 1] offsets into cand_tri, mesh-major */
    int32_t *cand_tri;       /* candidate triangles, ascending per particle and mesh  */
    size_t cand_cap;
    jd_mesh_cells cells;     /* the grid of the mesh whose candidates are being built    */
    /* scratch of one sphere's evaluation, sized for the largest candidate list */
    jd_mesh_closest *closest;
    unsigned char *is_contact;
    size_t scratch_cap;
    double *next;            /* [JD_MESH_SLOTS][stride]: a sphere's slots after the evaluation */
    unsigned features;       /* the run's law set (run->features): the records' layout */
    double e_damp_dropped, e_fric_dropped; /* dissipation of the contacts that ended [J]   */
    char error[256];         /* set when a sphere touches more than JD_MESH_SLOTS faces */
} jd_mesh_walls;

/* The mesh walls of the scene (topology from the kernel, empty histories); *out = NULL when
 * the scene has none.  Returns 0, or -1 with a message naming the wall. */
int sim_mesh_walls_init(jd_mesh_walls **out, const jd_run_constants *run, char *err,
                        size_t errlen);
void sim_mesh_walls_free(jd_mesh_walls *mw);

/* The mesh walls' part of an observable sample: the stored energy and the contacts of the live
 * slots, and the dissipation of live and ended contacts, added to o. */
void sim_mesh_walls_observables(const jd_mesh_walls *mw, jd_observables *o);

/* One time step dt [s] of every moving mesh (corners, topology, corner velocities); notes
 * when a corner has moved more than skin / 2 [m] since the candidates' build. */
void sim_mesh_walls_move(jd_mesh_walls *mw, double dt, double skin);

/* 1 when some mesh wall moves (its triangles go with every frame). */
int sim_mesh_walls_moving(const jd_mesh_walls *mw, size_t k);

/* The triangles [ntri][3][3] of mesh wall k where they are now [m]. */
const double (*sim_mesh_walls_corners(const jd_mesh_walls *mw, size_t k))[3][3];

/* After domain.c deleted the particles of scene indices p < n with gone_scene[p]: their history
 * is dropped (dissipation booked; F: the run's features) and the others close up over it, as
 * the scene indices do. */
void sim_mesh_walls_close_up(jd_mesh_walls *mw, const unsigned char *gone_scene, size_t n,
                             unsigned F);

/* What a checkpoint needs (checkpoint_state.c stores the corners, the corners at the
 * candidates' build, the histories, the candidate lists and the dissipation of ended contacts
 * as they are, so that a resumed run evaluates the same candidates in the same order):
 * - room for exactly n scene indices in h, every slot empty (0, or -1 out of memory);
 * - room for the candidate lists of n_particles particles holding n_candidates entries in all
 *   (0, or -1 out of memory);
 * - after they are read: each moving mesh's topology and corner velocities from its corners,
 *   and the scratch for the longest candidate list (0, or -1 with err). */
int sim_mesh_history_resize(jd_mesh_history *h, size_t n);
int sim_mesh_candidates_reserve(jd_mesh_walls *mw, size_t n_particles, size_t n_candidates);
int sim_mesh_walls_restored(jd_mesh_walls *mw, char *err, size_t errlen);

/* Each mesh wall's force (wall_force/NAME/x, y, z) at this step, like the plane walls'. */
int sim_mesh_walls_write_observables(const jd_mesh_walls *mw, const jd_run_constants *run,
                                     int64_t step, struct jd_h5md *h, char *err, size_t errlen);

/* sim_mesh_walls_forces (declared in sim.h): adds the mesh walls' forces and torques to the
 * particles (serial), rebuilding the candidates when the neighbour list was rebuilt, advancing
 * the histories (not during the set-up evaluation, which evaluates the same contacts without
 * keeping them, as LIGGGHTS' setup does), adding the walls' work to the accounts and the worst
 * overlap to the watchdog's trip.  A sphere with more than JD_MESH_SLOTS contacts sets
 * mw->error (sim_step stops the run). */

#endif
