/* jdem_script_checks.h — what a hand-written LIGGGHTS script with pair_style gran/jiang would
 * otherwise do silently: stock wall/gran fixes next to our pair (two contact laws in one run),
 * and material properties of other LIGGGHTS contact models, which our law never reads. */
#ifndef JDEM_SCRIPT_CHECKS_H
#define JDEM_SCRIPT_CHECKS_H

namespace LAMMPS_NS {
class LAMMPS;

/* Collective in effect (every rank decides the same).  One warning (rank 0, screen and log) per stock fix wall/gran*, and one per fix property/global
 * that defines a property of another contact model (the list in the .cpp).  Returns the number
 * of warnings. */
int jdem_warn_script(LAMMPS *lmp);

}  // namespace LAMMPS_NS

#endif
