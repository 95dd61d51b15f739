/* fix_jdem_observables.cpp — see fix_jdem_observables.h. */
#include "fix_jdem_observables.h"

#include <cstring>

#include "error.h"
#include "force.h"
#include "output.h"
#include "update.h"

#include "dump_h5md_jdem.h"

using namespace LAMMPS_NS;
using namespace FixConst;

FixJdemObservables::FixJdemObservables(LAMMPS *lmp, int narg, char **arg)
    : Fix(lmp, narg, arg), every(0), dump_index(-1), dump(NULL) {
  if (narg != 5)
    error->all(FLERR, "Illegal fix jdem/observables command: fix ID group jdem/observables M DUMP-ID");
  every = force->inumeric(FLERR, arg[3]);
  if (every <= 0) error->all(FLERR, "fix jdem/observables: M must be a positive number of steps");
  dump_id = arg[4];
}

int FixJdemObservables::setmask() { return END_OF_STEP; }

void FixJdemObservables::init() {
  dump = NULL;
  for (int k = 0; k < output->ndump; k++)
    if (dump_id == output->dump[k]->id) {
      dump = dynamic_cast<DumpH5mdJdem *>(output->dump[k]);
      dump_index = k;
    }
  if (!dump)
    error->all(FLERR, ("fix jdem/observables: no dump h5md/jdem with ID " + dump_id).c_str());
  dump->set_observables_every(every);
}

/* Output::write() follows end_of_step in the same step: a frame due now writes the sample. */
void FixJdemObservables::end_of_step() {
  const bigint step = update->ntimestep;
  if (!dump->observables_due(step) || output->next_dump[dump_index] == step) return;
  dump->write_observable_sample();
}
