/* fix_jdem_domain.h — `fix ID all jdem/domain lo XLO YLO ZLO hi XHI YHI ZHI gravity GX GY GZ`:
 * the scene's domain (docs/scenes.md "Domain", kernel/jdem_domain.h) in LIGGGHTS.
 *
 * At every reneighbouring step (pre_exchange, where build/jdem deletes at its neighbour builds)
 * the atoms whose centre is outside [lo, hi) are deleted, as LAMMPS' Comm::exchange drops an
 * atom that left a `boundary f f f` box, but here with the energy they take booked (the
 * observable lost_energy, jd_lost_energy: their v and omega completed from the half step with
 * the force and torque they last carried, as build/jdem does) and their bonds removed (fix
 * bond/jiang).  The deck generator gives the box the domain's bounds, so LIGGGHTS itself never
 * loses an atom, and `thermo_modify lost error` (the default) still guards everything else.
 * Define it after the inlets (fix jdem/inlet), as build/jdem inserts before it deletes.
 * Restart files (jdem_restart.h) carry the counts. */
#ifndef JDEM_FIX_JDEM_DOMAIN_H
#define JDEM_FIX_JDEM_DOMAIN_H

#include <vector>

#include "fix.h"

namespace LAMMPS_NS {

class FixJdemDomain : public Fix {
 public:
  FixJdemDomain(class LAMMPS *, int, char **);
  int setmask();
  void init();
  void pre_exchange();
  void write_restart(FILE *);
  void restart(char *);

  /* the atoms deleted so far [-] and the energy they took [J], the same on every rank */
  double lost_particles() const { return lost; }
  double lost_energy() const { return energy; }
  /* the ids of the atoms deleted so far (every rank; rank 0's survive a restart) */
  const std::vector<int> &gone_ids() const { return gone_all; }

 private:
  double lo[3], hi[3], g[3];
  double lost, energy;
  std::vector<int> gone_all;
  std::vector<class FixBondJiang *> bonds; /* set by init() */
};

}  // namespace LAMMPS_NS

#endif
