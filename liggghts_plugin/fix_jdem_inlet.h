/* fix_jdem_inlet.h — `fix ID group jdem/inlet file SECTION origin X Y Z velocity VX VY VZ
 *                     plane PX PY PZ NX NY NZ period L [offset D] first_id ID
 *                     stop sections N | stop time T | stop height H [below_speed V] [every N]
 *                     [max_insert_overlap F | inf] [record FILE | append_record FILE]`:
 * the conveyor inlet of docs/mixing.md 2.1 in LIGGGHTS, the stream of kernel/jdem_inlet.h (the
 * same function calls as build/jdem's stepper/inlet.c, so the particles, ids, steps, positions and
 * velocities are the stepper's bit for bit).
 *
 * SECTION: one line per section particle, "TYPE RADIUS DENSITY X Y Z" (atom type, [m], [kg/m^3],
 * position relative to the section origin [m]; '#' comments); particle p of copy c gets the atom
 * id first_id + c n + p, the type, radius and density of line p and the mass 4/3 pi R^3 rho
 * (jd_sphere_mass, as read_data).  Bonded blocks (Jiang (2021) Ch. 5): lines "bond I J T" join
 * section particles I and J (0-based, in the order of the particle lines) by a bond of type T
 * (0-based: the T+1-th fix bond/jiang of the input, as /connectivity/bond_type counts them).
 * The bonds' connected components are groups the kernel inserts whole (jd_inlet_groups,
 * "Bonded groups of a section" in kernel/jdem_inlet.h); at a group's insertion step the rank
 * that owns a bond's lower id forms it in that fix bond/jiang, unstressed, copies in increasing
 * order and each copy's bonds in (I, J) order, as build/jdem does.  The other keywords are the fields of jd_inlet_spec and the
 * scene's stop rule (the deck generator writes them from the resolved scene's inlets:).  record:
 * rank 0 writes every insertion as `jdem run --inlet-record` does (jd_inlet_record_line), in a
 * new file; append_record: after the lines of an earlier fix jdem/inlet (a deck with several
 * inlets keeps one record, in the stepper's order).
 *
 * When.  A particle due at step k (its crossing step) exists from step k on: it is created in
 * pre_exchange of step k at x(k) (after the step's first half kick and drift, which it does not
 * take), the step's forces and final half kick see it, and at end_of_step its state is set to
 * the stepper's: velocity the belt's, no spin, force m g (the fixes gravity's acceleration) and
 * no torque, so that the frame of step k shows it as build/jdem does and it is integrated from
 * step k.  (A particle that touches something at its crossing point would push on it one step
 * earlier than in build/jdem: a well-placed inlet plane is in free space.)  Define the fix
 * before the fixes that read the state at end_of_step (jdem/watchdog, jdem/observables).
 *
 * Where.  Every rank computes the whole stream (it is a rigid motion, O(n) per due step); each
 * particle is created by the rank whose subdomain holds it, with LIGGGHTS' own atom creation
 * (AtomVec::create_atom, the create_attribute fixes' set_arrays, natoms, the atom map), as fix
 * insert/pack and insert/stream do.  A particle outside every subdomain (outside the box) stops the run.
 *
 * Occupied places (kernel/jdem_inlet.h "Insertion into an occupied place").  Before creating
 * the step's particles, the ghosts' positions are brought to this step (a forward
 * communication: pre_exchange runs before the step's own); the rank that owns a due particle's
 * position measures its worst overlap with its local and ghost atoms (a ghost cutoff of twice
 * the largest radius and more covers every atom that can touch it), the ranks share those
 * (one reduction), and every rank applies the kernel's rule (jd_inlet_skip_groups): a particle
 * (with its bonded block) whose place is occupied beyond max_insert_overlap (a fraction of the
 * smaller radius; default JD_INLET_MAX_INSERT_OVERLAP, inf: never skip) is not created, and is
 * counted (skipped(), the observable skipped_particles); rank 0 reports the first
 * JD_INLET_REPORTED, as build/jdem does.
 *
 * Cost.  The fix asks for a re-neighbouring at the next due step only (force_reneighbor,
 * next_reneighbor); at any other step pre_exchange and end_of_step compare the step with one
 * number and return, so a pending particle costs nothing per step.
 *
 * Energy.  The kinetic and gravitational energy the inserted particles bring, 1/2 m v^2 - m g.x
 * summed in insertion order (the stepper's inlet_energy), is booked as input by fix
 * jdem/watchdog and printed at the end of each run with the count and the insertion cost
 * ("fix ID jdem/inlet: inserted N particles, inflow energy E J, insertion S s, X ns per
 * particle": the slowest rank's time).  Stop rules: sections and time are the stream's (jd_inlet_spec); height is
 * checked at end_of_step of the steps jd_inlet_height_due names, with the largest top
 * (jd_inlet_deposit_top) over the ranks. */
#ifndef JDEM_FIX_JDEM_INLET_H
#define JDEM_FIX_JDEM_INLET_H

#include <cstdio>
#include <string>
#include <vector>

#include "fix.h"

#include "jdem_inlet.h"

namespace LAMMPS_NS {

class FixJdemInlet : public Fix {
 public:
  FixJdemInlet(class LAMMPS *, int, char **);
  ~FixJdemInlet();
  int setmask();
  void init();
  void pre_exchange();
  void end_of_step();
  void post_run();
  /* f_ID: the work the stream still brings until the run's last step [particle-steps]
   * (jd_inlet_pending_particle_steps), the same on every rank; scripts/liggghts_run.py's ETA
   * reads it through fix print (scripts/scene_to_liggghts.py) */
  double compute_scalar();
  /* restart files (jdem_restart.h) */
  void write_restart(FILE *);
  void restart(char *);
  /* the largest section radius of atom type t [m] (0 for a type the section lacks): LIGGGHTS'
   * granular pair styles size the neighbour and ghost cutoffs of future particles with it */
  double max_rad(int t);
  /* the smallest and largest atom type of the section (LIGGGHTS' material properties count
   * the types of future particles with them) */
  int min_type();
  int max_type();

  /* kinetic + gravitational energy the inserted particles brought [J] (the same on every rank) */
  double inflow_energy() const { return energy_in; }
  /* particles inserted so far (all ranks) and the wall time this rank spent inserting [s] */
  long long inserted() const { return (long long)stream.inserted; }
  /* particles not inserted because their place was occupied (all ranks) */
  long long skipped() const { return (long long)stream.skipped; }
  double seconds() const { return insert_seconds; }
  /* the section: its particles' atom types - 1, radii [m] and densities [kg/m^3] (fix jdem/guard
   * counts them as the stepper's guard does, once each) */
  const std::vector<int32_t> &section_types() const { return type0; }
  const std::vector<double> &section_radii() const { return radius; }
  const std::vector<double> &section_densities() const { return density; }
  /* For fix jdem/guard: the section's bonds' frequency bound (jd_inlet_bond_omega2), 0 without
   * bonds [rad^2/s^2]; valid after init(). */
  double section_bond_omega2();

 private:
  void parse(int narg, char **arg);
  void read_section(const char *path);
  void open_record(const char *path, bool append);
  void start_stream();
  void create(const jd_inlet_particle &p, const double g[3]);
  void check_created(const std::vector<jd_inlet_particle> &due, int created_here);
  std::vector<jd_inlet_particle> kept_of(const std::vector<jd_inlet_particle> &due);
  void report_skip(const jd_inlet_particle &p, double worst, int with_tag);
  void settle_new_particles();
  void height_rule();
  void sort_bonds(const std::vector<int> &bonds, const char *path);
  void make_groups();
  void find_bond_fixes();
  void form_block_bonds(const std::vector<jd_inlet_particle> &due);

  jd_inlet_spec spec;
  std::vector<double> rel, radius, density;
  std::vector<int32_t> type0; /* atom type - 1 of each section particle (spec.species) */
  /* the section's bonds (I < J, sorted by (I, J)), their types, and the groups they make */
  std::vector<int32_t> bond_pair, bond_type, group_of;
  std::vector<size_t> group_first, group_member;
  std::vector<class FixBondJiang *> bond_fix; /* fix bond/jiang of each bond type, in input order */
  std::vector<jd_inlet_cursor> cursor;
  jd_inlet_stream stream;
  bool started;
  double stop_time;           /* stop time [s], or < 0 */
  double height, below_speed; /* stop height [m] (< 0: none), the speed below which a particle counts [m/s] */
  long long every;            /* steps between height checks */
  std::vector<int> new_ids;   /* the particles inserted at this step (tags) */
  double gravity[3];          /* of the insertion step [m/s^2] */
  double energy_in, insert_seconds;
  FILE *record;
};

}  // namespace LAMMPS_NS

#endif
