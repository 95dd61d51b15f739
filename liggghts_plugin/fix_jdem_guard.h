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
 * The particles still to come count too: fix jdem/inlet's sections, and the templates
 * (particletemplate/sphere) of LIGGGHTS' insert/pack, insert/stream and insert/rate/region,
 * whose fastest insertion speed raises V; an insertion it cannot read is named in a warning.
 * scripts/scene_to_liggghts.py writes this fix from the resolved scene. */
#ifndef JDEM_FIX_JDEM_GUARD_H
#define JDEM_FIX_JDEM_GUARD_H

#include "fix.h"

#include <vector>

namespace LAMMPS_NS {

/* Per atom type (index type - 1): the smallest radius [m], its density [kg/m^3] and how many
 * particles (present, or one per template / inlet section particle) the guard evaluates. */
struct JdemGuardTally {
  std::vector<double> &rmin, &rho, &count;
  void add(int t, double r, double density, double n);
  bool any() const;
};

class FixJdemGuard : public Fix {
 public:
  FixJdemGuard(class LAMMPS *, int, char **);
  int setmask() { return 0; }
  void init();
  void setup(int);

 private:
  void add_inlets(JdemGuardTally &tally);
  double add_templates(JdemGuardTally &tally);
  void cannot_check(const Fix *f, const char *why);
  double vmax, coordination;
  bool force_run;
};

}  // namespace LAMMPS_NS

#endif
