/* fix_jdem_domain.cpp — see fix_jdem_domain.h. */
#include "fix_jdem_domain.h"

#include <mpi.h>

#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "atom.h"
#include "atom_vec.h"
#include "comm.h"
#include "error.h"
#include "fix_bond_jiang.h"
#include "force.h"
#include "modify.h"
#include "update.h"

#include "jdem_domain.h"
#include "jdem_restart.h"

using namespace LAMMPS_NS;
using namespace FixConst;

namespace {
/* The three numbers after keyword `key` at arg[at], or a message naming the command. */
void read3(Error *error, int narg, char **arg, int at, const char *key, double out[3]) {
  if (std::strcmp(arg[at], key) != 0) {
    const std::string msg = std::string("Illegal fix jdem/domain command: expected '") + key +
                            "' at argument " + std::to_string(at + 1) + ", got '" + arg[at] +
                            "'; valid: fix ID all jdem/domain lo XLO YLO ZLO hi XHI YHI ZHI "
                            "gravity GX GY GZ";
    error->all(FLERR, msg.c_str());
  }
  for (int d = 0; d < 3; d++) {
    char *end = NULL;
    out[d] = std::strtod(arg[at + 1 + d], &end);
    if (*end != '\0') {
      const std::string msg = std::string("fix jdem/domain: '") + arg[at + 1 + d] +
                              "' after '" + key + "' is not a number";
      error->all(FLERR, msg.c_str());
    }
  }
}
}  // namespace

FixJdemDomain::FixJdemDomain(LAMMPS *lmp, int narg, char **arg)
    : Fix(lmp, narg, arg), lost(0.0), energy(0.0) {
  if (narg != 15)
    error->all(FLERR, "Illegal fix jdem/domain command: fix ID all jdem/domain lo XLO YLO ZLO "
                      "hi XHI YHI ZHI gravity GX GY GZ");
  read3(error, narg, arg, 3, "lo", lo);
  read3(error, narg, arg, 7, "hi", hi);
  read3(error, narg, arg, 11, "gravity", g);
  for (int d = 0; d < 3; d++)
    if (!(lo[d] < hi[d])) error->all(FLERR, "fix jdem/domain: hi must be above lo along every axis");
  if (!atom->tag_enable) error->all(FLERR, "fix jdem/domain needs atom IDs");
  restart_global = 1;
}

int FixJdemDomain::setmask() { return PRE_EXCHANGE; }

/* The bond fixes whose bonds a deleted atom takes with it, found once per run, not at every
 * reneighbouring step. */
void FixJdemDomain::init() {
  bonds.clear();
  for (int k = 0; k < modify->nfix; k++)
    if (FixBondJiang *b = dynamic_cast<FixBondJiang *>(modify->fix[k])) bonds.push_back(b);
}

/* Delete this rank's atoms outside the domain (swapping the last atom in, as LAMMPS does), then,
 * collectively, the bonds to them held on other atoms, and book the counts on every rank. */
void FixJdemDomain::pre_exchange() {
  double **x = atom->x, **v = atom->v, **omega = atom->omega, **f = atom->f,
         **torque = atom->torque;
  double *rmass = atom->rmass, *radius = atom->radius;
  const double dtf = 0.5 * update->dt * force->ftm2v;
  std::vector<int> mine;
  double e = 0.0;
  int nlocal = atom->nlocal;
  for (int i = 0; i < nlocal;) {
    if (jd_inside_domain(lo, hi, x[i])) {
      i++;
      continue;
    }
    const double m = rmass[i], inertia = 0.4 * m * radius[i] * radius[i];
    double vv[3], ww[3];
    for (int d = 0; d < 3; d++) {
      vv[d] = v[i][d] + dtf / m * f[i][d];
      ww[d] = omega[i][d] + dtf / inertia * torque[i][d];
    }
    e += jd_lost_energy(m, inertia, x[i], vv, ww, g);
    for (size_t b = 0; b < bonds.size(); b++) e += bonds[b]->held_elastic(i);
    mine.push_back(atom->tag[i]);
    atom->avec->copy(nlocal - 1, i, 1);
    nlocal--;
  }
  atom->nlocal = nlocal;
  int n_mine = (int)mine.size(), n_all = 0;
  MPI_Allreduce(&n_mine, &n_all, 1, MPI_INT, MPI_SUM, world);
  if (n_all == 0) return;
  int nprocs;
  MPI_Comm_size(world, &nprocs);
  std::vector<int> counts(nprocs), displs(nprocs, 0), gone(n_all);
  MPI_Allgather(&n_mine, 1, MPI_INT, counts.data(), 1, MPI_INT, world);
  for (int r = 1; r < nprocs; r++) displs[r] = displs[r - 1] + counts[r - 1];
  MPI_Allgatherv(mine.data(), n_mine, MPI_INT, gone.data(), counts.data(), displs.data(), MPI_INT,
                 world);
  std::sort(gone.begin(), gone.end());
  gone_all.insert(gone_all.end(), gone.begin(), gone.end());
  for (size_t b = 0; b < bonds.size(); b++) e += bonds[b]->drop_partners(gone);
  double e_all = 0.0;
  MPI_Allreduce(&e, &e_all, 1, MPI_DOUBLE, MPI_SUM, world);
  lost += (double)n_all;
  energy += e_all;
  bigint nblocal = atom->nlocal;
  MPI_Allreduce(&nblocal, &atom->natoms, 1, MPI_LMP_BIGINT, MPI_SUM, world);
  if (atom->map_style) {
    atom->nghost = 0;
    atom->map_init();
    atom->map_set();
  }
}

void FixJdemDomain::write_restart(FILE *fp) {
  JdemRestartState st;
  st.shared.push_back(lost);
  st.shared.push_back(energy);
  if (comm->me == 0)
    for (int id : gone_all) st.tail.push_back((double)id);
  jdem_restart_write_state(lmp, fp, st);
}

void FixJdemDomain::restart(char *buf) {
  const std::string who = std::string("fix ") + id + " (jdem/domain)";
  const JdemRestartState st = jdem_restart_read_state(lmp, buf, who, 2, 0);
  lost = st.shared[0];
  energy = st.shared[1];
  gone_all.clear();
  for (double id : st.tail) gone_all.push_back((int)id);
}
