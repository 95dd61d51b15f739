/*
 * bonds.h — parallel bonds in the standalone engine (docs/scenes.md "Bonds"; the law is
 * kernel/jdem_bond.h).  The bond loop is separate from the contact loops: a bonded pair is also
 * an ordinary contact candidate, and the contact law acts whenever the spheres overlap, in
 * parallel with the bond.
 *
 * Bonds are stored by particle index (a = i, b = j as formed, i.e. the smaller id first), in
 * formation order: the scene's step-0 bonds sorted by ids, then each rule's bonds sorted by ids,
 * and an inlet's block bonds at their insertion steps (inlet.c: by inlet, then ids).
 * Only intact bonds are kept; a bond that breaks is removed at the end of the loop that broke it
 * (order kept) after its event is recorded and its energies are moved to the totals.  A spatial
 * re-sort of the particles remaps the list with sim_bonds_permute().
 */
#ifndef JDEM_BONDS_H
#define JDEM_BONDS_H

#include <stddef.h>
#include <stdint.h>

#include "h5md.h"
#include "jdem_bond.h"
#include "jdem_laws.h"
#include "jdem_observable_names.h"

struct jd_particles;
struct jd_run_constants;
struct jd_thread_layout;
struct jd_scene;

/* A bond's state is the kernel's record (jdem_laws.h, jd_bond_record_len: without the energy
 * bookkeeping only the law's fields).  The cross-section and the dashpots' effective masses are
 * not stored: the bond loop computes them from the particles' radii and masses each step (as the
 * LIGGGHTS plugin does for the masses), which keeps a bond at 84 bytes, 156 with the
 * bookkeeping.  (When all particles share one radius the sections are taken per type:
 * jd_bond_section_of's three divisions cost a fifth of a bond's evaluation.) */

/* A failed bond's figures, what its event records (jd_bond_result's). */
typedef struct jd_bond_failure {
    double fn, ft, mn, mt, sigma_max, tau_max;
} jd_bond_failure;

/* One bond's result in the threaded bond loop, kept from its evaluation to the forces' sums
 * and the events (bonds.c bond_loop_threads). */
typedef struct jd_bond_out {
    int mode; /* jd_bond_mode (JD_BOND_INTACT or a failure), or -1: not evaluated (coincident
                 centres) */
    union {
        struct {
            double f[3], ta[3], tb[3]; /* force on b, torques on a and b [N], [N m] */
        } force;                       /* intact */
        struct {
            jd_bond_failure r;
            double xc[3]; /* the bond point [m] */
        } broke;          /* failed */
    };
} jd_bond_out;

typedef struct jd_bonds {
    unsigned features;         /* JD_B_* of the bond loop, fixed for the run */
    size_t n_types;
    const jd_bond_params *params; /* per type (n_types), copied from the scene */
    const jd_bond_section *sec_type; /* per type when all particles share one radius (every bond of
                                        a type then has the same section), else NULL */
    size_t n, cap;             /* intact bonds */
    int32_t *i, *j;            /* particle indices of a and b */
    int32_t *type;             /* index into params */
    int sw;                    /* doubles of state per bond: JD_BOND_LAWS_LEN, or JD_BOND_STATE_LEN
                                  with the energy bookkeeping (JD_B_ENERGY) */
    double *state;             /* cap x sw: the leading sw doubles of each bond's jd_bond_state */
    jd_bond_out *out;          /* out_cap results of the threaded bond loop; NULL with one
                                  thread */
    size_t out_cap;
    size_t next_rule;          /* first scene rule not yet applied */
    unsigned char *ever;       /* per particle: 1 once it has been bonded (fragment count) */
    size_t ever_cap;           /* entries of ever: every particle the run can hold (inlets) */
    /* output not yet written */
    jd_h5md_bond *formed;      /* bonds formed since the last sim_bonds_output */
    size_t n_formed, formed_cap;
    jd_h5md_bond_break *events; /* breaks since the last sim_bonds_output */
    size_t n_events, events_cap;
    const char *failed;        /* set when the bond loop ran out of memory (reported by
                                  sim_bonds_output, which stops the run) */
    /* totals */
    int64_t n_broken[3];       /* by jd_bond_mode (index 0 unused) */
    double e_damp_dropped, e_break_dropped; /* energies of removed bonds [J] */
} jd_bonds;

/* Bond observables (the /observables written for scenes with bond types). */
typedef struct jd_bond_observables {
    double bonds, fragments;   /* intact bonds; components of the intact-bond graph over the
                                  particles ever bonded */
    double elastic_energy, damping_dissipation, breakage_energy; /* [J]; 0 without the energy
                                                                    bookkeeping */
} jd_bond_observables;
/* The values in the order of jd_bond_observable_names (kernel/jdem_observables.h). */
void sim_bond_observables_values(const jd_bond_observables *o, double out[JD_N_BOND_OBSERVABLES]);

/* Set up *bonds from the scene and its particles ps (NULL when the scene has no bond types);
 * capacity: every particle the run can hold (the inlets' included).  0 or -1 with err. */
int sim_bonds_init(jd_bonds **bonds, const struct jd_particles *ps, const struct jd_scene *sc,
                   size_t capacity, char *err, size_t errlen);
/* Form an intact, unstressed bond between particle indices i and j (either order: a = the smaller
 * id) at `step`, recorded for /connectivity (an inlet's block, inlet.c).  0, or -1 when out of
 * memory (also set in b->failed, which stops the run at the next sim_bonds_output). */
int sim_bonds_form(jd_bonds *b, const struct jd_particles *ps, int32_t i, int32_t j, int32_t type,
                   int64_t step);
void sim_bonds_free(jd_bonds **bonds);
/* Bytes the bonds hold (the bond arrays at their capacity, the output not yet written); 0 for
 * NULL. */
size_t sim_bonds_memory_bytes(const jd_bonds *b, size_t n_particles);

/* Form the bonds of rules due at the step being computed (steps_done + 1), then add every intact
 * bond's force and torques to ps->f and ps->torque.  Called by sim_compute_forces.  At step 0
 * (in_setup, LIGGGHTS `setup`) the bonds are evaluated with dt = 0: no increment, the force
 * is the stored one (zero for a new bond) plus the dashpots, and no rule is applied. */
void sim_bonds_forces(jd_bonds *b, struct jd_particles *ps, const struct jd_run_constants *run,
                      const struct jd_thread_layout *threads, int64_t steps_done, int in_setup);

/* Write the bonds formed and the bonds broken since the last call to /connectivity (h may be
 * NULL: only forget them).  0; JD_RUN_OUTPUT with err on a write error; -1 with err when the
 * bond loop ran out of memory. */
int sim_bonds_output(jd_bonds *b, int64_t step, jd_h5md *h, char *err, size_t errlen);

/* The bond observables of a set of n_particles particles. */
void sim_bonds_observables(const jd_bonds *b, size_t n_particles, jd_bond_observables *o);

/* Remap the particle indices after a re-sort (reorder.c): particle k < n is now new_index[k]. */
void sim_bonds_permute(jd_bonds *b, const int32_t *new_index, size_t n);
/* Remove the bonds of the particles at indices >= keep (deleted, stepper/domain.c), keeping the
 * order of the others; their dissipation goes to the totals.  Returns the elastic energy they
 * held [J], which leaves the run with them (0 for NULL). */
double sim_bonds_drop_from(jd_bonds *b, size_t keep);

/* Time-step guard input (jd_guard_input.bond_omega2): the largest over the particles of the sum
 * of its bonds' squared frequency bounds (jd_bond_omega2_bound; Gershgorin) [rad^2/s^2]; 0
 * without bonds, INFINITY when out of memory (the guard then refuses).  Particles in a rule's group count 12 more
 * bonds to neighbours of their own size (the densest packing), since rules bond during the run. */
double sim_bonds_omega2(const struct jd_scene *sc);

#endif /* JDEM_BONDS_H */
