/* fix_jdem_observables.h — `fix ID group jdem/observables M DUMP-ID`: the observables of dump
 * h5md/jdem DUMP-ID sampled on their own cadence, as build/jdem's output.observables_every: at
 * step 0, every M steps and at the last step, whether or not the step is a frame.
 *
 * LIGGGHTS calls a dump at its frames only, so the samples between frames are taken here, at
 * end_of_step (after the final integration, the state the dump sees at a frame); at a frame the
 * dump writes the sample itself.  The group is not used: the dump's group is sampled.  Define
 * the fix after the fixes that change the state at end_of_step. */
#ifndef JDEM_FIX_JDEM_OBSERVABLES_H
#define JDEM_FIX_JDEM_OBSERVABLES_H

#include <string>

#include "fix.h"

namespace LAMMPS_NS {

class DumpH5mdJdem;

class FixJdemObservables : public Fix {
 public:
  FixJdemObservables(class LAMMPS *, int, char **);
  int setmask();
  void init();
  void end_of_step();

 private:
  bigint every;         /* M [steps] */
  std::string dump_id;  /* DUMP-ID */
  int dump_index;       /* in Output::dump, set by init() */
  DumpH5mdJdem *dump;
};

}  // namespace LAMMPS_NS

#endif
