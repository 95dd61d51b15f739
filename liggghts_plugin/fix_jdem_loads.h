/* fix_jdem_loads.h — `fix ID group jdem/loads file FILE`: held particles and constant external
 * forces, the scene's particles[].fixed and particles[].force (docs/scenes.md), as build/jdem
 * applies them (stepper/loads.c): after every other force, the external force is added, then a
 * held particle's force and torque are set to zero, so that it keeps its velocity and spin.
 *
 * FILE: one line per loaded atom, "ID FX FY FZ HELD" (force [N]; HELD 1 or 0; '#' comments).
 * Define it after every other force fix (walls, bonds, gravity) and before the integrator.
 *
 * The work these loads do on the particles (the external force, and the constraint's reaction
 * -f, -torque on a held particle) is booked into the observable wall_work with the trapezoidal
 * rule of the walls (jd_wall_work), so that the energy balance closes.  Per-atom data (the load
 * and the previous step's applied force and torque) migrates with the atom. */
#ifndef JDEM_FIX_JDEM_LOADS_H
#define JDEM_FIX_JDEM_LOADS_H

#include <string>

#include "fix.h"

namespace LAMMPS_NS {

class FixJdemLoads : public Fix {
 public:
  FixJdemLoads(class LAMMPS *, int, char **);
  ~FixJdemLoads();
  int setmask();
  void setup(int);
  void post_force(int);

  void grow_arrays(int);
  void copy_arrays(int, int, int);
  void set_arrays(int);
  int pack_exchange(int, double *);
  int unpack_exchange(int, double *);
  double memory_usage();
  /* restart files (jdem_restart.h) */
  void write_restart(FILE *);
  void restart(char *);
  int pack_restart(int, double *);
  void unpack_restart(int, int);
  int size_restart(int) { return L_N + 1; }
  int maxsize_restart() { return L_N + 1; }

  /* work done on this rank's atoms since the start [J] (an observable: wall_work) */
  double work_cum;

 private:
  void apply(bool commit);
  void read_file(const char *path);

  enum { L_FX = 0, L_HELD = 3, L_PREV = 4, L_N = 10 }; /* per atom: force, held, applied x 6 */
  std::string path; /* the file, until the first set-up reads it */
  double **load;
  int nmax_l;
};

}  // namespace LAMMPS_NS

#endif
