/* jdem_observables.h — this rank's part of the /observables of docs/scenes.md, from the atoms,
 * fix gravity, pair_style gran/jiang and every fix wall/jiang: summed over ranks they are the
 * totals.  One computation for the two users, dump h5md/jdem (which writes them) and fix
 * jdem/watchdog (which checks the energy balance with kernel/jdem_watchdog.h). */
#ifndef JDEM_OBSERVABLES_H
#define JDEM_OBSERVABLES_H

namespace LAMMPS_NS {
class LAMMPS;

/* Indices into the array filled by jdem_local_observables(). */
enum { JDO_KINETIC = 0, JDO_ROTATIONAL, JDO_GRAVITATIONAL, JDO_ELASTIC, JDO_DAMPING,
       JDO_FRICTION, JDO_WALL_WORK, JDO_CONTACTS, JDO_WALL_CONTACTS, JDO_BOND_ELASTIC,
       JDO_BOND_DAMPING, JDO_BOND_BREAKAGE, JDO_N };

/* Sums over this rank's atoms of `groupbit` and its contacts (pairs with a ghost partner count
 * 1/2, see PairGranJiang) and bonds (each stored on one rank, see FixBondJiang).  The contact
 * terms stay 0 without pair_style gran/jiang, the bond terms without fix bond/jiang. */
void jdem_local_observables(LAMMPS *lmp, int groupbit, double out[JDO_N]);

/* True when some consumer of the energies is defined (a dump h5md/jdem, which writes them, or a
 * fix jdem/watchdog, which checks their balance): the force loops then book them. */
bool jdem_wants_energy(LAMMPS *lmp);

}  // namespace LAMMPS_NS

#endif
