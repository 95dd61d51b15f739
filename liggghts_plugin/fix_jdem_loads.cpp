/* fix_jdem_loads.cpp — see fix_jdem_loads.h. */
#include "fix_jdem_loads.h"

#include <mpi.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "atom.h"
#include "comm.h"
#include "error.h"
#include "memory.h"
#include "update.h"

#include "jdem_input_file.h"
#include "jdem_kernel.h"
#include "jdem_restart.h"

using namespace LAMMPS_NS;
using namespace FixConst;

FixJdemLoads::FixJdemLoads(LAMMPS *lmp, int narg, char **arg)
    : Fix(lmp, narg, arg), work_cum(0.0), load(NULL), nmax_l(0) {
  if (narg != 5 || std::strcmp(arg[3], "file") != 0)
    error->all(FLERR, "Illegal fix jdem/loads command: fix ID group jdem/loads file FILE");
  if (!atom->tag_enable || atom->map_style == 0)
    error->all(FLERR, "fix jdem/loads needs atom IDs and `atom_modify map array` (or hash)");
  create_attribute = 1;
  restart_global = restart_peratom = 1; /* jdem_restart.h */
  grow_arrays(atom->nmax);
  atom->add_callback(0);
  atom->add_callback(1);
  path = arg[4];
}

FixJdemLoads::~FixJdemLoads() {
  atom->delete_callback(id, 0);
  atom->delete_callback(id, 1);
  memory->destroy(load);
}

int FixJdemLoads::setmask() { return POST_FORCE; }

/* Rank 0 reads the file and broadcasts it; the owner of each atom keeps its line. */
void FixJdemLoads::read_file(const char *path) {
  std::vector<double> rows; /* id fx fy fz held */
  char msg[512] = "";
  int bad = 0;
  if (comm->me == 0) {
    std::ifstream in;
    std::string why = jdem_open_input("fix jdem/loads: file", path, in);
    std::map<double, int> seen; /* id -> line */
    std::string line;
    for (int lineno = 1; !bad && why.empty() && std::getline(in, line); lineno++) {
      why = jdem_text_line("fix jdem/loads: file", path, lineno, line);
      if (!why.empty()) break;
      const size_t hash = line.find('#');
      if (hash != std::string::npos) line.erase(hash);
      std::istringstream ls(line);
      double v[5];
      std::string rest;
      if (!(ls >> v[0])) continue;
      if (!(ls >> v[1] >> v[2] >> v[3] >> v[4]) || (ls >> rest) || v[0] < 1 || v[0] > atom->map_tag_max ||
          v[0] != std::floor(v[0]) || (v[4] != 0.0 && v[4] != 1.0)) {
        std::snprintf(msg, sizeof msg, "fix jdem/loads: %s line %d: expected \"ID FX FY FZ HELD\" with an "
                      "atom id between 1 and %d and HELD 0 or 1", path, lineno, atom->map_tag_max);
        bad = 1;
      } else if (seen.count(v[0])) {
        std::snprintf(msg, sizeof msg, "fix jdem/loads: %s line %d: atom id %.0f is listed twice (first on "
                      "line %d)", path, lineno, v[0], seen[v[0]]);
        bad = 1;
      }
      seen[v[0]] = lineno;
      rows.insert(rows.end(), v, v + 5);
    }
    if (why.empty() && !bad && rows.empty())
      why = std::string("fix jdem/loads: file ") + path + ": holds no loads (lines \"ID FX FY FZ HELD\")";
    if (!why.empty() && !bad) {
      std::snprintf(msg, sizeof msg, "%s", why.c_str());
      bad = 1;
    }
  }
  jdem_share_input(lmp, bad, msg, sizeof msg, rows);
  const int n = (int)rows.size();
  int mine = 0, all = 0;
  for (int r = 0; r < n; r += 5) {
    const int i = atom->map((int)rows[r]);
    if (i < 0 || i >= atom->nlocal) continue;
    mine++;
    for (int d = 0; d < 4; d++) load[i][L_FX + d] = rows[r + 1 + d];
  }
  MPI_Allreduce(&mine, &all, 1, MPI_INT, MPI_SUM, world);
  if (all != n / 5) error->all(FLERR, "fix jdem/loads: the file names atom ids that do not exist");
}

/* The file is read at the first set-up: Modify::add_fix resets the per-atom data of a new fix
 * (set_arrays) after its constructor.  The set-up evaluation applies the loads (as the
 * stepper's) but books no work. */
void FixJdemLoads::setup(int vflag) {
  if (jdem_restart_resuming(lmp)) return; /* the loads and forces read from the file stand */
  if (!path.empty()) read_file(path.c_str());
  path.clear();
  apply(false);
}

void FixJdemLoads::post_force(int vflag) { apply(true); }

void FixJdemLoads::apply(bool commit) {
  double **f = atom->f, **torque = atom->torque, **v = atom->v, **omega = atom->omega;
  const double dt = update->dt;
  double work = 0.0;
  for (int i = 0; i < atom->nlocal; i++) {
    double *l = load[i];
    const bool held = l[L_HELD] != 0.0;
    if (!held && l[L_FX] == 0.0 && l[L_FX + 1] == 0.0 && l[L_FX + 2] == 0.0) continue;
    double applied[6];
    for (int d = 0; d < 3; d++) {
      f[i][d] += l[L_FX + d];
      /* a held particle: the constraint applies minus everything else */
      applied[d] = held ? -f[i][d] : l[L_FX + d];
      applied[3 + d] = held ? -torque[i][d] : 0.0;
      if (held) f[i][d] = torque[i][d] = 0.0;
    }
    work += jd_load_work(&l[L_PREV], applied, v[i], omega[i], dt);
    for (int k = 0; k < 6; k++) l[L_PREV + k] = applied[k];
  }
  if (commit) work_cum += work;
}

void FixJdemLoads::grow_arrays(int nmax) {
  memory->grow(load, nmax, L_N, "jdem/loads:load");
  for (int i = nmax_l; i < nmax; i++)
    for (int k = 0; k < L_N; k++) load[i][k] = 0.0;
  nmax_l = nmax;
}

void FixJdemLoads::copy_arrays(int i, int j, int delflag) {
  for (int k = 0; k < L_N; k++) load[j][k] = load[i][k];
}

void FixJdemLoads::set_arrays(int i) {
  for (int k = 0; k < L_N; k++) load[i][k] = 0.0;
}

int FixJdemLoads::pack_exchange(int i, double *buf) {
  for (int k = 0; k < L_N; k++) buf[k] = load[i][k];
  return L_N;
}

int FixJdemLoads::unpack_exchange(int nlocal, double *buf) {
  for (int k = 0; k < L_N; k++) load[nlocal][k] = buf[k];
  return L_N;
}

double FixJdemLoads::memory_usage() { return (double)nmax_l * L_N * sizeof(double); }

/* ---- restart files (jdem_restart.h): whether the file was read, each rank's work; per atom
 * the load and the force and torque applied at the last step ---- */

void FixJdemLoads::write_restart(FILE *fp) {
  JdemRestartState st;
  st.shared.push_back(path.empty() ? 1.0 : 0.0);
  st.sums.push_back(work_cum);
  jdem_restart_write_state(lmp, fp, st);
}

void FixJdemLoads::restart(char *buf) {
  const JdemRestartState st =
      jdem_restart_read_state(lmp, buf, std::string("fix ") + id + " (jdem/loads)", 1, 1);
  if (st.shared[0] != 0.0) path.clear(); /* the loads come with the atoms */
  work_cum = st.sums[0];
}

int FixJdemLoads::pack_restart(int i, double *buf) { return jdem_pack_restart(this, i, buf); }

void FixJdemLoads::unpack_restart(int nlocal, int nth) {
  if (jdem_stored_restart_len(lmp, nlocal, nth) != L_N)
    error->one(FLERR, (std::string("fix ") + id + " (jdem/loads): the restart file's per-atom "
                       "record has another length: continue with the version that wrote it").c_str());
  jdem_unpack_restart(lmp, this, nlocal, nth);
}
