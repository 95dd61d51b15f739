/*
 * scene_internal.h — internal to the scene reader (stepper/scene*.c): the loader state shared by
 * the section readers, and the readers each file provides.
 *
 *   scene.c             scene_load / scene_list_cases / scene_free: cases, header, time, output,
 *                       gravity, model, the default max_impact_speed; calls the readers below
 *   scene_materials.c   materials, material references, interactions
 *   scene_particles.c   explicit particles, the sort by id (duplicate ids), the start-overlap check
 *   scene_generate.c    the lattice generator
 *   scene_walls.c       walls and their geometry checks
 *   scene_deposit.c     particles_from (scene_deposit_h5md.c reads the trajectory's frame)
 *   scene_inlets.c      the conveyor inlets (docs/mixing.md 2.1) and the kernel's check of them
 *   scene_bonds.c       bond_types, explicit bonds, bond_rules; their resolution after the sort
 *   scene_bond_generators.c   the bonded_block and bonded_sphere generators
 *   scene_bond_rules.c  the pair test of a bond rule (shared with the stepper, scene.h)
 *
 * Every reader reports the first problem into L->c (see scene_doc.h) and returns -1; 0 means
 * success.
 */
#ifndef JDEM_SCENE_INTERNAL_H
#define JDEM_SCENE_INTERNAL_H

#include <math.h>
#include <stddef.h>
#include <stdint.h>

#include "jdem_kernel.h"
#include "scene.h"
#include "scene_doc.h"

#define MAX_PARTICLES 100000000

/* [0, 1]: model.mu_r and a lattice's jitter. */
static const sd_range UNIT = {0.0, 1.0, 0, 0};

/* Loader state: the scene being filled plus, per particle, where it came from (for messages). */
typedef struct loader {
    sd_ctx c;
    jd_scene *s;
    const yaml_node_t *root;
    size_t cap;                 /* allocated particles */
    const yaml_node_t **pnode;  /* the particle's mapping, or its generator's */
    int32_t *psrc;              /* >= 0: index in particles; < 0: -(generator index + 1) */
    unsigned char *by_particle; /* per material: used by a particle */
    unsigned char *by_wall;     /* per material: used by a wall */
    int max_impact_given;
    size_t bond_cap;            /* allocated bonds */
    const yaml_node_t **bnode;  /* per bond: the node that made it (for messages) */
    const yaml_node_t *time;    /* the time mapping: steps from end_time wait for an auto dt */
    const yaml_node_t **inode;  /* per inlet: its mapping (messages of the check after dt) */
} loader;

static inline double norm3(const double v[3]) { return sqrt(jd_dot(v, v)); }

static inline void sub3(const double a[3], const double b[3], double out[3]) {
    for (int d = 0; d < 3; d++) out[d] = a[d] - b[d];
}

/* scene.c: optional integer map.key >= lo (out keeps its default when absent). */
int scene_opt_int(loader *L, const yaml_node_t *map, const char *path, const char *key,
                  int64_t lo, int64_t *out);

/* scene.c: the file named at node (key path; what: "an STL file", for the message when it
 * names none) resolved against the scene file's folder into out[size] (an absolute path as it
 * is), so that a scene and the files beside it can be moved together; a path that does not fit
 * is refused. */
int scene_file_path(loader *L, const yaml_node_t *node, const char *path, const char *what,
                    char *out, size_t size);

/* scene_materials.c */
int scene_read_materials(loader *L);
/* The required map.material, as an index into the scene's materials. */
int scene_req_material(loader *L, const yaml_node_t *map, const char *path, int *out);
/* scene_mesh.c: walls.K of type mesh (file, scale) into mw: the STL read and checked. */
int scene_read_mesh_wall(loader *L, const yaml_node_t *w, const char *path, jd_mesh_wall *mw);
/* Last: the defaults of a pair depend on whether particles and walls make it meet. */
int scene_read_interactions(loader *L);

/* scene_particles.c */
int scene_read_particles(loader *L);
/* Append a particle with zero velocities; returns its index or -1. */
long scene_add_particle(loader *L, const yaml_node_t *node, int32_t src);
int scene_sort_particles(loader *L);
int scene_check_overlaps(loader *L);
int scene_check_wall_overlaps(loader *L);

/* scene_generate.c */
int scene_read_generators(loader *L);
/* The generator list `list` at `prefix` (lattice_only: no bonded generators), appending
 * particles with ids from *next_id on. */
int scene_generate_list(loader *L, const yaml_node_t *list, const char *prefix,
                        int lattice_only, int64_t *next_id);

/* scene_generate.c: one lattice mapping `lat` at `path` (the generate section's lattice keys),
 * its particles appended with ids from *next_id, its counts into counts. */
int scene_generate_lattice(loader *L, const yaml_node_t *lat, const char *path, int32_t gen,
                           int64_t counts[3], int64_t *next_id);

/* scene_inlet_blocks.c (docs/scenes.md "Bonded blocks in an inlet section"): an inlet section's
 * blocks (read before its other particles, at section index 0) and explicit section bonds
 * (after them), into in->bond_pair/bond_type; the groups; the blocks' fit (after the whole
 * inlet entry at `path` is read: the belt and the period are known). */
typedef struct section_blocks section_blocks;
int scene_read_section_blocks(loader *L, const yaml_node_t *sec, const char *path,
                              section_blocks **out);
int scene_read_section_bonds(loader *L, const yaml_node_t *sec, const char *path, jd_inlet *in,
                             section_blocks *blocks);
int scene_check_section_blocks(loader *L, const char *path, const jd_inlet *in,
                               const section_blocks *blocks);
void scene_free_section_blocks(section_blocks *blocks);

/* scene_inlets.c: the inlets section (after the particles and generators, before the sort),
 * and its kernel check once dt is final. */
int scene_read_inlets(loader *L);
int scene_check_inlets(loader *L);

/* scene_deposit.c: particles_from, after particles and generate.  Its particles' psrc is
 * PSRC_DEPOSIT(entry index). */
#define PSRC_DEPOSIT(k) (INT32_MIN + (int32_t)(k))
#define PSRC_IS_DEPOSIT(src) ((src) < INT32_MIN / 2)
int scene_read_deposits(loader *L);
/* The deposit entries of `list` (at `path`, e.g. an inlet's section.from_deposit) appended to
 * the scene's particles, each marked settled, with the bonds intact between them (bonds: keep,
 * the default; `section`: an inlet's section, which refuses a deposit whose kept particles are
 * bonded unless bonds: none). */
int scene_read_deposit_list(loader *L, const yaml_node_t *list, const char *path, int section);

/* scene_walls.c */
int scene_read_walls(loader *L);
int scene_wall_steps(loader *L);      /* an auto dt's vanishing walls: until -> until_step */
/* After the particles: no plane wound away from the particles over it (the kernel's rule). */
int scene_check_plane_winding(loader *L);

/* scene_materials.c: material index named by scalar node n, or -1 after reporting. */
int scene_material_ref(loader *L, const yaml_node_t *n, const char *path);

/* scene_bonds.c */
int scene_read_bond_types(loader *L);
/* The required map.key naming a bond type: its index in *out. */
int scene_req_bond_type(loader *L, const yaml_node_t *map, const char *path, const char *key,
                        int *out);
/* Append a bond between ids a and b (any order) made by node. */
int scene_add_bond(loader *L, const yaml_node_t *node, int64_t a, int64_t b, int type);
int scene_read_bonds(loader *L);      /* bonds and bond_rules; before the sort */
int scene_resolve_bonds(loader *L);   /* after the sort: ids exist, step-0 rules, duplicates */
int scene_bond_rule_steps(loader *L); /* an auto dt's rules: their times -> steps, once dt is set */
/* A time [s] -> step ceil(time/dt - 1e-9) (as end_time); the node and path name it in errors. */
int scene_time_to_step(loader *L, const yaml_node_t *at, const char *path, double time,
                       int64_t *step);

/* scene_bond_generators.c: one generator entry (key is "bonded_block" or "bonded_sphere"). */
int scene_generate_bonded(loader *L, const yaml_node_t *g, const char *key, const char *path,
                          int32_t gen, int64_t *next_id);

#endif
