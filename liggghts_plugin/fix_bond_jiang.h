/* fix_bond_jiang.h — `fix bond/jiang`: Potyondy–Cundall parallel bonds (kernel/jdem_bond.h) in
 * LIGGGHTS, acting in parallel with pair_style gran/jiang's contacts.
 *
 *   fix ID group bond/jiang kn KN kt KT sigma_c S tau_c T lambda L [damping GAMMA]
 *                           [bending I|J_literal] [max_bonds N] [file FILE]
 *                           [rule K step S group GROUP max_gap X] ...
 *
 * One fix is one bond type of the scene (docs/scenes.md "Bonds"); the n-th fix bond/jiang of
 * the input is bond type n - 1 in the trajectory's /connectivity/bond_type.
 *   kn, kt     normal and shear stiffness per unit area                     [N/m^3]
 *   sigma_c    tensile strength, tau_c shear strength (inf: never)          [Pa]
 *   lambda     bond-radius multiplier: R_bond = lambda min(R_a, R_b)        [-]
 *   damping    damping ratio of the bond's dashpots (default 0: none)       [-]
 *   bending    second moment of the bending stiffness (default I; docs/model.md)
 *   max_bonds  bonds one atom can store (default 12, the FCC coordination)
 *   file FILE  explicit bonds: lines "ID_A ID_B" ('#' starts a comment), formed at the first
 *              set-up with zero force, wherever the two atoms are
 *   rule       at step S (before the step's bond forces), bond every pair of atoms of GROUP not
 *              yet bonded (by any fix bond/jiang) with |x_b - x_a| - R_a - R_b <= X min(R_a, R_b);
 *              K orders the rules of all bond fixes in /connectivity (the scene's rule index).
 *              The candidates come from the pair style's neighbour list: X max(R) must not
 *              exceed the neighbour skin.
 *
 * Bookkeeping (docs/liggghts.md, "Bonds"):
 *   - a bond is stored once, on the atom with the lower id, as the partner's id and the kernel
 *     state; it moves with that atom between ranks (pack/unpack_exchange) and does not depend on
 *     neighbour lists, so it survives rebuilds and any stretch;
 *   - the rank owning the lower-id atom evaluates it; it finds the partner through atom->map, a
 *     ghost when the partner lives on another rank, and sends the partner's force and torque back
 *     with a reverse communication (LIGGGHTS runs granular pairs with newton off: no other
 *     reverse communication of forces takes place);
 *   - a partner must be within the ghost cutoff at every neighbour rebuild (then it stays a ghost
 *     until the next one): a longer bond stops the run on every rank with a message that names
 *     it (`communicate single vel yes cutoff X` raises the cutoff);
 *   - a bond that fails is removed on the spot and recorded as an event (dump h5md/jdem writes
 *     them); the pair then interacts through gran/jiang alone.
 * Restart files (jdem_restart.h) carry the bonds, their states and the counts: a fix of the same
 * ID continues from them (the bond file is not read again, the rules already applied not again).
 * Thermo: f_ID is the number of intact bonds, f_ID[1], f_ID[2], f_ID[3] the intact bonds and the
 * bonds broken in tension and in shear so far. */
#ifndef JDEM_FIX_BOND_JIANG_H
#define JDEM_FIX_BOND_JIANG_H

#include <string>
#include <vector>

#include "fix.h"

#include "jdem_bond.h"

namespace LAMMPS_NS {

class FixBondJiang : public Fix {
 public:
  FixBondJiang(class LAMMPS *, int, char **);
  ~FixBondJiang();
  int setmask();
  void init();
  void setup(int);
  void setup_pre_neighbor();
  void pre_neighbor();
  void post_force(int);

  void grow_arrays(int);
  void copy_arrays(int, int, int);
  void set_arrays(int);
  int pack_exchange(int, double *);
  int unpack_exchange(int, double *);
  int pack_reverse_comm(int, int, double *);
  void unpack_reverse_comm(int, int *, double *);
  double memory_usage();
  /* restart files (jdem_restart.h); the ids of the particles ever bonded before the file was
   * written (rank 0), for dump h5md/jdem's fragments */
  const std::vector<int> &restored_ever_bonded() const { return ever_bonded_read; }
  void write_restart(FILE *);
  void restart(char *);
  int pack_restart(int, double *);
  void unpack_restart(int, int);
  int size_restart(int);
  int maxsize_restart();
  /* thermo output: f_ID = intact bonds, f_ID[1..3] = intact, broken in tension, in shear */
  double compute_scalar();
  double compute_vector(int);

  /* One broken bond. */
  struct Event {
    bigint step;
    double time;      /* [s] */
    int tag_a, tag_b; /* tag_a < tag_b */
    int mode;         /* jd_bond_mode */
    double x[3];      /* the bond's point x_C [m] */
    double n[3];      /* unit vector a -> b */
    jd_bond_result r; /* forces, moments and stresses that broke it */
  };
  /* A bond formed: rule -1 for the explicit ones (docs/scenes.md orders /connectivity/bonds
   * by step, rule, ids). */
  struct Formed {
    bigint step;
    int rule;
    int tag_a, tag_b; /* tag_a < tag_b */
  };
  /* This rank's records since the last call; dump h5md/jdem collects them. */
  std::vector<Event> take_events();
  std::vector<Formed> take_formed();
  /* The records take_formed() would return now, left in place (an observable sample between
   * frames marks their atoms as ever bonded). */
  const std::vector<Formed> &pending_formed() const { return formed; }
  /* True when local atom i (the lower id) holds an intact bond with the atom of id tag_b. */
  bool bonded(int i, int tag_b) const;

  /* For the time-step guard (kernel/jdem_guard.h, bond_omega2): the largest over the atoms of
   * the sum of jd_bond_omega2_bound over the atom's bonds, plus for each rule that may bond it
   * 12 bonds with its own kind (as build/jdem estimates it) [rad^2/s^2].  Collective; valid
   * after this fix's set-up (explicit bonds are read then). */
  double omega2_max();

  /* Form a bond, unstressed, between local atom i and the atom of id partner_tag > tag[i] (it
   * need not be present on this rank yet): fix jdem/inlet's bonded blocks, at their insertion
   * step, recorded as an explicit bond (rule -1).  Stops the run past max_bonds. */
  void form_inlet_bond(int i, int partner_tag);
  /* The bond type's parameters (fix jdem/guard bounds the inlets' future bonds with them). */
  const jd_bond_params &bond_params() const { return params; }

  /* fix jdem/domain deletes the atoms that left the box (kernel/jdem_domain.h): the elastic
   * energy [J] of the bonds local atom i holds, which go with it; then, once every rank has
   * deleted its atoms, the bonds whose partner id is in `gone` (sorted) are removed, and the
   * elastic energy they held is returned.  Their dashpots were harvested at their last step. */
  double held_elastic(int i);
  double drop_partners(const std::vector<int> &gone);

  /* This rank's intact bonds as (lower id, higher id) pairs. */
  void local_bonds(std::vector<int> &pairs) const;
  int local_count() const;

  /* Observables of this rank: elastic energy stored in the bonds at the last force evaluation,
   * and the cumulative energy dissipated by bond damping and released by broken bonds [J]. */
  double e_elastic_now, e_damp_cum, e_broken_cum;

 private:
  void compute(bool commit);
  void check_reach();
  template <unsigned F> void loop(bool commit);
  void read_bond_file(const char *path);
  struct Rule {
    int index;
    bigint step;
    int groupbit;
    double max_gap;
  };
  void form_by_rule(const Rule &r);
  void form_due();
  bool bonded_anywhere(int i, int tag_b) const;
  bool add_bond(int i, int j, int rule);
  bool add_bond_to(int i, int partner_tag, int rule);
  /* A bond's record: its kernel state.  The cross-section is computed where it is needed
   * (jd_bond_section_of, as the stepper does for mixed radii): every atom keeps max_bonds
   * records, so 7 doubles fewer per record is 28 % less bond memory, at the same speed. */
  enum { REC_LEN = JD_BOND_STATE_LEN };
  double *state(int i, int k) { return &bstate[i][k * REC_LEN]; }

  jd_bond_params params;
  unsigned features; /* JD_B_* of the run */
  int max_bonds;
  std::string bond_file;
  std::vector<Rule> rules;
  bool file_read;
  bigint rules_done_at; /* the step whose rules were applied last */
  bool record; /* keep formed/broken records: a dump h5md/jdem collects them */

  int nmax_b;
  int *nbond;     /* bonds stored on each atom */
  int **partner;  /* their partners' ids */
  double **bstate; /* their records, REC_LEN doubles each */
  int nmax_ghost;
  double **fghost; /* force and torque on ghost partners, sent home by reverse communication */
  int reverse_len;  /* doubles per atom of the next reverse communication: 6, or 1 (omega2) */
  std::vector<double> w2;  /* omega2_max's per-atom sums (local and ghost) */
  std::vector<Event> events;
  std::vector<Formed> formed;
  double nbroken[2]; /* this rank's bonds broken in tension, in shear (cumulative) */
  std::vector<int> ever_bonded_read; /* restored_ever_bonded() */
};

}  // namespace LAMMPS_NS

#endif
