/* fix_jdem_watchdog.h — `fix ID group jdem/watchdog N [overlap F] [energy J|off]`: the run-time
 * watchdog of docs/scenes.md ("Watchdog") in LIGGGHTS, with the stepper's limits
 * (kernel/jdem_watchdog.h) and message text.
 *
 * Every step (end_of_step, and once at set-up): a non-finite force, torque, position, velocity
 * or angular velocity of an atom of the group; an overlap beyond F (default 0.5) of the smaller
 * radius in pair_style gran/jiang or any fix wall/jiang.  Every N steps, and at the last step:
 * a jump of the total energy (the observables of dump h5md/jdem, bonds included) beyond J (default 0.05)
 * relative to the energy in play, since the previous check (energy off: no energy check, as
 * build/jdem with output.energy: false).  On a trip the dumps write the
 * frame of this step (not for a non-finite state) and the run ends through error->all with
 * "jdem: watchdog: step S: QUANTITY VALUE for particle(s) IDS exceeds LIMIT ...": dump
 * h5md/jdem then keeps its file, closed, as FILE.part.
 *
 * Energy that enters the run counts as input (wall_work), as in the stepper: fix jdem/inlet's
 * inflow, and the kinetic, rotational and gravitational energy of each atom that LIGGGHTS' fix
 * insert/... inserts (booked in the state it has at the end of its insertion step, the state the
 * energy account first sees).  A new atom is one whose id exceeds the largest id present at the
 * end of the step before the insertion (fix insert gives new atoms ids above every present one).
 * f_ID is that booked insertion energy [J]; every run's end prints it.
 *
 * Requires pair_style gran/jiang.  scripts/scene_to_liggghts.py writes this fix from the scene's
 * watchdog: section. */
#ifndef JDEM_FIX_JDEM_WATCHDOG_H
#define JDEM_FIX_JDEM_WATCHDOG_H

#include <cstdio>
#include <string>
#include <vector>

#include "fix.h"

#include "jdem_watchdog.h"

namespace LAMMPS_NS {

class FixJdemWatchdog : public Fix {
 public:
  FixJdemWatchdog(class LAMMPS *, int, char **);
  int setmask();
  void init();
  void setup(int);
  void end_of_step();
  void write_restart(FILE *);
  void restart(char *);
  void post_run();
  double compute_scalar() { return inserted_energy; }
  bool checks_energy() const { return max_energy_jump > 0.0; }

 private:
  void check();
  bool inserting_at(bigint step) const;
  void note_last_tag();
  void book_insertions();
  bool nonfinite(std::string &msg);
  bool overlap(std::string &msg);
  bool energy(std::string &msg);
  int most_energetic();
  void trip(const std::string &msg, bool write_frame);

  int energy_every;
  double max_overlap, max_energy_jump; /* max_energy_jump 0: energy off */
  bool has_ref;
  jd_energy_terms ref;
  bigint ref_step;
  /* LIGGGHTS' fix insert/... of the run (init), the largest atom id present before the next
   * insertion, the energy [J] and the number of the atoms they inserted */
  std::vector<class FixInsert *> inserts;
  int last_tag;
  double inserted_energy, inserted_atoms;
};

}  // namespace LAMMPS_NS

#endif
