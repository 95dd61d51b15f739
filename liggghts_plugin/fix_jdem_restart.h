/* fix_jdem_restart.h — `fix jdem_restart all jdem/restart`: what a restart file of a run with
 * pair_style gran/jiang carries besides LIGGGHTS' own data and our other fixes' states
 * (jdem_restart.h), defined by pair_style gran/jiang itself at its first set-up: the user does
 * not write it.
 *
 *  - per atom: the force and torque after the step the file was written at.  A run that
 *    continues from the file sets them at the end of its set-up, after every fix's set-up (this
 *    fix is defined after the script's fixes), so that the first half kick of the next step is
 *    the uninterrupted run's;
 *  - global: the pair style's options (checked against a later pair_style line,
 *    jdem_restart_check_pair_style), the clock (update->atime and atimestep, which LIGGGHTS'
 *    file does not keep; restored when the file is read) and each rank's contact observables of the pair style
 *    (cumulative damping and friction dissipation, elastic energy and contacts at the last
 *    force evaluation).
 * resuming(): from the creation with a file's data until the end of the next set-up; the set-up
 * evaluations of our styles keep the state that was read then (jdem_restart_resuming). */
#ifndef JDEM_FIX_JDEM_RESTART_H
#define JDEM_FIX_JDEM_RESTART_H

#include <string>

#include "fix.h"
#include "jdem_restart.h"

namespace LAMMPS_NS {

class FixJdemRestart : public Fix {
 public:
  FixJdemRestart(class LAMMPS *, int, char **);
  ~FixJdemRestart();
  int setmask() { return 0; }
  void setup(int);
  bool resuming() const { return resuming_; }

  void write_restart(FILE *);
  void restart(char *);
  int pack_restart(int, double *);
  void unpack_restart(int, int);
  int size_restart(int) { return 1 + SAVED; }
  int maxsize_restart() { return 1 + SAVED; }

  void grow_arrays(int);
  void copy_arrays(int, int, int);
  int pack_exchange(int, double *);
  int unpack_exchange(int, double *);
  double memory_usage();

  /* The options of pair_style gran/jiang stored in a global state of this fix, as the
   * pair_style keywords (for messages). */
  static std::string describe_pair_options(class LAMMPS *lmp, const char *state);

  /* Defines the fix once (pair_style gran/jiang's init_style). */
  static void define(class LAMMPS *lmp);

 private:
  enum { SAVED = 6 };                 /* force [N] and torque [N m] */
  /* the global state: the pair style's options, the clock (2), then MEPA's options (normal_law,
   * mepa_exponent, mepa_plastic_depth), which files written before MEPA lack; the sums */
  enum { NPAIR = 7, NMEPA = 3 };
  enum { NSHARED_BEFORE_MEPA = NPAIR + 2, NSHARED = NPAIR + 2 + NMEPA, NSUMS = 4 };
  static JdemRestartState read_state(class LAMMPS *lmp, const char *buf);
  bool resuming_;
  double **saved;
  int nmax_saved;
};

}  // namespace LAMMPS_NS

#endif
