/* fix_jdem_guard.cpp — see fix_jdem_guard.h. */
#include "fix_jdem_guard.h"

#include <mpi.h>

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

#include "fix_bond_jiang.h"
#include "fix_jdem_inlet.h"
#include "fix_wall_jiang.h"
#include "jdem_guard.h"
#include "jdem_kernel.h"
#include "pair_gran_jiang.h"

using namespace LAMMPS_NS;

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

  /* the inlets' section particles, once each (as the stepper's guard: they take part once inserted) */
  for (int k = 0; k < modify->nfix; k++) {
    const FixJdemInlet *in = dynamic_cast<const FixJdemInlet *>(modify->fix[k]);
    for (size_t p = 0; in && p < in->section_types().size(); p++) {
      const int t = in->section_types()[p];
      g_count[t] += 1.0;
      if (in->section_radii()[p] < g_rmin[t]) {
        g_rmin[t] = in->section_radii()[p];
        g_rho[t] = in->section_densities()[p];
      }
    }
  }
  std::vector<jd_guard_species> sp(nt);
  for (int t = 0; t < nt; t++) {
    sp[t].count = (size_t)g_count[t];
    sp[t].rmin = g_count[t] > 0.0 ? g_rmin[t] : 0.0;
    sp[t].density = g_rho[t];
    sp[t].E = pair->youngs(t + 1);
    sp[t].nu = pair->poisson(t + 1);
  }
  bool walls = false;
  for (int k = 0; k < modify->nfix; k++) walls = walls || dynamic_cast<FixWallJiang *>(modify->fix[k]);

  jd_guard_input in;
  in.species = sp.data();
  in.n_species = (size_t)nt;
  in.has_walls = walls;
  in.wall_rule = pair->wall_rule;
  in.tangential_rule = pair->tangential_rule;
  in.max_impact_speed = vmax;
  in.coordination = coordination;
  in.damping_ratio = jd_guard_damping_ratio(sp.data(), (size_t)nt, pair->restitution_table(),
                                            pair->damping_map);
  in.bond_omega2 = 0.0; /* bonds of several types add up on an atom: a sum of bounds bounds it */
  for (int k = 0; k < modify->nfix; k++) {
    FixBondJiang *b = dynamic_cast<FixBondJiang *>(modify->fix[k]);
    if (b) in.bond_omega2 += b->omega2_max();
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
