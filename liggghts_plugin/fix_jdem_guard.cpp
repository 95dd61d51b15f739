/* fix_jdem_guard.cpp — see fix_jdem_guard.h. */
#include "fix_jdem_guard.h"

#include <mpi.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <string>
#include <vector>

#include "atom.h"
#include "comm.h"
#include "error.h"
#include "force.h"
#include "modify.h"
#include "update.h"

#include "fix_insert.h"
#include "fix_particledistribution_discrete.h"
#include "fix_template_sphere.h"
#include "probability_distribution.h"

#include "fix_bond_jiang.h"
#include "fix_jdem_inlet.h"
#include "fix_wall_jiang.h"
#include "jdem_guard.h"
#include "jdem_kernel.h"
#include "pair_gran_jiang.h"

using namespace LAMMPS_NS;

bool JdemGuardTally::any() const {
  for (size_t t = 0; t < count.size(); t++)
    if (count[t] > 0.0) return true;
  return false;
}

void JdemGuardTally::add(int t, double r, double density, double n) {
  count[t] += n;
  if (r < rmin[t]) {
    rmin[t] = r;
    rho[t] = density;
  }
}

/* LIGGGHTS keeps a template's density distribution and an insertion's velocity protected, with
 * no accessor.  A class derived from the owner may name them ([class.protected]): these read
 * them through such member pointers, without changing LIGGGHTS. */
namespace {
struct TemplatePeek : FixTemplateSphere {
  static double min_density(FixTemplateSphere *t) {
    return LMP_PROBABILITY_NS::pdf_min(t->*(&TemplatePeek::pdf_density));
  }
};
struct InsertPeek : FixInsert {
  /* the fastest insertion speed |v| + |fluctuation| [m/s] */
  static double max_speed(FixInsert *f) {
    const double *v = f->*(&InsertPeek::v_insert), *dv = f->*(&InsertPeek::v_insertFluct);
    const bool fluct = f->*(&InsertPeek::v_randomSetting) != RANDOM_CONSTANT;
    return std::sqrt(jd_dot(v, v)) + (fluct ? std::sqrt(jd_dot(dv, dv)) : 0.0);
  }
};
}  // namespace

/* the inlets' section particles, once each (as the stepper's guard: they take part once inserted) */
void FixJdemGuard::add_inlets(JdemGuardTally &tally) {
  for (int k = 0; k < modify->nfix; k++) {
    const FixJdemInlet *in = dynamic_cast<const FixJdemInlet *>(modify->fix[k]);
    for (size_t p = 0; in && p < in->section_types().size(); p++)
      tally.add(in->section_types()[p], in->section_radii()[p], in->section_densities()[p], 1.0);
  }
}

/* The particles that LIGGGHTS' own insertion fixes (insert/pack, insert/stream,
 * insert/rate/region) will insert: each template of their particledistribution/discrete, with
 * its smallest radius and its smallest density (the shortest contact: t_c grows with R and
 * rho^(2/5)).  Returns the fastest insertion speed; what cannot be checked is named in a
 * warning. */
double FixJdemGuard::add_templates(JdemGuardTally &tally) {
  double speed = 0.0;
  for (int k = 0; k < modify->nfix; k++) {
    Fix *f = modify->fix[k];
    FixInsert *ins = dynamic_cast<FixInsert *>(f);
    if (!ins) {
      if (std::strncmp(f->style, "pour", 4) == 0 || std::strncmp(f->style, "insert", 6) == 0)
        cannot_check(f, "its particles are not described by particle templates the guard can read");
      continue;
    }
    FixParticledistributionDiscrete *dist = ins->get_distribution();
    if (!dist) continue;
    const double v = InsertPeek::max_speed(ins);
    speed = v > speed ? v : speed;
    for (int j = 0; j < dist->n_particletemplates(); j++) {
      FixTemplateSphere *t = dist->get_template(j);
      if (std::strcmp(t->style, "particletemplate/sphere") != 0 || t->is_relative()) {
        cannot_check(f, (std::string("its template ") + t->id + " (" + t->style + ") is not one "
                         "sphere of absolute radius").c_str());
        continue;
      }
      tally.add(t->mintype() - 1, t->min_rad(), TemplatePeek::min_density(t), 1.0);
    }
  }
  return speed;
}

void FixJdemGuard::cannot_check(const Fix *f, const char *why) {
  if (comm->me != 0) return;
  error->warning(FLERR, (std::string("fix jdem/guard cannot check the particles that fix ") + f->id +
                         " (" + f->style + ") will insert: " + why +
                         "; it checks the atoms present and the other insertions").c_str());
}

FixJdemGuard::FixJdemGuard(LAMMPS *lmp, int narg, char **arg)
    : Fix(lmp, narg, arg), vmax(0.0), coordination(JD_GUARD_DEFAULT_COORDINATION), force_run(false) {
  const char *usage = "Illegal fix jdem/guard command: fix ID all jdem/guard vmax V [coordination C] [force]";
  for (int i = 3; i < narg; i++) {
    if (std::strcmp(arg[i], "force") == 0) {
      force_run = true;
    } else if (i + 1 < narg && std::strcmp(arg[i], "vmax") == 0) {
      vmax = force->numeric(FLERR, arg[++i]);
      if (!(vmax >= 0.0)) error->all(FLERR, "fix jdem/guard: vmax must be >= 0");
    } else if (i + 1 < narg && std::strcmp(arg[i], "coordination") == 0) {
      coordination = force->numeric(FLERR, arg[++i]);
      if (!(coordination >= 1.0)) error->all(FLERR, "fix jdem/guard: coordination must be >= 1");
    } else {
      error->all(FLERR, usage);
    }
  }
}

/* At set-up, after the bond fixes' (explicit bonds are read then): they must come first. */
void FixJdemGuard::init() {
  bool seen_me = false;
  for (int k = 0; k < modify->nfix; k++) {
    if (modify->fix[k] == this) seen_me = true;
    else if (seen_me && dynamic_cast<FixBondJiang *>(modify->fix[k]))
      error->all(FLERR, "fix jdem/guard must be defined after every fix bond/jiang");
  }
}

void FixJdemGuard::setup(int) {
  PairGranJiang *pair = dynamic_cast<PairGranJiang *>(force->pair);
  if (!pair) error->all(FLERR, "fix jdem/guard requires pair_style gran/jiang");
  const int nt = atom->ntypes;
  /* per type (index t-1): smallest radius, its density, atom count */
  std::vector<double> rmin(nt, INFINITY), rho(nt, 0.0), count(nt, 0.0);
  for (int i = 0; i < atom->nlocal; i++) {
    const int t = atom->type[i] - 1;
    const double r = atom->radius[i];
    count[t] += 1.0;
    if (r < rmin[t]) {
      rmin[t] = r;
      rho[t] = atom->rmass[i] / (4.0 * JD_PI / 3.0 * r * r * r);
    }
  }
  std::vector<double> g_rmin(nt), g_count(nt), g_rho(nt);
  MPI_Allreduce(rmin.data(), g_rmin.data(), nt, MPI_DOUBLE, MPI_MIN, world);
  MPI_Allreduce(count.data(), g_count.data(), nt, MPI_DOUBLE, MPI_SUM, world);
  for (int t = 0; t < nt; t++) rho[t] = rmin[t] == g_rmin[t] ? rho[t] : 0.0; /* the owner's */
  MPI_Allreduce(rho.data(), g_rho.data(), nt, MPI_DOUBLE, MPI_MAX, world);

  JdemGuardTally tally = {g_rmin, g_rho, g_count};
  add_inlets(tally);
  const double insertion_speed = add_templates(tally);
  if (comm->me == 0 && !tally.any())
    error->warning(FLERR, "fix jdem/guard: no particles and no insertion template to check at this "
                          "run's set-up: the time step is not checked until a run starts with some");
  std::vector<jd_guard_species> sp(nt);
  for (int t = 0; t < nt; t++) {
    sp[t].count = (size_t)g_count[t];
    sp[t].rmin = g_count[t] > 0.0 ? g_rmin[t] : 0.0;
    sp[t].density = g_rho[t];
    sp[t].E = pair->youngs(t + 1);
    sp[t].nu = pair->poisson(t + 1);
    sp[t].mepa_k1 = pair->mepa() ? pair->mepa_k1(t + 1) : 0.0;
    sp[t].mepa_k2 = pair->mepa() ? pair->mepa_k2(t + 1) : 0.0;
  }
  bool walls = false;
  for (int k = 0; k < modify->nfix; k++) walls = walls || dynamic_cast<FixWallJiang *>(modify->fix[k]);

  jd_guard_input in;
  in.species = sp.data();
  in.n_species = (size_t)nt;
  in.has_walls = walls;
  in.wall_rule = pair->wall_rule;
  in.tangential_rule = pair->tangential_rule;
  in.normal_law = pair->normal_law;
  in.mepa_n = pair->mepa_exponent;
  in.max_impact_speed = vmax > insertion_speed ? vmax : insertion_speed;
  in.coordination = coordination;
  in.damping_ratio = jd_guard_damping_ratio(sp.data(), (size_t)nt, pair->restitution_table(),
                                            pair->damping_map);
  in.bond_omega2 = 0.0; /* bonds of several types add up on an atom: a sum of bounds bounds it */
  for (int k = 0; k < modify->nfix; k++) {
    FixBondJiang *b = dynamic_cast<FixBondJiang *>(modify->fix[k]);
    if (b) in.bond_omega2 += b->omega2_max();
  }
  for (int k = 0; k < modify->nfix; k++) { /* the inlets' future bonds, as build/jdem bounds them */
    FixJdemInlet *inlet = dynamic_cast<FixJdemInlet *>(modify->fix[k]);
    if (inlet) in.bond_omega2 = std::max(in.bond_omega2, inlet->section_bond_omega2());
  }
  in.dt = update->dt;
  jd_guard_result r;
  jd_guard_assess(&in, &r);
  if (!r.violated) return;
  char msg[512];
  if (!force_run) {
    jd_guard_refusal(&in, &r, "Add the keyword force to fix jdem/guard to run anyway.", msg, sizeof msg);
    error->all(FLERR, (std::string("jdem: ") + msg).c_str());
  }
  jd_guard_warning(&in, &r, "fix jdem/guard force", msg, sizeof msg);
  if (comm->me == 0) error->warning(FLERR, (std::string("jdem: ") + msg).c_str());
}
