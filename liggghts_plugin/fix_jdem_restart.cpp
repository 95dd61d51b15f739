/* fix_jdem_restart.cpp — see fix_jdem_restart.h. */
#include "fix_jdem_restart.h"

#include <cstdio>

#include "atom.h"
#include "error.h"
#include "force.h"
#include "memory.h"
#include "modify.h"
#include "update.h"

#include "jdem_kernel.h"
#include "jdem_restart.h"
#include "pair_gran_jiang.h"

using namespace LAMMPS_NS;

FixJdemRestart::FixJdemRestart(LAMMPS *lmp, int narg, char **arg)
    : Fix(lmp, narg, arg), resuming_(false), saved(NULL), nmax_saved(0) {
  if (narg != 3) error->all(FLERR, "Illegal fix jdem/restart command: fix ID group jdem/restart");
  restart_global = 1;
  restart_peratom = 1;
  grow_arrays(atom->nmax);
  atom->add_callback(0);
  atom->add_callback(1);
}

FixJdemRestart::~FixJdemRestart() {
  atom->delete_callback(id, 0);
  atom->delete_callback(id, 1);
  memory->destroy(saved);
}

void FixJdemRestart::define(LAMMPS *lmp) {
  if (lmp->modify->find_fix("jdem_restart") >= 0) return;
  jdem_restart_warn_unclaimed_motion(lmp);
  char *args[3] = {(char *)"jdem_restart", (char *)"all", (char *)"jdem/restart"};
  lmp->modify->add_fix(3, args);
}

/* The last fix's set-up: the forces and torques of the step the file was written at. */
void FixJdemRestart::setup(int) {
  if (!resuming_) return;
  double **f = atom->f, **torque = atom->torque;
  for (int i = 0; i < atom->nlocal; i++)
    for (int d = 0; d < 3; d++) {
      f[i][d] = saved[i][d];
      torque[i][d] = saved[i][3 + d];
    }
  resuming_ = false;
}

/* ---- global state: the pair style's options and contact observables ---- */

void FixJdemRestart::write_restart(FILE *fp) {
  PairGranJiang *pair = dynamic_cast<PairGranJiang *>(force->pair);
  JdemRestartState st;
  if (pair) {
    const double shared[NPAIR] = {(double)pair->wall_rule, (double)pair->damping_map,
                                  (double)pair->xi_limit, (double)pair->tangential_rule,
                                  pair->mu_r, pair->rolling ? 1.0 : 0.0,
                                  pair->energy_accounts ? 1.0 : 0.0};
    const double sums[NSUMS] = {pair->e_damp_cum, pair->e_fric_cum, pair->e_elastic_now,
                                pair->contacts_now};
    st.shared.assign(shared, shared + NPAIR);
    st.sums.assign(sums, sums + NSUMS);
  } else {
    st.shared.assign(NPAIR, -1.0);
    st.sums.assign(NSUMS, 0.0);
  }
  st.shared.push_back(update->atime);
  st.shared.push_back(jdem_restart_pack_i64((int64_t)update->atimestep));
  st.shared.push_back(pair ? (double)pair->normal_law : -1.0);
  st.shared.push_back(pair ? pair->mepa_exponent : -1.0);
  st.shared.push_back(pair ? pair->mepa_plastic_depth : -1.0);
  jdem_restart_write_state(lmp, fp, st);
}

/* pair_style gran/jiang (the one this run defines) defines this fix at its set-up: it takes
 * the file's contact observables. */
void FixJdemRestart::restart(char *buf) {
  const JdemRestartState st = read_state(lmp, buf);
  /* the clock as the writer had it, so that the time of every later step (atime + (step -
   * atimestep) dt: the dump's, the bond breaks') has the uninterrupted run's bits; LIGGGHTS'
   * restart file does not keep it */
  update->atime = st.shared[NPAIR];
  update->atimestep = (bigint)jdem_restart_unpack_i64(st.shared[NPAIR + 1]);
  PairGranJiang *pair = dynamic_cast<PairGranJiang *>(force->pair);
  if (!pair) return;
  pair->e_damp_cum = st.sums[0];
  pair->e_fric_cum = st.sums[1];
  pair->e_elastic_now = st.sums[2];
  pair->contacts_now = st.sums[3];
  resuming_ = true;
}

/* The global state of a file written with or without MEPA's options (before MEPA: Hertz). */
JdemRestartState FixJdemRestart::read_state(LAMMPS *lmp, const char *buf) {
  JdemRestartState st = jdem_restart_read_state(lmp, buf, "fix jdem_restart (jdem/restart)",
                                                NSHARED, NSUMS, NSHARED_BEFORE_MEPA);
  if (st.shared.size() == NSHARED_BEFORE_MEPA) {
    const double hertz[NMEPA] = {(double)JD_NORMAL_HERTZ, JD_MEPA_DEFAULT_EXPONENT,
                                 JD_MEPA_DEFAULT_DEPTH};
    st.shared.insert(st.shared.end(), hertz, hertz + NMEPA);
  }
  return st;
}

std::string FixJdemRestart::describe_pair_options(LAMMPS *lmp, const char *state) {
  const JdemRestartState st = read_state(lmp, state);
  const double *o = st.shared.data(), *mepa = o + NPAIR + 2;
  char text[512];
  int n = std::snprintf(text, sizeof text,
                        "wall_rule %s damping %s tangential_limit %s tangential_stiffness %s "
                        "mu_r %.17g rolling %s energy %s",
                        o[0] == JD_WALL_HERTZ ? "hertz" : "jiang2021",
                        o[1] == JD_DAMP_JIANG2021 ? "jiang2021" : "exact_restitution",
                        o[2] == JD_XI_COULOMB ? "coulomb" : "unconstrained",
                        o[3] == JD_KT_JIANG2021 ? "jiang2021" : "mindlin", o[4],
                        o[5] != 0.0 ? "on" : "off", o[6] != 0.0 ? "yes" : "no");
  if (mepa[0] == JD_NORMAL_MEPA && n > 0 && (size_t)n < sizeof text)
    std::snprintf(text + n, sizeof text - (size_t)n,
                  " normal_law mepa mepa_exponent %.17g mepa_plastic_depth %.17g", mepa[1], mepa[2]);
  return text;
}

/* ---- per atom: force and torque ---- */

int FixJdemRestart::pack_restart(int i, double *buf) {
  buf[0] = 1 + SAVED;
  for (int d = 0; d < 3; d++) {
    buf[1 + d] = atom->f[i][d];
    buf[4 + d] = atom->torque[i][d];
  }
  return 1 + SAVED;
}

void FixJdemRestart::unpack_restart(int nlocal, int nth) {
  if (jdem_stored_restart_len(lmp, nlocal, nth) != SAVED)
    error->one(FLERR, "fix jdem_restart (jdem/restart): the restart file's per-atom record has "
                      "another length: continue the run with the version that wrote it");
  jdem_unpack_restart(lmp, this, nlocal, nth);
}

void FixJdemRestart::grow_arrays(int nmax) {
  memory->grow(saved, nmax, SAVED, "jdem/restart:saved");
  for (int i = nmax_saved; i < nmax; i++)
    for (int k = 0; k < SAVED; k++) saved[i][k] = 0.0;
  nmax_saved = nmax;
}

void FixJdemRestart::copy_arrays(int i, int j, int) {
  for (int k = 0; k < SAVED; k++) saved[j][k] = saved[i][k];
}

int FixJdemRestart::pack_exchange(int i, double *buf) {
  for (int k = 0; k < SAVED; k++) buf[k] = saved[i][k];
  return SAVED;
}

int FixJdemRestart::unpack_exchange(int nlocal, double *buf) {
  for (int k = 0; k < SAVED; k++) saved[nlocal][k] = buf[k];
  return SAVED;
}

double FixJdemRestart::memory_usage() { return (double)nmax_saved * SAVED * sizeof(double); }
