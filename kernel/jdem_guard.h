/*
 * jdem_guard.h — the time-step guard shared by both engines (the stepper's `jdem run` and
 * LIGGGHTS' `fix jdem/guard`): is a time step safe for a scene, which bound binds, and what is
 * the largest safe step?  docs/model.md §8 gives the bounds and their evidence.
 *
 * Three bounds, each from the smallest sphere of each species (pure C11: no I/O, no
 * allocation, no globals):
 *   rayleigh      JD_GUARD_RAYLEIGH_FRACTION of the Rayleigh step of eq. (34) (Jiang 2021
 *                 §2.6, "typical 20 %");
 *   contact_time  the shortest Hertz contact (any pair of species, any species against a wall)
 *                 at the scene's max_impact_speed spans JD_GUARD_STEPS_PER_CONTACT steps
 *                 (accuracy of the force curve; erratum 18); with MEPA, its impact
 *                 (jd_mepa_impact_time); the Rayleigh bound still reads E, nu and the density,
 *                 which a MEPA scene gives (MEPA's law itself reads none of E, nu);
 *   coordination  stability of velocity Verlet, omega_max dt <= 2, with omega_max bounded for a
 *                 particle with C contacts (Otsubo, O'Sullivan & Shire 2017: the critical step
 *                 depends on m, K_max and the maximum coordination number; see docs/model.md);
 *   bond          with parallel bonds, the fastest bond mode spans JD_GUARD_STEPS_PER_BOND_PERIOD
 *                 steps (the engine sums jd_bond_omega2_bound, kernel/jdem_bond.h, over the bonds
 *                 of each particle: a Gershgorin bound; docs/model.md §9).
 */
#ifndef JDEM_KERNEL_GUARD_H
#define JDEM_KERNEL_GUARD_H

#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

#define JD_GUARD_RAYLEIGH_FRACTION 0.2
#define JD_GUARD_STEPS_PER_CONTACT 50.0
#define JD_GUARD_STEPS_PER_BOND_PERIOD 20.0
/* Default expected (maximum) coordination number: the kissing number of equal spheres. */
#define JD_GUARD_DEFAULT_COORDINATION 12.0

/* One species (material) as the guard sees it. */
typedef struct jd_guard_species {
    size_t count;   /* particles of this species (0: the species is absent and ignored) */
    double rmin;    /* smallest radius of the species [m] */
    double density; /* [kg/m^3] */
    double E;       /* Young's modulus [Pa] */
    double nu;      /* Poisson's ratio [-] */
    double mepa_k1; /* MEPA's virgin-loading stiffness of the material (normal_law MEPA) [N/m^n] */
    double mepa_k2; /* its unloading stiffness [N/m^n] */
} jd_guard_species;

typedef struct jd_guard_input {
    const jd_guard_species *species;
    size_t n_species;
    int has_walls;           /* any wall the particles may touch */
    int wall_rule;           /* jd_wall_rule (jdem_kernel.h) */
    int tangential_rule;     /* jd_tangential_rule (jdem_kernel.h): which K_t the tangential
                                spring has */
    int normal_law;          /* jd_normal_law (jdem_kernel.h): Hertz, or MEPA with the species'
                                mepa_k1, mepa_k2 (a wall taken as rigid: the particle's own) */
    double mepa_n;           /* MEPA's exponent [-] (normal_law MEPA) */
    double max_impact_speed; /* fastest relative impact to resolve [m/s]; 0: nothing moves */
    double coordination;     /* expected maximum contacts of one particle [-], >= 1 */
    double damping_ratio;    /* largest viscous damping ratio gamma of any pair [-], >= 0 */
    double bond_omega2;      /* largest over the particles of the sum of jd_bond_omega2_bound
                                over its bonds [rad^2/s^2]; 0 without bonds */
    double dt;               /* the time step to judge [s] */
} jd_guard_input;

/* The guard's damping ratio: the largest gamma (jd_gamma_for with damping_map) of any pair of
 * species of which the first has particles (species[a].count > 0); restitution is n_species x
 * n_species, row-major [-]. */
double jd_guard_damping_ratio(const jd_guard_species *species, size_t n_species,
                              const double *restitution, int damping_map);

typedef enum {
    JD_GUARD_SAFE = 0,
    JD_GUARD_RAYLEIGH = 1,
    JD_GUARD_CONTACT_TIME = 2,
    JD_GUARD_COORDINATION = 3,
    JD_GUARD_BOND = 4
} jd_guard_bound;

typedef struct jd_guard_result {
    double rayleigh_bound;     /* JD_GUARD_RAYLEIGH_FRACTION x the smallest Rayleigh step [s];
                                  INFINITY without particles */
    double contact_time;       /* shortest Hertz contact time at max_impact_speed [s]; INFINITY
                                  when nothing moves */
    double contact_bound;      /* contact_time / JD_GUARD_STEPS_PER_CONTACT [s] */
    double omega_max;          /* upper bound of the highest angular frequency of a particle
                                  with `coordination` contacts at the impact's peak overlap
                                  [rad/s]; 0 when nothing moves */
    double coordination_bound; /* 2/omega_max, reduced for damping [s]; INFINITY when nothing
                                  moves */
    double bond_bound;         /* 2 pi / sqrt(bond_omega2) / JD_GUARD_STEPS_PER_BOND_PERIOD [s];
                                  INFINITY without bonds */
    double safe_dt;            /* the smallest of the four bounds [s] */
    int binding;               /* jd_guard_bound: the smallest bound (SAFE only if all are
                                  infinite) */
    int violated;              /* jd_guard_bound: the smallest bound dt exceeds, or SAFE */
    double violated_value;     /* its value [s] */
} jd_guard_result;

/* Assess in->dt.  Pure: reads in, writes out. */
void jd_guard_assess(const jd_guard_input *in, jd_guard_result *out);

/* "20 % of the Rayleigh time step", "1/50 of the shortest Hertz contact time", "the Verlet
 * stability limit at coordination number C" (without C), "1/20 of the fastest bond period",
 * "" for SAFE. */
const char *jd_guard_bound_name(int bound);

/* The engines' shared texts, written into buf (len bytes; no I/O):
 *   refusal  "time step DT s is unsafe: it exceeds BOUND (V s); largest safe dt = S s. " +
 *            `hint` (how this engine overrides it)
 *   warning  "warning: time step DT s exceeds BOUND (V s); running anyway (" + `how` + ")"
 * Return the snprintf count. */
int jd_guard_refusal(const jd_guard_input *in, const jd_guard_result *r, const char *hint,
                     char *buf, size_t len);
int jd_guard_warning(const jd_guard_input *in, const jd_guard_result *r, const char *how,
                     char *buf, size_t len);

#ifdef __cplusplus
}
#endif
#endif /* JDEM_KERNEL_GUARD_H */
