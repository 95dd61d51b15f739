/* jdem_observables.h — this rank's part of the /observables of docs/scenes.md, from the atoms,
 * fix gravity, pair_style gran/jiang and every fix wall/jiang: summed over ranks they are the
 * totals.  One computation for the two users, dump h5md/jdem (which writes them) and fix
 * jdem/watchdog (which checks the energy balance with kernel/jdem_watchdog.h). */
#ifndef JDEM_OBSERVABLES_H
#define JDEM_OBSERVABLES_H

#include <string>
#include <vector>

#include "jdem_observable_names.h"

namespace LAMMPS_NS {
class LAMMPS;

/* Indices into the array filled by jdem_local_observables(): the contact observables in the
 * kernel's order (jd_observable_names), then the bond energies. */
enum { JDO_KINETIC = JD_OBS_KINETIC, JDO_ROTATIONAL = JD_OBS_ROTATIONAL,
       JDO_GRAVITATIONAL = JD_OBS_GRAVITATIONAL, JDO_ELASTIC = JD_OBS_ELASTIC,
       JDO_DAMPING = JD_OBS_DAMPING, JDO_FRICTION = JD_OBS_FRICTION,
       JDO_WALL_WORK = JD_OBS_WALL_WORK, JDO_CONTACTS = JD_OBS_CONTACTS,
       JDO_WALL_CONTACTS = JD_OBS_WALL_CONTACTS, JDO_BOND_ELASTIC = JD_N_OBSERVABLES,
       JDO_BOND_DAMPING, JDO_BOND_BREAKAGE, JDO_N };

/* Sums over this rank's atoms of `groupbit` and its contacts (pairs with a ghost partner count
 * 1/2, see PairGranJiang) and bonds (each stored on one rank, see FixBondJiang).  The contact
 * terms stay 0 without pair_style gran/jiang, the bond terms without fix bond/jiang. */
void jdem_local_observables(LAMMPS *lmp, int groupbit, double out[JDO_N]);

/* The acceleration of every fix gravity, summed [m/s^2] (the weight m g of an atom of mass m). */
void jdem_gravity(LAMMPS *lmp, double g[3]);

/* The wall observables of docs/scenes.md "Servo walls" (names of jdem_observable_names.h): for
 * every fix wall/jiang with a name, in fix order, its force and, for a servo wall, its stress
 * and position; then, if any wall has a name, the stress tensor of their contacts
 * (jd_stress_tensor per rank, summed over the ranks) in the box of every plane wall's current
 * corners (jd_servo_box).  Collective; the values are complete on rank 0. */
void jdem_wall_observables(LAMMPS *lmp, std::vector<std::string> &names,
                           std::vector<double> &values);

/* True when some consumer of the bond energies is defined (a dump h5md/jdem without `energy
 * no`, which writes them,
 * or a fix jdem/watchdog that checks the energy balance): fix bond/jiang then books them. */
bool jdem_wants_energy(LAMMPS *lmp);

/* The first consumer of the contact energies (a dump h5md/jdem without `energy no`, a fix
 * jdem/watchdog without `energy off`), described for an error message with the option that
 * turns it off, e.g. "dump d (h5md/jdem) writes the energy observables: add 'energy no' to
 * the dump"; empty when there is none.  pair_style gran/jiang books the energies only then. */
std::string jdem_contact_energy_user(LAMMPS *lmp);

}  // namespace LAMMPS_NS

#endif
