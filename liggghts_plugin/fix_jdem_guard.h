/* fix_jdem_guard.h — `fix ID all jdem/guard vmax V [coordination C] [force]`: the time-step
 * guard of the standalone engine (kernel/jdem_guard.h, docs/model.md §8) in LIGGGHTS.
 *
 * At every run's set-up (after the set-up of the fix bond/jiang, which must be defined before
 * it) it gathers, over all ranks, the smallest radius and the density of each
 * atom type that has atoms, E and nu from pair_style gran/jiang, whether any fix wall/jiang
 * exists, and the largest damping ratio of a pair with a type that has atoms; V is the fastest
 * relative impact to resolve [m/s] (the scene's max_impact_speed) and C the expected
 * coordination number (default 12); with fix bond/jiang, the bonds' frequency bound
 * (FixBondJiang::omega2_max, summed over the bond fixes).  An unsafe `timestep` stops the run before anything is
 * written, with the stepper's message (error->all); `force` runs it anyway with a warning.
 * scripts/scene_to_liggghts.py writes this fix from the resolved scene. */
#ifndef JDEM_FIX_JDEM_GUARD_H
#define JDEM_FIX_JDEM_GUARD_H

#include "fix.h"

namespace LAMMPS_NS {

class FixJdemGuard : public Fix {
 public:
  FixJdemGuard(class LAMMPS *, int, char **);
  int setmask() { return 0; }
  void init();
  void setup(int);

 private:
  double vmax, coordination;
  bool force_run;
};

}  // namespace LAMMPS_NS

#endif
