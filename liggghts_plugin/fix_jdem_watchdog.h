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
 * Requires pair_style gran/jiang.  scripts/scene_to_liggghts.py writes this fix from the scene's
 * watchdog: section. */
#ifndef JDEM_FIX_JDEM_WATCHDOG_H
#define JDEM_FIX_JDEM_WATCHDOG_H

#include <cstdio>
#include <string>

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
  bool checks_energy() const { return max_energy_jump > 0.0; }

 private:
  void check();
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
};

}  // namespace LAMMPS_NS

#endif
