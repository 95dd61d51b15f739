/* pair_gran_jiang.cpp — see pair_gran_jiang.h.  Glue only: neighbour/history bookkeeping of
 * LIGGGHTS around jd_geom_spheres() and jd_contact(). */
#include "pair_gran_jiang.h"

#include <cmath>
#include <cstddef>
#include <cstdio>
#include <cstring>
#include <string>

#include "atom.h"
#include "compute_pair_gran_local.h"
#include "comm.h"
#include "error.h"
#include "fix.h"
#include "fix_property_global.h"
#include "force.h"
#include "modify.h"
#include "neigh_list.h"
#include "neighbor.h"
#include "update.h"

#include "fix_jdem_inlet.h"
#include "fix_wall_jiang.h"
#include "jdem_dispatch.h"
#include "pair_gran_jiang_lanes.h"
#include "jdem_laws.h"
#include "jdem_history.h"
#include "jdem_observables.h"
#include "jdem_restart.h"
#include "fix_jdem_restart.h"
#include "jdem_script_checks.h"
#include "jdem_geometry.h"
#include "jdem_watchdog.h"

using namespace LAMMPS_NS;

PairGranJiang::PairGranJiang(LAMMPS *lmp)
    : PairGran(lmp), wall_rule(JD_WALL_HERTZ), damping_map(JD_DAMP_JIANG2021),
      xi_limit(JD_XI_COULOMB), tangential_rule(JD_KT_JIANG2021), normal_law(JD_NORMAL_HERTZ),
      mu_r(1.0), mepa_exponent(JD_MEPA_DEFAULT_EXPONENT),
      mepa_plastic_depth(JD_MEPA_DEFAULT_DEPTH), rolling(false), energy_accounts(true), energy(false),
      e_damp_cum(0.0), e_fric_cum(0.0), e_elastic_now(0.0), contacts_now(0.0), overlap_limit(INFINITY),
      features_(0), ntypes_(0), kp_ncalls_(-1), kp_nall_(-1), script_checked_(false) {}

/* ---------------------------------------------------------------------------------------- */

void PairGranJiang::settings(int narg, char **arg) {
  std::string mepa_option; /* a MEPA option given, which needs normal_law mepa */
  for (int i = 0; i < narg; i += 2) {
    if (i + 1 >= narg) error->all(FLERR, "pair_style gran/jiang: option without a value");
    const std::string k = arg[i], val = arg[i + 1];
    if (k == "wall_rule") {
      if (val == "hertz") wall_rule = JD_WALL_HERTZ;
      else if (val == "jiang2021") wall_rule = JD_WALL_JIANG2021;
      else error->all(FLERR, ("pair_style gran/jiang: wall_rule must be hertz or jiang2021, not '" + val +
                              "'").c_str());
    } else if (k == "damping") {
      if (val == "jiang2021") damping_map = JD_DAMP_JIANG2021;
      else if (val == "exact_restitution") damping_map = JD_DAMP_EXACT;
      else error->all(FLERR, "pair_style gran/jiang: damping must be jiang2021 or exact_restitution");
    } else if (k == "tangential_limit") {
      if (val == "coulomb") xi_limit = JD_XI_COULOMB;
      else if (val == "unconstrained") xi_limit = JD_XI_UNCONSTRAINED;
      else error->all(FLERR, "pair_style gran/jiang: tangential_limit must be coulomb or unconstrained");
    } else if (k == "tangential_stiffness") {
      if (val == "jiang2021") tangential_rule = JD_KT_JIANG2021;
      else if (val == "mindlin") tangential_rule = JD_KT_MINDLIN;
      else error->all(FLERR, ("pair_style gran/jiang: tangential_stiffness must be jiang2021 or mindlin, not '" +
                              val + "'").c_str());
    } else if (k == "normal_law") {
      if (val == "hertz") normal_law = JD_NORMAL_HERTZ;
      else if (val == "mepa") normal_law = JD_NORMAL_MEPA;
      else error->all(FLERR, ("pair_style gran/jiang: normal_law must be hertz or mepa, not '" + val +
                              "'").c_str());
    } else if (k == "mepa_exponent" || k == "mepa_plastic_depth") {
      const double x = force->numeric(FLERR, arg[i + 1]);
      if (!(x > 0.0)) error->all(FLERR, ("pair_style gran/jiang: " + k + " must be > 0").c_str());
      (k == "mepa_exponent" ? mepa_exponent : mepa_plastic_depth) = x;
      mepa_option = k;
    } else if (k == "mu_r") {
      mu_r = force->numeric(FLERR, arg[i + 1]);
      if (!(mu_r >= 0.0 && mu_r <= 1.0)) error->all(FLERR, "pair_style gran/jiang: mu_r must be in [0, 1]");
    } else if (k == "rolling") {
      if (val == "on") rolling = true;
      else if (val == "off") rolling = false;
      else error->all(FLERR, "pair_style gran/jiang: rolling must be on or off");
    } else if (k == "energy") {
      if (val == "yes") energy_accounts = true;
      else if (val == "no") energy_accounts = false;
      else error->all(FLERR, "pair_style gran/jiang: energy must be yes or no");
    } else {
      error->all(FLERR, ("pair_style gran/jiang: unknown option '" + k +
                         "' (valid: wall_rule, damping, tangential_limit, mu_r, rolling, energy, "
                         "tangential_stiffness, normal_law, mepa_exponent, mepa_plastic_depth)").c_str());
    }
  }

  if (!mepa_option.empty() && !mepa())
    error->all(FLERR, ("pair_style gran/jiang: " + mepa_option + " is MEPA's option; valid: "
                       "normal_law mepa with it, or no " + mepa_option).c_str());
  register_history();
  jdem_restart_check_pair_style(lmp, "gran/jiang", state_len());
  present_as_gran();
}

/* Per-contact history (jdem_history.h): jd_contact_state, then jd_rolling_state when rolling is
 * on, or only their law fields without energy accounts, with the kernel's sign-flip flags.
 * (settings() may run again for a repeated pair_style line.) */
void PairGranJiang::register_history() {
  history_arg.clear();
  dnum_pairgran = 0;
  char name[32];
  for (int k = 0; k < state_len(); k++) {
    std::snprintf(name, sizeof name, k < rolling_at() ? "jd_state_%d" : "jd_rolling_%d",
                  k < rolling_at() ? k : k - rolling_at());
    add_history_value(name, jd_history_newton(energy_accounts, mepa(), k) ? "1" : "0");
  }
}

/* FixContactHistory and check/timestep/gran find the pair by the exact name "gran". */
void PairGranJiang::present_as_gran() {
  if (force->pair == this && std::strcmp(force->pair_style, "gran") != 0) {
    delete[] force->pair_style;
    force->pair_style = new char[5];
    std::strcpy(force->pair_style, "gran");
  }
}

/* ---------------------------------------------------------------------------------------- */

void PairGranJiang::init_granular() {
  const int nt = atom->ntypes;
  ntypes_ = nt;
  const char *me = "gran/jiang";
  FixPropertyGlobal *fE = static_cast<FixPropertyGlobal *>(
      modify->find_fix_property("youngsModulus", "property/global", "peratomtype", nt, 0, me));
  FixPropertyGlobal *fnu = static_cast<FixPropertyGlobal *>(
      modify->find_fix_property("poissonsRatio", "property/global", "peratomtype", nt, 0, me));
  FixPropertyGlobal *fe = static_cast<FixPropertyGlobal *>(modify->find_fix_property(
      "coefficientRestitution", "property/global", "peratomtypepair", nt, nt, me));
  FixPropertyGlobal *fmu = static_cast<FixPropertyGlobal *>(modify->find_fix_property(
      "coefficientFriction", "property/global", "peratomtypepair", nt, nt, me));
  /* read whether or not the rolling keyword is on: the law set depends on the coefficients,
   * as in the stepper (update_law_set) */
  FixPropertyGlobal *feta = static_cast<FixPropertyGlobal *>(modify->find_fix_property(
      "coefficientRollingFriction", "property/global", "peratomtypepair", nt, nt, me, false));

  kp_ncalls_ = -1; /* the materials may have changed: recompute the prefactors */
  E_.assign(nt + 1, 0.0);
  nu_.assign(nt + 1, 0.0);
  for (int i = 1; i <= nt; i++) {
    E_[i] = fE->compute_vector(i - 1);
    nu_[i] = fnu->compute_vector(i - 1);
    if (!(E_[i] > 0.0) || !(nu_[i] > -1.0 && nu_[i] <= 0.5))
      error->all(FLERR, "gran/jiang: youngsModulus must be > 0 and poissonsRatio in (-1, 0.5]");
  }
  /* the type-pair tables, 0-based and row-major as the kernel's rulebook reads them */
  restitution_.assign(nt * nt, 0.0);
  friction_.assign(nt * nt, 0.0);
  rolling_friction_.assign(nt * nt, 0.0);
  for (int i = 0; i < nt; i++)
    for (int j = 0; j < nt; j++) {
      const int k = i * nt + j;
      restitution_[k] = fe->compute_array(i, j);
      friction_[k] = fmu->compute_array(i, j);
      rolling_friction_[k] = feta ? feta->compute_array(i, j) : 0.0;
      if (!(restitution_[k] > 0.0 && restitution_[k] <= 1.0))
        error->all(FLERR, "gran/jiang: coefficientRestitution must be in (0, 1]");
      if (friction_[k] < 0.0 || rolling_friction_[k] < 0.0)
        error->all(FLERR, "gran/jiang: friction coefficients must be >= 0");
    }
  read_mepa_stiffnesses();
  const jd_mepa_inputs mepa_in = {mepa() ? &mepa_k_[0][1] : NULL, mepa() ? &mepa_k_[1][1] : NULL,
                                  mepa() ? &mepa_k_[2][1] : NULL, mepa_exponent,
                                  mepa_plastic_depth};
  std::vector<jd_pair_coeffs> table(nt * nt);
  jd_pair_coeffs_table(nt, &restitution_[0], &friction_[0], &rolling_friction_[0], &E_[1],
                       &nu_[1], damping_map, mu_r, xi_limit, mepa() ? &mepa_in : NULL, &table[0]);
  coeffs_.assign((nt + 1) * (nt + 1), jd_pair_coeffs());
  for (int i = 1; i <= nt; i++)
    for (int j = 1; j <= nt; j++) coeffs_[i * (nt + 1) + j] = table[(i - 1) * nt + (j - 1)];

  /* Energies only when a dump h5md/jdem records the observables or fix jdem/watchdog checks
   * their balance; without energy accounts in the history neither may ask for them. */
  const std::string user = jdem_contact_energy_user(lmp);
  if (!energy_accounts && !user.empty())
    error->all(FLERR, ("pair_style gran/jiang energy no keeps no energy accounts, but " + user +
                       ", or use pair_style gran/jiang energy yes").c_str());
  energy = !user.empty();

  types_in_use_.assign(nt, 0);
  update_law_set(true);
  if (!script_checked_) jdem_warn_script(lmp); /* at the first run's set-up only */
  script_checked_ = true;
}

/* MEPA's per-type stiffnesses (normal_law mepa): LoadingStiffness and UnloadingStiffness
 * required, k2 > k1 > 0; CohesiveStiffness optional (0).  Without MEPA, giving them is an error
 * (a script that means MEPA but forgot the keyword). */
void PairGranJiang::read_mepa_stiffnesses() {
  const int nt = atom->ntypes;
  static const char *const names[3] = {"LoadingStiffness", "UnloadingStiffness",
                                       "CohesiveStiffness"};
  for (int q = 0; q < 3; q++) {
    mepa_k_[q].assign(nt + 1, 0.0);
    FixPropertyGlobal *f = static_cast<FixPropertyGlobal *>(modify->find_fix_property(
        names[q], "property/global", "peratomtype", nt, 0, "gran/jiang", mepa() && q < 2));
    if (f && !mepa())
      error->all(FLERR, (std::string("gran/jiang: fix property/global ") + names[q] +
                         " is MEPA's, but pair_style gran/jiang has no 'normal_law mepa'").c_str());
    for (int t = 1; f && t <= nt; t++) mepa_k_[q][t] = f->compute_vector(t - 1);
  }
  for (int t = 1; mepa() && t <= nt; t++)
    if (!jd_mepa_material_valid(mepa_k_[0][t], mepa_k_[1][t], mepa_k_[2][t])) {
      char msg[256];
      std::snprintf(msg, sizeof msg, "gran/jiang: type %d has LoadingStiffness %g, "
                    "UnloadingStiffness %g, CohesiveStiffness %g; valid: UnloadingStiffness > "
                    "LoadingStiffness > 0, CohesiveStiffness >= 0", t, mepa_k_[0][t],
                    mepa_k_[1][t], mepa_k_[2][t]);
      error->all(FLERR, msg);
    }
}

/* The law set of the interactions that can occur (jd_law_set_select, the stepper's rule): the
 * types of the atoms present on any rank and of the inlets' sections (fix jdem/inlet) against
 * those types and the walls' (fix wall/jiang).
 * At set-up, and again after every neighbour build, when atoms of another type may have been
 * inserted: the set then widens (collective: every rank builds its lists at the same step). */
void PairGranJiang::update_law_set(bool report) {
  const int nt = ntypes_;
  std::vector<int> mine(nt, 0), all(nt, 0);
  for (int i = 0; i < atom->nlocal; i++) mine[atom->type[i] - 1] = 1;
  for (int k = 0; k < modify->nfix; k++) { /* the inlets' particles, as the stepper counts them */
    const FixJdemInlet *in = dynamic_cast<const FixJdemInlet *>(modify->fix[k]);
    for (size_t p = 0; in && p < in->section_types().size(); p++) mine[in->section_types()[p]] = 1;
  }
  MPI_Allreduce(&mine[0], &all[0], nt, MPI_INT, MPI_MAX, world);
  bool grew = report;
  for (int t = 0; t < nt; t++)
    if (all[t] && !types_in_use_[t]) types_in_use_[t] = 1, grew = true;
  if (!grew) return;
  std::vector<unsigned char> walls(nt, 0);
  for (int k = 0; k < modify->nfix; k++) {
    FixWallJiang *w = dynamic_cast<FixWallJiang *>(modify->fix[k]);
    if (w && w->wall_type() >= 1 && w->wall_type() <= nt) walls[w->wall_type() - 1] = 1;
  }
  features_ = jd_law_set_select(nt, &restitution_[0], &friction_[0], &rolling_friction_[0],
                                &types_in_use_[0], &walls[0], mu_r, tangential_rule, normal_law,
                                energy);
  if ((features_ & JD_F_ROLLING) && !rolling)
    error->all(FLERR, "pair_style gran/jiang: coefficientRollingFriction is > 0 for a pair of types "
                      "in use, which needs the rolling law and its history: add 'rolling on' to "
                      "pair_style gran/jiang (or set coefficientRollingFriction to 0)");
  if (report && comm->me == 0) {
    char laws[96];
    jd_law_set_describe(features_, laws, sizeof laws);
    if (screen) std::fprintf(screen, "gran/jiang: law set %s\n", laws);
    if (logfile) std::fprintf(logfile, "gran/jiang: law set %s\n", laws);
  }
}

/* Computed once per atom instead of once per contact.  The atoms (local and ghost) and their
 * radii change only at neighbour builds, unless the radii vary during the run (radvary_flag,
 * e.g. fix adapt): then every step. */
void PairGranJiang::refresh_prefactors() {
  const int nall = atom->nlocal + atom->nghost;
  const bool rebuilt = neighbor->ncalls != kp_ncalls_; /* on every rank at the same step */
  if (!rebuilt && nall == kp_nall_ && !atom->radvary_flag) return;
  const double *radius = atom->radius;
  const int *type = atom->type;
  kp_.resize(nall > 0 ? nall : 1);
  kw_.resize(nall > 0 ? nall : 1);
  for (int i = 0; i < nall; i++) {
    kp_[i] = jd_hertz_prefactor(E_[type[i]], nu_[type[i]], radius[i]);
    kw_[i] = jd_kn_wall(wall_rule, E_[type[i]], nu_[type[i]], radius[i]);
  }
  kp_ncalls_ = neighbor->ncalls;
  kp_nall_ = nall;
  if (rebuilt) update_law_set(false);
}

void PairGranJiang::compute_force(int eflag, int vflag, int addflag) {
  refresh_prefactors(); /* first: a neighbour build may widen the law set */
#define JD_PAIR_LOOP(b) \
  case (b): loop<(b)>(eflag, vflag, addflag); break;
  JD_DISPATCH(features_, JD_PAIR_LOOP)
#undef JD_PAIR_LOOP
}

template <unsigned F>
void PairGranJiang::loop(int eflag, int vflag, int addflag) {
  if (eflag || vflag) ev_setup(eflag, vflag);
  else evflag = vflag_fdotr = 0;

  const unsigned laws = jd_law_set_of_loop(F, features_); /* with the run-time laws */
  /* LIGGGHTS evaluates forces without advancing the history at set-up (shearupdate 0) and for
   * compute pair/gran/local (computeflag 0): evaluate on a copy then. */
  const bool commit = shearupdate_ != 0;
  const bool apply = computeflag_ != 0;
  const bool report = addflag && cpl();
  LoopSums sums;
  overlap_trip = JdOverlapTrip();
  if (laws == F && commit && apply && !report) lane_loop<F>(sums);
  else plain_loop<F>(laws, commit, apply, report, sums);

  if (commit) {
    e_damp_cum += sums.e_damp;
    e_fric_cum += sums.e_fric;
  }
  e_elastic_now = sums.e_el;
  contacts_now = sums.ncontacts;
}

/* Atom i's neighbours and their contact histories and touch flags (LIGGGHTS' lists). */
PairGranJiang::NeighbourRow PairGranJiang::row_of(int i) const {
  NeighbourRow r;
  r.j = list->firstneigh[i];
  r.n = list->numneigh[i];
  r.touch = listgranhistory->firstneigh[i];
  r.hist = listgranhistory->firstdouble[i];
  return r;
}

/* A pair whose spheres no longer touch: our semantics reset its history now (the dissipation
 * was harvested while it touched). */
void PairGranJiang::forget_contact(int *touch, double *hist) const {
  if (!*touch) return;
  *touch = 0;
  const int slen = state_len();
  for (int k = 0; k < slen; k++) hist[k] = 0.0;
}

/* The watchdog's overlap limit: overlaps at most overlap_limit x R_i and x R_j are never
 * excessive, which skips the exact test (jd_overlap_excessive, a libm fmin call) for almost
 * every contact. */
void PairGranJiang::note_overlap(int i, int j, double delta, double Ri, double Rj) {
  if ((delta > overlap_limit * Ri || delta > overlap_limit * Rj) &&
      jd_overlap_excessive(delta, Ri, Rj, overlap_limit))
    overlap_trip.note(delta, std::fmin(Ri, Rj), atom->tag[i], atom->tag[j], NULL);
}

/* A touching pair's share of the evaluation's sums (a pair with a ghost partner is evaluated on
 * both ranks: it counts half on each); with JD_F_ENERGY its dissipation is harvested from st. */
template <unsigned F>
void PairGranJiang::book_contact(jd_contact_state *st, int j, int carries, LoopSums &sums) {
  const double w = j < atom->nlocal ? 1.0 : 0.5;
  if (F & JD_F_ENERGY) {
    jd_contact_harvest(st, w, &sums.e_damp, &sums.e_fric);
    if (carries) sums.e_el += w * jd_contact_elastic_energy(st);
  }
  if (carries) sums.ncontacts += w;
}

/* The force fb on j (-fb on i) and the torques ta, tb into LIGGGHTS' arrays (j's only when it is
 * local: a ghost's are its owner's), and the virial. */
void PairGranJiang::add_pair_forces(int i, int j, const double fb[3], const double ta[3],
                                    const double tb[3]) {
  double **x = atom->x, **f = atom->f, **torque = atom->torque;
  const int nlocal = atom->nlocal;
  jd_sub3(f[i], fb);
  jd_add3(torque[i], ta);
  if (j < nlocal) {
    jd_add3(f[j], fb);
    jd_add3(torque[j], tb);
  }
  if (evflag)
    ev_tally_xyz(i, j, nlocal, 0, 0.0, 0.0, -fb[0], -fb[1], -fb[2], x[i][0] - x[j][0],
                 x[i][1] - x[j][1], x[i][2] - x[j][2]);
}

/* One pair at a time: LIGGGHTS' set-up evaluation, compute pair/gran/local and run-time laws. */
template <unsigned F>
void PairGranJiang::plain_loop(unsigned laws, bool commit, bool apply, bool report, LoopSums &sums) {
  double **x = atom->x, **v = atom->v, **omega = atom->omega;
  const double *radius = atom->radius, *rmass = atom->rmass;
  const int *type = atom->type;
  const int dn = dnum(), roll_at = rolling_at();
  const double dt_run = update->dt;
  const double *kp = pair_prefactors();

  for (int ii = 0; ii < list->inum; ii++) {
    const int i = list->ilist[ii];
    const NeighbourRow row = row_of(i);
    const double Ri = radius[i], mi = rmass[i];
    const jd_pair_coeffs *coeffs_i = &coeffs_[type[i] * (ntypes_ + 1)];

    for (int jj = 0; jj < row.n; jj++) {
      const int j = row.j[jj] & NEIGHMASK;
      double *hist = &row.hist[dn * jj];
      jd_contact_geom g;
      if (!jd_geom_spheres(x[i], Ri, x[j], radius[j], &g)) {
        if (commit) forget_contact(&row.touch[jj], hist);
        continue;
      }
      const double Rj = radius[j], mj = rmass[j];
      note_overlap(i, j, g.delta, Ri, Rj);
      jd_geom_pair_material(F, &g, kp[i], kp[j], mi, mj, jd_sphere_inertia(mi, Ri),
                            jd_sphere_inertia(mj, Rj));
      jd_kinematics k;
      jd_copy3(k.va, v[i]);
      jd_copy3(k.wa, omega[i]);
      jd_copy3(k.vb, v[j]);
      jd_copy3(k.wb, omega[j]);
      /* the stored history itself or a local copy (jdem_history.h) */
      JdHistory<F> h(hist, roll_at, commit);
      jd_contact_result out;
      const int carries = jd_contact(laws, &coeffs_i[type[j]], &g, &k, dt_run, h.st, h.rs, &out);
      /* a pair with a ghost partner is evaluated on both ranks: count it half on each */
      book_contact<F>(h.st, j, carries, sums);
      row.touch[jj] = 1; /* keep the history across neighbour rebuilds while overlapping */
      h.finish();
      if (report) report_pair(i, j, carries, out, hist);
      if (carries && apply) add_pair_forces(i, j, out.f, out.ta, out.tb);
    }
  }
}

/* A time step in SIMD lanes (pair_gran_jiang_lanes.h): the pairs that pass LIGGGHTS' sphere
 * test are queued with copies of their inputs, evaluated JdPairLanes::N at a time, and applied
 * in queue order. */
template <unsigned F>
void PairGranJiang::lane_loop(LoopSums &sums) {
  double **x = atom->x, **v = atom->v;
  double **omega = atom->omega;
  const double *radius = atom->radius, *rmass = atom->rmass;
  const int *type = atom->type;
  const int dn = dnum(), roll_at = rolling_at();
  const double dt_run = update->dt;
  const double *kp = pair_prefactors();
  typedef JdPairLanes<F> Lanes;
  Lanes lanes;
  lanes.n = 0;

  for (int ii = 0; ii < list->inum; ii++) {
    const int i = list->ilist[ii];
    const NeighbourRow row = row_of(i);
    const double *xi = x[i];
    const double Ri = radius[i];
    const jd_pair_coeffs *coeffs_i = &coeffs_[type[i] * (ntypes_ + 1)];

    for (int jj = 0; jj < row.n; jj++) {
      const int j = row.j[jj] & NEIGHMASK;
      double *hist = &row.hist[dn * jj];
      /* LIGGGHTS' test, as jd_geom_spheres_contact writes it */
      const double dx[3] = {x[j][0] - xi[0], x[j][1] - xi[1], x[j][2] - xi[2]};
      const double rsq = jd_dot(dx, dx), radsum = Ri + radius[j];
      if (rsq >= radsum * radsum) {
        forget_contact(&row.touch[jj], hist);
        continue;
      }
      const int b = lanes.n++;
      lanes.i[b] = i;
      lanes.j[b] = j;
      lanes.hist[b] = hist;
      lanes.touch[b] = &row.touch[jj];
      for (int d = 0; d < 3; d++) {
        lanes.dx[d][b] = dx[d];
        lanes.va[d][b] = v[i][d];
        lanes.wa[d][b] = omega[i][d];
        lanes.vb[d][b] = v[j][d];
        lanes.wb[d][b] = omega[j][d];
      }
      lanes.rsq[b] = rsq;
      lanes.ri[b] = Ri;
      lanes.rj[b] = radius[j];
      lanes.kpi[b] = kp[i];
      lanes.kpj[b] = kp[j];
      lanes.mi[b] = rmass[i];
      lanes.mj[b] = rmass[j];
      const jd_pair_coeffs &co = coeffs_i[type[j]];
      lanes.gamma[b] = co.gamma;
      lanes.mu[b] = co.mu;
      lanes.eta[b] = co.eta;
      lanes.mu_r[b] = co.mu_r;
      lanes.xi_limit[b] = co.xi_limit;
      for (int q = 0; q < Lanes::HW; q++) lanes.rec[q][b] = hist[q];
      for (int q = 0; q < Lanes::RW; q++) lanes.roll[q][b] = hist[roll_at + q];
      if (lanes.n == Lanes::N) {
        jd_pair_lanes_evaluate<F>(lanes, dt_run);
        apply_lanes<F>(lanes, sums);
        lanes.n = 0;
      }
    }
  }
  jd_pair_lanes_evaluate<F>(lanes, dt_run);
  apply_lanes<F>(lanes, sums);
}

/* The evaluated lanes in queue order, each as the plain loop applies one pair: the overlap
 * check, the history, the energy sums, the touch flag, the forces and torques, the virial. */
template <unsigned F>
void PairGranJiang::apply_lanes(JdPairLanes<F> &L, LoopSums &sums) {
  typedef JdPairLanes<F> Lanes;
  const int roll_at = rolling_at();
  for (int b = 0; b < L.n; b++) {
    const int i = L.i[b], j = L.j[b];
    double *hist = L.hist[b];
    if (!L.contact[b]) { /* jd_geom_spheres's verdict after the sphere test: separated */
      forget_contact(L.touch[b], hist);
      continue;
    }
    note_overlap(i, j, L.delta[b], L.ri[b], L.rj[b]);
    for (int q = 0; q < Lanes::HW; q++) hist[q] = L.rec[q][b];
    for (int q = 0; q < Lanes::RW; q++) hist[roll_at + q] = L.roll[q][b];
    /* with JD_F_ENERGY the record is the whole jd_contact_state (jdem_history.h) */
    book_contact<F>(reinterpret_cast<jd_contact_state *>(hist), j, L.carries[b], sums);
    *L.touch[b] = 1;
    if (!L.carries[b]) continue;
    const double fb[3] = {L.f[0][b], L.f[1][b], L.f[2][b]};
    const double ta[3] = {L.ta[0][b], L.ta[1][b], L.ta[2][b]};
    const double tb[3] = {L.tb[0][b], L.tb[1][b], L.tb[2][b]};
    add_pair_forces(i, j, fb, ta, tb);
  }
}

/* compute pair/gran/local: a row for every pair whose spheres overlap (the rows it counts), with
 * the force and torque on i as LIGGGHTS' own pairs report them (zero once Luding's end of
 * collision has released the pair) and the stored history. */
void PairGranJiang::report_pair(int i, int j, bool carries, const jd_contact_result &out,
                                double *hist) {
  double fi[3] = {0.0, 0.0, 0.0}, ti[3] = {0.0, 0.0, 0.0};
  if (carries)
    for (int d = 0; d < 3; d++) {
      fi[d] = -out.f[d];
      ti[d] = out.ta[d];
    }
  cpl()->add_pair(i, j, fi[0], fi[1], fi[2], ti[0], ti[1], ti[2], hist, NULL);
}

/* ---------------------------------------------------------------------------------------- */
/* Restart files (jdem_restart.h).                                                            */

/* LIGGGHTS' set-up of the granular pair (contact history fix, neighbour requests), then the fix
 * that carries the rest of our state through restart files (fix_jdem_restart.h). */
void PairGranJiang::init_style() {
  PairGran::init_style();
  FixJdemRestart::define(lmp);
}

/* A run resuming from a restart file keeps the history and observables that were read: no
 * set-up evaluation (fix jdem/restart sets the forces of the step the file was written at). */
void PairGranJiang::compute(int eflag, int vflag) {
  if (update->setupflag && jdem_restart_resuming(lmp)) return;
  PairGran::compute(eflag, vflag);
}

/* The pair section of the file (rank 0): our hashcode, a layout version, the options. */
namespace {
/* version 1: six options and mu_r; 2 (MEPA): normal_law too, and mu_r, mepa_exponent and
 * mepa_plastic_depth */
enum { PAIR_RESTART_VERSION = 2, PAIR_RESTART_OPTIONS = 7 };
}

void PairGranJiang::write_restart_settings(FILE *fp) {
  const int64_t mark = hashcode();
  const int version = PAIR_RESTART_VERSION;
  const int options[PAIR_RESTART_OPTIONS] = {wall_rule, damping_map, xi_limit, tangential_rule,
                                             rolling ? 1 : 0, energy_accounts ? 1 : 0, normal_law};
  const double values[3] = {mu_r, mepa_exponent, mepa_plastic_depth};
  std::fwrite(&mark, sizeof mark, 1, fp);
  std::fwrite(&version, sizeof version, 1, fp);
  std::fwrite(options, sizeof(int), PAIR_RESTART_OPTIONS, fp);
  std::fwrite(values, sizeof(double), 3, fp);
}

void PairGranJiang::read_restart_settings(FILE *fp, const int, const int) {
  int64_t mark = 0;
  int version = 0, options[PAIR_RESTART_OPTIONS] = {0, 0, 0, 0, 0, 0, JD_NORMAL_HERTZ};
  /* a version 1 file's MEPA options: Hertz, with the defaults */
  double values[3] = {0.0, JD_MEPA_DEFAULT_EXPONENT, JD_MEPA_DEFAULT_DEPTH};
  int ok = 1;
  if (comm->me == 0) {
    ok = std::fread(&mark, sizeof mark, 1, fp) == 1 && std::fread(&version, sizeof version, 1, fp) == 1 &&
         mark == hashcode() && (version == 1 || version == PAIR_RESTART_VERSION);
    const int n_options = version == 1 ? PAIR_RESTART_OPTIONS - 1 : PAIR_RESTART_OPTIONS;
    const int n_values = version == 1 ? 1 : 3;
    ok = ok && std::fread(options, sizeof(int), n_options, fp) == (size_t)n_options &&
         std::fread(values, sizeof(double), n_values, fp) == (size_t)n_values;
  }
  MPI_Bcast(&ok, 1, MPI_INT, 0, world);
  if (!ok)
    error->all(FLERR, "read_restart: the pair section of the restart file is not one of "
                      "pair_style gran/jiang (another version of liggghts-jdem wrote it, or the "
                      "file is truncated)");
  MPI_Bcast(options, PAIR_RESTART_OPTIONS, MPI_INT, 0, world);
  MPI_Bcast(values, 3, MPI_DOUBLE, 0, world);
  mu_r = values[0];
  mepa_exponent = values[1];
  mepa_plastic_depth = values[2];
  wall_rule = options[0];
  damping_map = options[1];
  xi_limit = options[2];
  tangential_rule = options[3];
  rolling = options[4] != 0;
  energy_accounts = options[5] != 0;
  normal_law = options[6];
  register_history();
  present_as_gran();
}
