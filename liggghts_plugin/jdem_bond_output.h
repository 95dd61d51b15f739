/* jdem_bond_output.h — what dump h5md/jdem writes about bonds (docs/scenes.md "Bonds"): the
 * bonds formed and broken since the previous frame of every fix bond/jiang, gathered on rank 0
 * and appended to /jdem/bonds, /jdem/broken_bonds (and their tuple lists in /connectivity)
 * through io/h5md.h, and the observables bonds and fragments.
 *
 * The bonds are ordered by step, rule (explicit bonds first), ids; broken_bonds by step,
 * ids.  fragments counts the connected components of the intact-bond graph over the particles
 * that were ever bonded (1 for an intact aggregate). */
#ifndef JDEM_BOND_OUTPUT_H
#define JDEM_BOND_OUTPUT_H

#include <mpi.h>

#include <cstddef>
#include <vector>

struct jd_h5md;

namespace LAMMPS_NS {
class LAMMPS;

/* Rows of ncol doubles from every rank, concatenated in rank order on rank 0 (collective;
 * empty elsewhere). */
std::vector<double> jdem_gather_rows(MPI_Comm world, const std::vector<double> &mine);

class JdemBondOutput {
 public:
  /* Collective.  Collects the bond records of every fix bond/jiang (none: nothing to do) and,
   * on rank 0, appends them to h and sets the intact-bond count and the fragments.  Returns 0,
   * or -1 with a reason in err (rank 0). */
  int write(LAMMPS *lmp, jd_h5md *h, char *err, size_t errlen);
  /* Collective.  Sets the intact-bond count and the fragments (rank 0) for an observable sample
   * between frames; the records stay with the fixes for the next write(). */
  void count(LAMMPS *lmp);
  bool active() const { return active_; }
  double bonds() const { return bonds_; }
  double fragments() const { return fragments_; }
  /* The ids of the particles ever bonded, as far as this output has seen (rank 0). */
  std::vector<int> ever_bonded_ids() const;

 private:
  /* Marks the atoms of both lists of (lower id, higher id) pairs as ever bonded (and those fix
   * jdem/domain deleted as no longer), then counts the intact bonds and the fragments over the
   * concatenated (lower id, higher id) pairs (rank 0). */
  void count_intact(LAMMPS *lmp, const std::vector<double> &formed_pairs,
                    const std::vector<double> &intact);
  /* Marks the particles a restart file lists as ever bonded (FixBondJiang, rank 0). */
  void mark_restored(LAMMPS *lmp);
  bool active_ = false;
  double bonds_ = 0.0, fragments_ = 0.0;
  std::vector<char> ever_bonded_; /* by particle id (rank 0) */
};

}  // namespace LAMMPS_NS

#endif
