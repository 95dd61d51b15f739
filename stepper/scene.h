/*
 * scene.h — a resolved scene: one case of a scene file (docs/scenes.md) with every default filled
 * in, every generator expanded and every value validated.  Produced by scene_load(), consumed by
 * the simulation (sim.h) and by scene_emit_yaml() (`jdem resolve`, read by the LIGGGHTS deck
 * generator).  SI units throughout.
 */
#ifndef JDEM_SCENE_H
#define JDEM_SCENE_H

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include "jdem_bond.h"
#include "jdem_mesh_motion.h"
#include "jdem_servo.h"

#define JD_NAME_MAX 64

typedef struct jd_material {
    char name[JD_NAME_MAX];
    int has_elastic;          /* 0 for a material used only by walls (no E, nu, density) */
    double youngs_modulus;    /* [Pa] */
    double poisson_ratio;     /* [-]  */
    double density;           /* [kg/m^3] */
    double restitution;       /* (0, 1] */
    double friction;          /* >= 0 */
    double rolling_friction;  /* >= 0, dimensionless eta */
    /* MEPA's stiffnesses (model.normal_law mepa; all three given, or none) */
    int has_mepa;             /* 1 when the material gives them */
    double loading_stiffness;   /* k1 > 0 [N/m^n] */
    double unloading_stiffness; /* k2 > k1 [N/m^n] */
    double cohesive_stiffness;  /* kadh >= 0 [N/m^n] */
} jd_material;

/* Coefficients of an (unordered) pair of materials, after the interaction rules. */
typedef struct jd_interaction {
    double restitution, friction, rolling_friction;
} jd_interaction;

typedef enum { JD_WALL_PLANE = 0, JD_WALL_CYLINDER = 1, JD_WALL_MESH = 2 } jd_wall_type;

typedef struct jd_wall {
    char name[JD_NAME_MAX];
    int type;                 /* jd_wall_type */
    int material;             /* index into materials */
    double velocity[3];       /* [m/s] */
    /* plane */
    double corners[4][3];     /* [m], counter-clockwise seen from the active side */
    double normal[3];         /* unit normal of the active side: (P2-P1) x (P3-P1) normalised */
    /* cylinder */
    double axis[2][3];        /* [m] end points of the axis segment */
    double radius;            /* [m] */
    int inside;               /* 0: obstacle (contact on the outer surface), 1: container */
    double angular_velocity;  /* spin about the axis, right-handed about axis[1] - axis[0] [rad/s] */
    /* servo (plane walls only, docs/scenes.md "Servo walls") */
    int has_servo;            /* 1: the wall moves along its normal by the servo law */
    jd_servo_spec servo;      /* target, gain, tolerance, max_speed; hold_steps is set by the
                                 engine from servo_hold once dt is known (jd_servo_hold_steps) */
    double servo_hold;        /* [s] within tolerance this long completes the test */
    /* removal (docs/scenes.md "A wall that vanishes"): the wall acts on the forces of the steps
     * before until_step and is gone from that step's on (LIGGGHTS: unfix) */
    double until;             /* [s] as the scene gives it; NAN when given as a step, or never */
    int64_t until_step;       /* JD_WALL_ALWAYS: the whole run */
} jd_wall;

/* A wall's until_step when it never vanishes. */
#define JD_WALL_ALWAYS INT64_MAX

/* A static triangle-mesh wall: a walls entry of type mesh, read from an STL file (docs/scenes.md
 * "Mesh walls").  Kept apart from the plane and cylinder walls, whose shapes the engine moves. */
typedef struct jd_mesh_wall {
    char name[JD_NAME_MAX];
    int material;             /* index into materials */
    char file[1024];          /* the STL file, relative paths resolved against the scene's folder */
    double scale;             /* the STL coordinates times scale are metres [m per STL unit] */
    size_t ntri;              /* triangles, in the STL's order */
    double (*corner)[3][3];   /* [ntri] the triangles' corners, scaled [m], at time 0 */
    jd_mesh_motion motion;    /* velocity or rotation (kernel/jdem_mesh_motion.h); still by default */
    double rotation_period;   /* rotation: the period as given [s] (0 when not rotating) */
    double rotation_axis[3];  /* rotation: the axis as given */
    double surface_velocity[3]; /* a conveyor surface's velocity [m/s]; (0, 0, 0): none */
    int spinning;             /* surface_angular_velocity given: the surface spins in place */
    double spin_origin[3];    /* a point of its axis [m] */
    double spin_axis[3];      /* its axis, as given (any length > 0) */
    double spin_omega;        /* its angular velocity, right-handed about spin_axis [rad/s] */
} jd_mesh_wall;

/* Run-time watchdog (docs/scenes.md "Watchdog"): limits that stop a run that goes wrong. */
typedef struct jd_watchdog_limits {
    int enabled;                 /* 0: no checks beyond the writer's refusal of non-finite frames */
    double max_overlap_fraction; /* overlap / the smaller radius of the pair (the particle's
                                    radius against a wall) [-] */
    double max_energy_jump;      /* |change of the total energy| between two observable samples
                                    relative to the energy in play (kernel/jdem_watchdog.h) [-] */
} jd_watchdog_limits;

/* A named bond type (bond_types section). */
typedef struct jd_bond_type {
    char name[JD_NAME_MAX];
    jd_bond_params p;         /* kernel parameters (kn, kt [N/m^3], sigma_c, tau_c [Pa], ...) */
} jd_bond_type;

/* A bond rule that forms bonds during the run (bond_rules with a step > 0; step-0 rules are
 * resolved into explicit bonds). */
typedef struct jd_bond_rule {
    int type;                 /* index into bond_types */
    int64_t step;             /* formed before the forces of this step */
    unsigned char *materials; /* n_materials flags: 1 = particles of that material take part */
    int64_t id_range[2];      /* ids in [first, last] take part */
    double max_gap;           /* surface gap <= max_gap x the smaller radius [-] */
    double time;              /* the rule's `time` [s] (NAN if given by step); with an auto dt,
                                 step is set from it once dt is known */
} jd_bond_rule;

/* How an inlet's stream stops (docs/mixing.md 2.1, `inlets[].stop`). */
typedef enum { JD_INLET_STOP_SECTIONS = 0, JD_INLET_STOP_TIME = 1, JD_INLET_STOP_HEIGHT = 2 } jd_inlet_stop;

/* A conveyor inlet (`inlets:` entry): a section of n particles that rides a belt and enters the
 * run particle by particle as each centre crosses the inlet plane (kernel/jdem_inlet.h). */
typedef struct jd_inlet {
    char name[JD_NAME_MAX];
    size_t n;                 /* particles per section, >= 1 */
    double *rel;              /* 3n positions relative to the section origin [m] */
    double *radius;           /* n radii [m] */
    int32_t *material;        /* n indices into materials */
    double origin[3];         /* copy 0's origin at t = 0 [m] */
    double velocity[3];       /* belt velocity [m/s] */
    double plane_point[3];    /* [m] */
    double plane_normal[3];   /* towards the domain, any length > 0 [-] */
    double period;            /* L [m] */
    double offset;            /* copy 0 set back along the belt [m] */
    int64_t first_id;         /* id of particle 0 of copy 0 */
    double max_insert_overlap; /* a particle whose place is occupied beyond this overlap (fraction
                                 of the smaller radius) is skipped (kernel/jdem_inlet.h); INFINITY:
                                 never */
    int stop;                 /* jd_inlet_stop */
    int64_t sections;         /* JD_INLET_STOP_SECTIONS: copies, >= 1 */
    double stop_time;         /* JD_INLET_STOP_TIME: no copy starts at or after ceil(time/dt) [s] */
    double height;            /* JD_INLET_STOP_HEIGHT: deposit top z + R that stops the stream [m] */
    double below_speed;       /* JD_INLET_STOP_HEIGHT: only particles slower than this count [m/s] */
    int64_t every;            /* JD_INLET_STOP_HEIGHT: steps between checks, >= 1 */
    int settled;              /* the section holds particles of a settled deposit (from_deposit):
                                 its overlaps are checked against watchdog.max_overlap_fraction */
    /* Bonds between section particles (section.blocks, section.bonds; docs/scenes.md "Bonded
     * blocks in an inlet section"), formed in every copy when its group is inserted. */
    size_t n_bonds;
    int32_t *bond_pair;       /* 2 n_bonds section indices, smaller first, sorted by (first, second) */
    int32_t *bond_type;       /* n_bonds indices into bond_types */
    /* Bonded groups: the connected components of those bonds (kernel/jdem_inlet.h), numbered by
     * their smallest member; each is inserted whole at its first member's crossing step. */
    size_t n_groups;
    size_t *group_first;      /* n_groups + 1 offsets into group_member */
    size_t *group_member;     /* members of each group, increasing */
    int32_t *group_of;        /* n: the group of each particle, -1: none */
} jd_inlet;

typedef struct jd_scene {
    char path[1024];          /* the scene file */
    char name[JD_NAME_MAX];   /* scene name */
    char case_name[2 * JD_NAME_MAX];
    char description[512];

    /* time */
    double dt;                /* [s]; time.dt, or JD_DT_AUTO_FACTOR x the guard's safe dt when
                                 the scene omits dt or says `dt: auto` (sim.h) */
    int dt_auto;              /* 1: dt was chosen by the guard (auto) */
    int64_t steps;            /* from steps, or ceil(end_time/dt) */
    double max_impact_speed;  /* [m/s], resolved (given, or estimated as docs/scenes.md says) */
    double coordination_number; /* expected maximum contacts of one sphere [-], >= 1, for the
                                   time-step guard (kernel/jdem_guard.h) */

    /* output */
    int64_t output_every;
    int64_t observables_every;
    double compare_tolerance; /* largest scaled difference scripts/compare_trajectories.py accepts
                                 between two engines' runs of this scene [-] */
    int energy;               /* 1: energy bookkeeping and the energy observables (default); 0:
                                 neither (the force loops skip JD_F_ENERGY; no energy watchdog) */

    double gravity[3];        /* [m/s^2] */

    /* domain (docs/scenes.md "Domain"): with has_domain, a particle whose centre is outside
     * [domain_lo, domain_hi) along some axis at a neighbour build is deleted, as LIGGGHTS does
     * with `boundary f f f` and `thermo_modify lost ignore` at a reneighbouring step */
    int has_domain;
    double domain_lo[3], domain_hi[3]; /* [m] */

    jd_watchdog_limits watchdog;

    /* neighbour lists (docs/scenes.md "Neighbour lists") */
    int64_t skin_steps;       /* a particle gets a half skin of what it crosses in this many
                                 steps, if that is more than skin/2 (up to its radius and its
                                 distance from the domain's faces, never below skin/2); 0: the
                                 common skin for all */

    /* model options (kernel enums) */
    int wall_rule;            /* jd_wall_rule */
    int damping_map;          /* jd_damping_map */
    int xi_limit;             /* jd_xi_limit */
    double mu_r;
    int tangential_rule;      /* jd_tangential_rule (model.tangential_stiffness) */
    int normal_law;           /* jd_normal_law (model.normal_law) */
    double mepa_exponent;     /* MEPA's n (model.mepa_exponent) [-] */
    double mepa_plastic_depth; /* MEPA's cap of the plastic overlap / R* (model.mepa_plastic_depth) */

    size_t n_materials;
    jd_material *materials;
    jd_interaction *interactions; /* n_materials x n_materials, symmetric, row-major */

    /* particles, sorted by id; structure of arrays */
    size_t n_particles;
    int64_t *id;
    int32_t *material;        /* index into materials */
    double *radius;           /* [m] */
    double *position;         /* 3n [m] */
    double *velocity;         /* 3n [m/s] */
    double *angular_velocity; /* 3n [rad/s] */
    unsigned char *fixed;     /* n: 1 = force and torque held at zero (moves at its initial
                                 velocity and spin, like LIGGGHTS fix freeze) */
    double *force;            /* 3n: constant external force [N] (LIGGGHTS fix addforce) */
    unsigned char *settled;   /* n: 1 = from a settled deposit (particles_from): its overlaps with
                                 other settled particles are contacts, allowed at the start up to
                                 watchdog.max_overlap_fraction */
    int has_loads;            /* some particle is fixed or has an external force */

    size_t n_walls;
    jd_wall *walls;
    size_t n_mesh_walls;      /* walls of type mesh, in file order */
    jd_mesh_wall *mesh_walls;

    /* bonds (docs/scenes.md "Bonds") */
    size_t n_bond_types;
    jd_bond_type *bond_types;
    size_t n_bonds;           /* bonds formed at step 0, sorted by (id[0], id[1]) */
    int64_t *bond_ids;        /* 2 n_bonds particle ids, id[0] < id[1] */
    int32_t *bond_type;       /* n_bonds indices into bond_types */
    size_t n_bond_rules;
    jd_bond_rule *bond_rules; /* sorted by step (stable) */

    size_t n_inlets;          /* conveyor inlets (docs/mixing.md 2.1), in file order */
    jd_inlet *inlets;
} jd_scene;

/* The failures of scene_list_cases and scene_load: the file is not a valid scene (or cannot be
 * read), or memory ran out while reading it.  Either way err holds the message. */
enum { SCENE_BAD_INPUT = -1, SCENE_NO_MEMORY = -2 };

/* List the case names of a scene file.  Returns the number of cases (>= 1) and an array of
 * names in *names (free with scene_free_names), or SCENE_BAD_INPUT / SCENE_NO_MEMORY with a
 * message in err. */
int scene_list_cases(const char *path, char ***names, char *err, size_t errlen);
void scene_free_names(char **names, int n);

/* Load one case (case_name NULL: the scene must have exactly one case).  Returns 0, or
 * SCENE_BAD_INPUT with a message "FILE:LINE: key 'a.b.c': what is wrong; what would be valid"
 * in err, or SCENE_NO_MEMORY. */
int scene_load(const char *path, const char *case_name, jd_scene *scene, char *err, size_t errlen);

/* Write the resolved scene as YAML in the scene-file schema (no sweep, no generate, every
 * default explicit, numbers with 17 significant digits).  Returns 0 or -1. */
int scene_emit_yaml(const jd_scene *scene, FILE *out);

/* The same text in a malloc'ed string (for /parameters/scene); NULL on failure. */
char *scene_yaml_string(const jd_scene *scene);

void scene_free(jd_scene *scene);

struct jd_inlet_spec;
/* The kernel's description of inlet k of the scene (kernel/jdem_inlet.h; its arrays point into
 * the scene).  The stepper builds its stream from this (scene_inlets.c); the LIGGGHTS fix
 * builds the same one from the resolved scene's values. */
void scene_inlet_spec(const jd_scene *scene, size_t k, struct jd_inlet_spec *out);

/* The pairs a bond rule bonds at positions x (3 n_particles [m], in the scene's order): particles
 * i < j (indices) both in the rule's group (material flag set, id in id_range) with
 * |x_j - x_i| - R_i - R_j <= max_gap min(R_i, R_j).  Returns the number of pairs with
 * 2 per pair in *pairs (malloc'ed, sorted by (i, j); NULL when none), or -1 when out of memory.
 * scene_bond_rules.c; used by the scene (rules at step 0) and by the stepper (later steps). */
long jd_bond_rule_pairs(const jd_scene *s, const jd_bond_rule *rule, const double *x,
                        int32_t **pairs);

#endif /* JDEM_SCENE_H */
