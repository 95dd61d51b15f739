/*
 * jdem_observable_names.h — the names of the /observables of docs/scenes.md, one list for both
 * engines (the stepper's observables.c and bonds.c, the plugin's jdem_observables and its dump),
 * with which of them need the energy bookkeeping (not written with output.energy off).
 * Pure C11: constants only.
 */
#ifndef JDEM_KERNEL_OBSERVABLES_H
#define JDEM_KERNEL_OBSERVABLES_H

#ifdef __cplusplus
extern "C" {
#endif

/* The contact observables, in the order the trajectory lists them. */
enum {
    JD_OBS_KINETIC,       /* kinetic_energy [J]                                  */
    JD_OBS_ROTATIONAL,    /* rotational_energy [J]                               */
    JD_OBS_ELASTIC,       /* elastic_energy: stored in the contacts [J]           */
    JD_OBS_GRAVITATIONAL, /* gravitational_energy [J]                            */
    JD_OBS_DAMPING,       /* damping_dissipation [J]                             */
    JD_OBS_FRICTION,      /* friction_dissipation [J]                            */
    JD_OBS_WALL_WORK,     /* wall_work: done on the particles by the walls [J]    */
    JD_OBS_CONTACTS,      /* contacts: particle pairs carrying force [-]          */
    JD_OBS_WALL_CONTACTS, /* wall_contacts [-]                                    */
    JD_N_OBSERVABLES
};
static const char *const jd_observable_names[JD_N_OBSERVABLES] = {
    "kinetic_energy",      "rotational_energy",    "elastic_energy",
    "gravitational_energy", "damping_dissipation", "friction_dissipation",
    "wall_work",           "contacts",             "wall_contacts"};
static const int jd_observable_is_energy[JD_N_OBSERVABLES] = {0, 0, 1, 0, 1, 1, 1, 0, 0};

/* The bond observables (scenes with bond types). */
enum {
    JD_OBS_BONDS,         /* bonds: intact [-]                                    */
    JD_OBS_FRAGMENTS,     /* fragments: connected groups of bonded particles [-]  */
    JD_OBS_BOND_ELASTIC,  /* bond_elastic_energy [J]                              */
    JD_OBS_BOND_DAMPING,  /* bond_damping_dissipation [J]                         */
    JD_OBS_BOND_BREAKAGE, /* bond_breakage_energy [J]                             */
    JD_N_BOND_OBSERVABLES
};
static const char *const jd_bond_observable_names[JD_N_BOND_OBSERVABLES] = {
    "bonds", "fragments", "bond_elastic_energy", "bond_damping_dissipation",
    "bond_breakage_energy"};
static const int jd_bond_observable_is_energy[JD_N_BOND_OBSERVABLES] = {0, 0, 1, 1, 1};

/* A scene with inlets also writes INLET_ENERGY [J]: the kinetic and gravitational energy the
 * inserted particles brought, 1/2 m v^2 - m g.x summed over them in insertion order (the input
 * side of the energy balance; with several inlets the LIGGGHTS fixes add their sums in fix
 * order, equal to the stepper's one running sum to round-off). */
static const char *const jd_obs_inlet_energy = "inlet_energy";

/* ... and SKIPPED_PARTICLES [-]: the particles its inlets did not insert because their place
 * was occupied (kernel/jdem_inlet.h "Insertion into an occupied place"), so far. */
static const char *const jd_obs_skipped_particles = "skipped_particles";

/* A scene with a domain (kernel/jdem_domain.h) also writes LOST_PARTICLES [-], the particles
 * deleted outside it so far, and LOST_ENERGY [J], the energy they took (jd_lost_energy summed;
 * the output side of the balance). */
static const char *const jd_obs_lost_particles = "lost_particles";
static const char *const jd_obs_lost_energy = "lost_energy";

/* The wall observables of a scene with a servo wall (docs/scenes.md "Servo walls"), each a
 * scalar series: for every wall WALL_FORCE/NAME/{x,y,z} [N], the particles' total force on it;
 * for every servo wall SERVO_STRESS/NAME [Pa] (its measured stress, jd_servo_stress) and
 * SERVO_POSITION/NAME [m] (its displacement along its normal since the start); and
 * STRESS_TENSOR/{xx,xy,...,zz} [Pa], the boundary stress of jd_stress_tensor, row-major. */
static const char *const jd_obs_wall_force = "wall_force";
static const char *const jd_obs_servo_stress = "servo_stress";
static const char *const jd_obs_servo_position = "servo_position";
static const char *const jd_obs_stress_tensor = "stress_tensor";
static const char *const jd_obs_axes[3] = {"x", "y", "z"};
static const char *const jd_obs_tensor_components[9] = {"xx", "xy", "xz", "yx", "yy",
                                                         "yz", "zx", "zy", "zz"};

#ifdef __cplusplus
}
#endif
#endif /* JDEM_KERNEL_OBSERVABLES_H */
