/* jdem_script_checks.cpp — see jdem_script_checks.h. */
#include "jdem_script_checks.h"

#include <cstring>
#include <string>

#include "comm.h"
#include "error.h"
#include "fix.h"
#include "fix_property_global.h"
#include "lammps.h"
#include "modify.h"

namespace LAMMPS_NS {

/* Properties that LIGGGHTS' other contact models read (hooke, cohesion sjkr/sjkr2, rolling
 * epsd/epsd2/epsd3, hysteresis, JKR/DMT) and the Jiang (2021) law has no use for. */
static const char *const FOREIGN_PROPERTIES[] = {
    "characteristicVelocity",        "cohesionEnergyDensity",
    "coefficientRollingViscousDamping", "coefficientRollingStiffness",
    "coefficientPlasticityDepth",    "coefficientMaxElasticStiffness",
    "coefficientAdhesionStiffness",  "coefficientUnloadingStiffness",
    "surfaceEnergy",                 "kn", "kt", "gamman", "gammat", "gamman_abs", "gammat_abs"};

static const char *const SHAPES[] = {"scalar", "peratomtype", "peratomtypepair"};

/* The foreign property fix f defines, or NULL. */
static const char *foreign_property(FixPropertyGlobal *f) {
  for (const char *name : FOREIGN_PROPERTIES)
    for (const char *shape : SHAPES)
      if (f->check_fix(name, shape, 0, 0, "gran/jiang", false)) return name;
  return NULL;
}

int jdem_warn_script(LAMMPS *lmp) {
  Modify *modify = lmp->modify;
  int n = 0;
  for (int k = 0; k < modify->nfix; k++) {
    Fix *f = modify->fix[k];
    std::string msg;
    if (std::strncmp(f->style, "wall/gran", 9) == 0) {
      msg = std::string("fix ") + f->id + " (" + f->style + ") evaluates its wall with LIGGGHTS' "
            "own contact model, not the Jiang (2021) law of pair_style gran/jiang: the run mixes "
            "two contact laws; use fix wall/jiang for plane, cylinder and mesh walls (docs/liggghts.md)";
    } else if (FixPropertyGlobal *p = dynamic_cast<FixPropertyGlobal *>(f)) {
      const char *name = foreign_property(p);
      if (name)
        msg = std::string("fix ") + f->id + " (property/global " + name + ") is not used by "
              "pair_style gran/jiang: the Jiang (2021) law has no such parameter, so it has no "
              "effect on the contacts";
    }
    if (msg.empty()) continue;
    if (lmp->comm->me == 0) lmp->error->warning(FLERR, msg.c_str());
    n++;
  }
  return n;
}

}  // namespace LAMMPS_NS
