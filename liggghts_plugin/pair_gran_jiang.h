/* pair_gran_jiang.h — `pair_style gran/jiang`: LIGGGHTS' granular pair machinery (neighbour
 * lists, contact history, MPI migration) around jdem's C contact kernel (kernel/jdem_kernel.h).
 *
 *   pair_style gran/jiang [wall_rule hertz|jiang2021] [damping jiang2021|exact_restitution]
 *                         [tangential_limit coulomb|unconstrained] [mu_r X] [rolling on|off]
 *                         [energy yes|no] [tangential_stiffness jiang2021|mindlin]
 *                         [normal_law hertz|mepa] [mepa_exponent N] [mepa_plastic_depth X]
 *   pair_coeff * *
 *
 * energy no: the contact history keeps no energy accounts (4 doubles per contact instead of 17;
 * MEPA keeps 18 either way, jdem_history.h); then no dump h5md/jdem or fix jdem/watchdog may ask
 * for the energies (their own keyword `energy no` / `energy off`), or init stops with a message
 * naming them.
 *
 * Materials come from fix property/global youngsModulus, poissonsRatio (peratomtype) and
 * coefficientRestitution, coefficientFriction, coefficientRollingFriction (peratomtypepair; the
 * last one only with rolling on), exactly like LIGGGHTS' own models; with normal_law mepa also
 * LoadingStiffness, UnloadingStiffness and CohesiveStiffness (peratomtype, [N/m^n]), Del Cid's
 * (2015) names for MEPA's k1, k2 and kadh, combined per pair in series as her code does.
 * Thin glue only: the
 * geometry is kernel/jdem_geometry.h, the laws kernel/jdem_kernel.h.
 *
 * The style registers itself as "gran" (FixContactHistory and check/timestep/gran look the pair
 * up by that name); restart files name it "gran/jiang" (jdem_restart.h). */
#ifndef JDEM_PAIR_GRAN_JIANG_H
#define JDEM_PAIR_GRAN_JIANG_H

#include <vector>

#include "pair_gran.h"

#include "jdem_dispatch.h"
#include "jdem_history.h"
#include "pair_gran_jiang_lanes.h"
#include "jdem_overlap.h"

namespace LAMMPS_NS {

class PairGranJiang : public PairGran {
 public:
  PairGranJiang(class LAMMPS *);
  virtual ~PairGranJiang() {}

  virtual void settings(int, char **);
  virtual void init_granular();
  /* Restart files (jdem_restart.h): the options in the pair section; init_style defines fix
   * jdem/restart; compute skips the set-up evaluation of a run resuming from a file. */
  virtual void init_style();
  virtual void compute(int eflag, int vflag);
  virtual void write_restart_settings(FILE *fp);
  virtual void read_restart_settings(FILE *fp, const int major, const int minor);
  virtual bool contact_match(const std::string, const std::string) { return false; }
  virtual int64_t hashcode() { return 0x6a6469616e67LL; } /* "jdiang": not a built-in model */
  virtual double stressStrainExponent() { return 1.5; }

  /* Model options (kernel enums) and the feature bits of the force loop. */
  int wall_rule, damping_map, xi_limit, tangential_rule, normal_law;
  double mu_r, mepa_exponent, mepa_plastic_depth;
  bool rolling;
  bool energy_accounts; /* keyword energy: the history has room for the energy bookkeeping */
  bool energy; /* JD_F_ENERGY: set when a dump h5md/jdem or fix jdem/watchdog wants energies */
  unsigned features() const { return features_; }

  /* Per-type data (types 1..ntypes), valid after init. */
  double youngs(int t) const { return E_[t]; }
  double poisson(int t) const { return nu_[t]; }
  /* MEPA's per-type stiffnesses k1 (loading) and k2 (unloading) [N/m^n] (normal_law mepa) */
  double mepa_k1(int t) const { return mepa_k_[0][t]; }
  double mepa_k2(int t) const { return mepa_k_[1][t]; }
  const jd_pair_coeffs &coeffs(int it, int jt) const { return coeffs_[it * (ntypes_ + 1) + jt]; }
  /* coefficientRestitution, ntypes x ntypes, 0-based, row-major (the kernel's tables) */
  const double *restitution_table() const { return &restitution_[0]; }
  /* Per-atom stiffness prefactors [N/m^1.5] of the local and ghost atoms (they depend on the
   * atom's type and radius only): jd_hertz_prefactor for pairs, jd_kn_wall (wall_rule) against
   * a wall.  refresh_prefactors() brings them up to date (the pair loop calls it every step;
   * it recomputes them only after a neighbour build or when the radii vary). */
  void refresh_prefactors();
  const double *pair_prefactors() const { return &kp_[0]; }
  const double *wall_prefactors() const { return &kw_[0]; }
  /* Contact-history layout (jdem_history.h): doubles per contact, and where the rolling part
   * starts; the same for the pair and the wall records. */
  bool mepa() const { return normal_law == JD_NORMAL_MEPA; }
  int state_len() const { return jd_history_len(energy_accounts, rolling, mepa()); }
  int rolling_at() const { return jd_history_contact_len(energy_accounts, mepa()); }

  /* Observables of this rank (pairs with a ghost partner count 1/2, so that the sums over ranks
   * count every pair once): cumulative dissipation [J], and at the last force evaluation the
   * elastic energy [J] and the number of contacts carrying force. */
  double e_damp_cum, e_fric_cum, e_elastic_now, contacts_now;

  /* Set by fix jdem/watchdog: overlaps beyond overlap_limit x the smaller radius are noted in
   * overlap_trip (reset at every force evaluation).  INFINITY (the default): never. */
  double overlap_limit;
  JdOverlapTrip overlap_trip;

 protected:
  virtual void compute_force(int eflag, int vflag, int addflag);
  template <unsigned F> void loop(int eflag, int vflag, int addflag);

 private:
  /* The sums of one force evaluation (this rank's share: pairs with a ghost partner count 1/2). */
  struct LoopSums {
    double e_damp, e_fric, e_el, ncontacts;
    LoopSums() : e_damp(0.0), e_fric(0.0), e_el(0.0), ncontacts(0.0) {}
  };
  template <unsigned F>
  JD_SPECIALISED void plain_loop(unsigned laws, bool commit, bool apply, bool report, LoopSums &sums);
  template <unsigned F> JD_SPECIALISED void lane_loop(LoopSums &sums);
  template <unsigned F> void apply_lanes(JdPairLanes<F> &lanes, LoopSums &sums);
  /* atom i's row of LIGGGHTS' lists: its neighbours, their histories (dnum() doubles each) and
   * touch flags */
  struct NeighbourRow {
    const int *j;
    int n;
    int *touch;
    double *hist;
  };
  NeighbourRow row_of(int i) const;
  void forget_contact(int *touch, double *hist) const;
  /* what the plain loop and apply_lanes do with each evaluated pair */
  void note_overlap(int i, int j, double delta, double Ri, double Rj);
  template <unsigned F> void book_contact(jd_contact_state *st, int j, int carries, LoopSums &sums);
  void add_pair_forces(int i, int j, const double fb[3], const double ta[3], const double tb[3]);

 private:
  void register_history();
  void present_as_gran();
  void update_law_set(bool report);
  void report_pair(int i, int j, bool carries, const jd_contact_result &out, double *hist);
  unsigned features_;
  int ntypes_;
  std::vector<double> E_, nu_;
  std::vector<double> mepa_k_[3]; /* LoadingStiffness, UnloadingStiffness, CohesiveStiffness */
  void read_mepa_stiffnesses();
  /* type-pair tables (ntypes x ntypes, 0-based): restitution, friction, rolling friction */
  std::vector<double> restitution_, friction_, rolling_friction_;
  std::vector<unsigned char> types_in_use_; /* 1 for a type some atom had (update_law_set) */
  std::vector<jd_pair_coeffs> coeffs_;

  std::vector<double> kp_, kw_;
  bigint kp_ncalls_;
  int kp_nall_;
  bool script_checked_; /* jdem_warn_script has run (at the first set-up) */
};

}  // namespace LAMMPS_NS

#endif
