/* fix_bond_jiang.cpp — see fix_bond_jiang.h.  Glue only: bookkeeping of LIGGGHTS around
 * jd_bond() (kernel/jdem_bond.h). */
#include "fix_bond_jiang.h"

#include "jdem_laws.h"

#include <mpi.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <map>
#include <sstream>

#include "atom.h"
#include "comm.h"
#include "domain.h"
#include "error.h"
#include "force.h"
#include "group.h"
#include "memory.h"
#include "modify.h"
#include "neighbor.h"
#include "output.h"
#include "dump.h"
#include "neigh_list.h"
#include "pair.h"
#include "update.h"

#include "dump_h5md_jdem.h"
#include "jdem_input_file.h"
#include "jdem_observables.h"
#include "jdem_restart.h"

using namespace LAMMPS_NS;
using namespace FixConst;

static_assert(sizeof(jd_bond_state) == JD_BOND_STATE_LEN * sizeof(double),
              "jd_bond_state must be JD_BOND_STATE_LEN doubles");
static_assert(sizeof(jd_bond_section) % sizeof(double) == 0, "jd_bond_section must be doubles");

FixBondJiang::FixBondJiang(LAMMPS *lmp, int narg, char **arg)
    : Fix(lmp, narg, arg), e_elastic_now(0.0), e_damp_cum(0.0), e_broken_cum(0.0), max_bonds(12),
      file_read(false), rules_done_at(-1), record(true), nmax_b(0), nbond(NULL), partner(NULL),
      bstate(NULL), nmax_ghost(0), fghost(NULL), reverse_len(6) {
  const char *usage =
      "Illegal fix bond/jiang command: fix ID group bond/jiang kn KN kt KT sigma_c S tau_c T "
      "lambda L [damping GAMMA] [bending I|J_literal] [max_bonds N] [file FILE] "
      "[rule K step S group GROUP max_gap X] ...";
  std::memset(&params, 0, sizeof params);
  params.bending = JD_BOND_BEND_I;
  bool seen[5] = {false, false, false, false, false};
  for (int iarg = 3; iarg < narg; iarg += 2) {
    if (iarg + 1 >= narg) error->all(FLERR, usage);
    const std::string k = arg[iarg], val = arg[iarg + 1];
    if (k == "rule") {
      if (iarg + 8 > narg || std::strcmp(arg[iarg + 2], "step") != 0 ||
          std::strcmp(arg[iarg + 4], "group") != 0 || std::strcmp(arg[iarg + 6], "max_gap") != 0)
        error->all(FLERR, "fix bond/jiang: rule K step S group GROUP max_gap X");
      Rule r;
      r.index = force->inumeric(FLERR, arg[iarg + 1]);
      r.step = (bigint)force->inumeric(FLERR, arg[iarg + 3]);
      const int igroup = group->find(arg[iarg + 5]);
      if (igroup < 0) error->all(FLERR, (std::string("fix bond/jiang: rule: no group '") + arg[iarg + 5] + "'").c_str());
      r.groupbit = group->bitmask[igroup];
      r.max_gap = force->numeric(FLERR, arg[iarg + 7]);
      if (r.index < 0 || r.step < 0 || !(r.max_gap >= 0.0))
        error->all(FLERR, "fix bond/jiang: rule needs K >= 0, step S >= 0 and max_gap X >= 0");
      rules.push_back(r);
      iarg += 6;
      continue;
    }
    if (k == "kn") params.kn = force->numeric(FLERR, arg[iarg + 1]), seen[0] = true;
    else if (k == "kt") params.kt = force->numeric(FLERR, arg[iarg + 1]), seen[1] = true;
    else if (k == "sigma_c") params.sigma_c = val == "inf" ? INFINITY : force->numeric(FLERR, arg[iarg + 1]), seen[2] = true;
    else if (k == "tau_c") params.tau_c = val == "inf" ? INFINITY : force->numeric(FLERR, arg[iarg + 1]), seen[3] = true;
    else if (k == "lambda") params.lambda = force->numeric(FLERR, arg[iarg + 1]), seen[4] = true;
    else if (k == "damping") params.gamma = force->numeric(FLERR, arg[iarg + 1]);
    else if (k == "bending") {
      if (val == "I") params.bending = JD_BOND_BEND_I;
      else if (val == "J_literal") params.bending = JD_BOND_BEND_J_LITERAL;
      else error->all(FLERR, "fix bond/jiang: bending must be I or J_literal");
    } else if (k == "max_bonds") max_bonds = force->inumeric(FLERR, arg[iarg + 1]);
    else if (k == "file") bond_file = val;
    else error->all(FLERR, ("fix bond/jiang: unknown keyword '" + k + "'; " + usage).c_str());
  }
  for (int s = 0; s < 5; s++)
    if (!seen[s]) error->all(FLERR, (std::string("fix bond/jiang: kn, kt, sigma_c, tau_c and lambda are required; ") + usage).c_str());
  if (!(params.kn >= 0.0) || !(params.kt >= 0.0) || std::isinf(params.kn) || std::isinf(params.kt))
    error->all(FLERR, "fix bond/jiang: kn and kt must be finite and >= 0 [N/m^3] (0: the bond carries no load)");
  if (!(params.sigma_c > 0.0) || !(params.tau_c > 0.0))
    error->all(FLERR, "fix bond/jiang: sigma_c and tau_c must be > 0 [Pa] (inf: unbreakable)");
  if (!(params.lambda > 0.0)) error->all(FLERR, "fix bond/jiang: lambda must be > 0");
  if (!(params.gamma >= 0.0)) error->all(FLERR, "fix bond/jiang: damping must be >= 0");
  /* Comm::exchange leaves room for about 1000 doubles beyond an atom's own: stay well inside */
  const int slots_max = 499 / (1 + REC_LEN);
  if (max_bonds < 1 || max_bonds > slots_max) {
    char msg[96];
    std::snprintf(msg, sizeof msg, "fix bond/jiang: max_bonds must be between 1 and %d", slots_max);
    error->all(FLERR, msg);
  }
  if (!atom->tag_enable || atom->map_style == 0)
    error->all(FLERR, "fix bond/jiang needs atom IDs and `atom_modify map array` (or hash)");
  if (!atom->radius_flag || !atom->rmass_flag || !atom->omega_flag || !atom->torque_flag)
    error->all(FLERR, "fix bond/jiang requires atom_style granular (sphere)");

  features = 0u; /* set by init() */
  nbroken[0] = nbroken[1] = 0.0;
  scalar_flag = vector_flag = 1;
  size_vector = 3;
  global_freq = 1;
  extscalar = extvector = 0;
  create_attribute = 1;
  comm_reverse = 6;
  restart_global = restart_peratom = 1; /* jdem_restart.h */
  grow_arrays(atom->nmax);
  atom->add_callback(0);
  atom->add_callback(1);
}

FixBondJiang::~FixBondJiang() {
  atom->delete_callback(id, 0);
  atom->delete_callback(id, 1);
  memory->destroy(nbond);
  memory->destroy(partner);
  memory->destroy(bstate);
  memory->destroy(fghost);
}

int FixBondJiang::setmask() { return PRE_NEIGHBOR | POST_FORCE; }

/* At every neighbour rebuild, after the ghosts were acquired: each bond shorter than the ghost
 * cutoff has its partner as a ghost until the next rebuild.  Collective, so that every rank
 * stops with the same message (and the dumps keep their files). */
void FixBondJiang::check_reach() {
  double **x = atom->x;
  const double cut = std::fmin(comm->cutghost[0], std::fmin(comm->cutghost[1], comm->cutghost[2]));
  struct { double ratio; int rank; } mine = {0.0, comm->me}, worst;
  int tags[2] = {0, 0};
  double len = 0.0;
  for (int i = 0; i < atom->nlocal; i++)
    for (int k = 0; k < nbond[i]; k++) {
      int j = atom->map(partner[i][k]);
      double L = INFINITY; /* no image of the partner here: beyond any cutoff */
      if (j >= 0) {
        j = domain->closest_image(i, j);
        const double d[3] = {x[j][0] - x[i][0], x[j][1] - x[i][1], x[j][2] - x[i][2]};
        L = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
      }
      if (L / cut > mine.ratio) {
        mine.ratio = L / cut;
        tags[0] = atom->tag[i];
        tags[1] = partner[i][k];
        len = L;
      }
    }
  MPI_Allreduce(&mine, &worst, 1, MPI_DOUBLE_INT, MPI_MAXLOC, world);
  if (worst.ratio < 1.0) return;
  MPI_Bcast(tags, 2, MPI_INT, worst.rank, world);
  MPI_Bcast(&len, 1, MPI_DOUBLE, worst.rank, world);
  char msg[400];
  std::snprintf(msg, sizeof msg, "fix bond/jiang: step " BIGINT_FORMAT ": bond %d-%d is %.9g m long, not within "
                "the ghost cutoff %g m that keeps bonded partners visible on every rank; raise it with "
                "`communicate single vel yes cutoff X`", update->ntimestep, tags[0], tags[1], len, cut);
  error->all(FLERR, msg);
}

void FixBondJiang::setup_pre_neighbor() { check_reach(); }

void FixBondJiang::pre_neighbor() { check_reach(); }

void FixBondJiang::init() {
  if (force->newton_pair)
    error->all(FLERR, "fix bond/jiang requires `newton off` (as LIGGGHTS' granular pair styles)");
  features = jd_bond_laws(params.gamma) | (jdem_wants_energy(lmp) ? (unsigned)JD_B_ENERGY : 0u);
  /* records only for a dump h5md/jdem that collects them */
  record = false;
  for (int k = 0; k < output->ndump; k++)
    if (std::strcmp(output->dump[k]->style, "h5md/jdem") == 0) record = true;
  if (!rules.empty() && !force->pair)
    error->all(FLERR, "fix bond/jiang: rules need a pair style (its neighbour list gives the candidates)");
  double rmax = 0.0, rmax_all = 0.0;
  for (int i = 0; i < atom->nlocal; i++) rmax = std::fmax(rmax, atom->radius[i]);
  MPI_Allreduce(&rmax, &rmax_all, 1, MPI_DOUBLE, MPI_MAX, world);
  for (size_t r = 0; r < rules.size(); r++)
    if (rules[r].max_gap * rmax_all > neighbor->skin) {
      char msg[256];
      std::snprintf(msg, sizeof msg, "fix bond/jiang: rule %d: max_gap x the largest radius (%g m) exceeds the "
                    "neighbour skin %g m, so candidate pairs could be missed; raise the skin",
                    rules[r].index, rules[r].max_gap * rmax_all, neighbor->skin);
      error->all(FLERR, msg);
    }
}

/* Explicit bonds are formed at the first set-up; the set-up evaluation does not advance the
 * bond states (as gran/jiang's contact history). */
void FixBondJiang::setup(int vflag) {
  if (jdem_restart_resuming(lmp)) return; /* the bonds read from the file stand */
  if (!file_read && !bond_file.empty()) {
    read_bond_file(bond_file.c_str());
    check_reach(); /* setup_pre_neighbor ran before these bonds existed */
  }
  file_read = true;
  form_due();
  compute(false);
}

void FixBondJiang::post_force(int vflag) {
  form_due();
  compute(true);
}

/* The rules due at this step, once (a run's set-up repeats the last step of the previous run). */
void FixBondJiang::form_due() {
  if (update->ntimestep == rules_done_at) return;
  rules_done_at = update->ntimestep;
  for (size_t r = 0; r < rules.size(); r++)
    if (rules[r].step == update->ntimestep) form_by_rule(rules[r]);
}

/* ---------------------------------------------------------------------------------------- */
/* Forming bonds.                                                                              */

bool FixBondJiang::bonded(int i, int tag_b) const {
  for (int k = 0; k < nbond[i]; k++)
    if (partner[i][k] == tag_b) return true;
  return false;
}

/* A pair holds at most one bond, of any type (docs/scenes.md). */
bool FixBondJiang::bonded_anywhere(int i, int tag_b) const {
  for (int k = 0; k < modify->nfix; k++) {
    const FixBondJiang *b = dynamic_cast<const FixBondJiang *>(modify->fix[k]);
    if (b && b->bonded(i, tag_b)) return true;
  }
  return false;
}

/* Store a new bond between local atom i (the lower id) and atom j (local or ghost) and record
 * it; false when i already holds max_bonds bonds of this type. */
bool FixBondJiang::add_bond(int i, int j, int rule) { return add_bond_to(i, atom->tag[j], rule); }

bool FixBondJiang::add_bond_to(int i, int partner_tag, int rule) {
  if (nbond[i] >= max_bonds) return false;
  const int k = nbond[i]++;
  partner[i][k] = partner_tag;
  Formed fr = {update->ntimestep, rule, atom->tag[i], partner_tag};
  if (record) formed.push_back(fr);
  jd_bond_state fresh;
  jd_bond_form(&fresh);
  std::memcpy(state(i, k), &fresh, sizeof fresh);
  return true;
}

static void too_many(Error *error, int tag, int max_bonds) {
  char msg[256];
  std::snprintf(msg, sizeof msg, "fix bond/jiang: atom %d would have more than %d bonds (raise max_bonds)",
                tag, max_bonds);
  error->one(FLERR, msg);
}

void FixBondJiang::form_inlet_bond(int i, int partner_tag) {
  if (!add_bond_to(i, partner_tag, -1)) too_many(error, atom->tag[i], max_bonds);
}

/* Rank 0 reads the file and broadcasts the pairs; the rank owning the lower id stores each. */
void FixBondJiang::read_bond_file(const char *path) {
  std::vector<int> pairs;
  int nbad = 0;
  char msg[512] = "";
  if (comm->me == 0) {
    std::ifstream in;
    std::string why = jdem_open_input("fix bond/jiang: bond file", path, in);
    std::map<std::pair<long, long>, int> seen; /* pair -> line */
    std::string line;
    int lineno = 1;
    for (; why.empty() && std::getline(in, line); lineno++) {
      why = jdem_text_line("fix bond/jiang: bond file", path, lineno, line);
      if (!why.empty()) break;
      const size_t hash = line.find('#');
      if (hash != std::string::npos) line.erase(hash);
      std::istringstream ls(line);
      long a, b;
      std::string rest;
      if (!(ls >> a)) continue; /* blank or comment line */
      if (!(ls >> b) || (ls >> rest) || a < 1 || b < 1 || a == b || a > atom->map_tag_max ||
          b > atom->map_tag_max) {
        std::snprintf(msg, sizeof msg,
                      "fix bond/jiang: %s line %d: expected two different atom ids between 1 and %d",
                      path, lineno, atom->map_tag_max);
        nbad = 1;
        break;
      }
      const std::pair<long, long> key(std::min(a, b), std::max(a, b));
      if (seen.count(key)) {
        std::snprintf(msg, sizeof msg, "fix bond/jiang: %s line %d: the bond %ld-%ld is listed twice "
                      "(first on line %d)", path, lineno, key.first, key.second, seen[key]);
        nbad = 1;
        break;
      }
      seen[key] = lineno;
      pairs.push_back((int)std::min(a, b));
      pairs.push_back((int)std::max(a, b));
    }
    if (why.empty() && !nbad && pairs.empty())
      why = std::string("fix bond/jiang: bond file ") + path + ": holds no bonds (lines \"ID_A ID_B\")";
    if (!why.empty() && !nbad) {
      std::snprintf(msg, sizeof msg, "%s", why.c_str());
      nbad = 1;
    }
  }
  jdem_share_input(lmp, nbad, msg, sizeof msg, pairs);
  const int n = (int)pairs.size();

  /* every id must exist somewhere (each atom is owned by exactly one rank) */
  int found_mine = 0;
  for (int p = 0; p < n; p += 2) {
    const int ia = atom->map(pairs[p]), ib = atom->map(pairs[p + 1]);
    if (ia >= 0 && ia < atom->nlocal) found_mine++;
    if (ib >= 0 && ib < atom->nlocal) found_mine++;
    if (ia >= 0 && ia < atom->nlocal) {
      if (bonded_anywhere(ia, pairs[p + 1])) {
        std::snprintf(msg, sizeof msg, "fix bond/jiang: %s: atoms %d and %d are bonded twice", path,
                      pairs[p], pairs[p + 1]);
        error->one(FLERR, msg);
      }
      if (ib < 0) { /* not even a ghost here: farther than the ghost cutoff */
        std::snprintf(msg, sizeof msg, "fix bond/jiang: %s: bond %d-%d is longer than the ghost cutoff; "
                      "raise it with `communicate single vel yes cutoff X`", path, pairs[p], pairs[p + 1]);
        error->one(FLERR, msg);
      }
      if (!add_bond(ia, ib, -1)) too_many(error, pairs[p], max_bonds);
    }
  }
  int found = 0;
  MPI_Allreduce(&found_mine, &found, 1, MPI_INT, MPI_SUM, world);
  if (found != n) {
    std::snprintf(msg, sizeof msg, "fix bond/jiang: %s names atom ids that do not exist", path);
    error->all(FLERR, msg);
  }
}

/* The rule's pair test (docs/scenes.md): both atoms in the group, not bonded yet, surface gap
 * |x_b - x_a| - R_a - R_b <= max_gap min(R_a, R_b).  The pair style's neighbour list holds each
 * local pair once and each local-ghost pair on both ranks; the owner of the lower id forms it. */
void FixBondJiang::form_by_rule(const Rule &r) {
  NeighList *list = force->pair->list;
  if (!list) error->all(FLERR, "fix bond/jiang: rules need a pair style with a neighbour list (gran/jiang)");
  double **x = atom->x;
  const double *radius = atom->radius;
  const int *tag = atom->tag, *mask = atom->mask;
  const int nlocal = atom->nlocal;
  for (int ii = 0; ii < list->inum; ii++) {
    const int i = list->ilist[ii];
    if (!(mask[i] & r.groupbit)) continue;
    for (int jj = 0; jj < list->numneigh[i]; jj++) {
      const int j = list->firstneigh[i][jj] & NEIGHMASK;
      if (!(mask[j] & r.groupbit)) continue;
      const int lo = tag[i] < tag[j] ? i : j, hi = lo == i ? j : i;
      if (lo >= nlocal) continue; /* the other rank forms it */
      const double d[3] = {x[hi][0] - x[lo][0], x[hi][1] - x[lo][1], x[hi][2] - x[lo][2]};
      const double gap = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]) - radius[lo] - radius[hi];
      if (!(gap <= r.max_gap * std::fmin(radius[lo], radius[hi]))) continue;
      if (bonded_anywhere(lo, tag[hi])) continue;
      if (!add_bond(lo, hi, r.index)) too_many(error, tag[lo], max_bonds);
    }
  }
}

/* ---------------------------------------------------------------------------------------- */
/* Evaluating the bonds.                                                                       */

void FixBondJiang::compute(bool commit) {
#define JD_BOND_LOOP(b) \
  case (b): loop<(b)>(commit); break;
  switch (features) {
    JD_BOND_LAW_SETS(JD_BOND_LOOP)
    default: break;
  }
#undef JD_BOND_LOOP
}

/* Atoms ahead whose bond records the loop prefetches.  The records sit in per-atom rows of
 * max_bonds slots, mostly empty, so the hardware's stream prefetchers miss them
 * (docs/performance.md; 2, 8 and 16 ahead did the same as 4). */
enum { PREFETCH_AHEAD = 4 };
/* Every bond stored on a local atom, in storage order.  commit false: the set-up evaluation. */
template <unsigned F>
void FixBondJiang::loop(bool commit) {
  double **x = atom->x, **v = atom->v, **f = atom->f;
  double **omega = atom->omega, **torque = atom->torque;
  const double *radius = atom->radius, *rmass = atom->rmass;
  const int *tag = atom->tag;
  const int nlocal = atom->nlocal, nall = nlocal + atom->nghost;
  /* the set-up evaluation (LIGGGHTS advances no history then) is the kernel's dt = 0 call: the
   * stored force, and the energy reference of the first step */
  const double dt = commit ? update->dt : 0.0;
  const bigint step = update->ntimestep;
  const double time = update->atime + (double)(step - update->atimestep) * update->dt;
  const bool periodic = domain->xperiodic || domain->yperiodic || domain->zperiodic;

  if (nall > nmax_ghost) {
    nmax_ghost = atom->nmax;
    memory->destroy(fghost);
    memory->create(fghost, nmax_ghost, 6, "bond/jiang:fghost");
  }
  for (int i = nlocal; i < nall; i++)
    for (int d = 0; d < 6; d++) fghost[i][d] = 0.0;

  double e_el = 0.0, e_damp = 0.0, e_broken = 0.0;
  for (int i = 0; i < nlocal; i++) {
    if (i + PREFETCH_AHEAD < nlocal) {
      const double *r = bstate[i + PREFETCH_AHEAD];
      for (int q = 0; q < nbond[i + PREFETCH_AHEAD] * REC_LEN; q += 8) __builtin_prefetch(r + q, 1);
    }
    for (int k = 0; k < nbond[i];) {
      int j = atom->map(partner[i][k]);
      if (j < 0) {
        char msg[256];
        std::snprintf(msg, sizeof msg, "fix bond/jiang: step " BIGINT_FORMAT ": the partner %d of atom %d "
                      "is neither on this rank nor a ghost", step, partner[i][k], tag[i]);
        error->one(FLERR, msg);
      }
      if (periodic) j = domain->closest_image(i, j);
      jd_bond_geom g = jd_bond_geom(); /* zeroed: at -O3 GCC cannot see that error->one ends */
      if (!jd_bond_geom_spheres(x[i], radius[i], x[j], radius[j], &g)) {
        char msg[160];
        std::snprintf(msg, sizeof msg, "fix bond/jiang: step " BIGINT_FORMAT ": bonded atoms %d and %d "
                      "are at the same position", step, tag[i], partner[i][k]);
        error->one(FLERR, msg);
      }
      g.sec = jd_bond_section_of(params.lambda, radius[i], radius[j]);
      g.m_eff = g.i_eff = 0.0; /* read only by the dashpots */
      if (F & JD_B_DAMPING)
        jd_bond_set_masses(&g, rmass[i], rmass[j], jd_sphere_inertia(rmass[i], radius[i]),
                           jd_sphere_inertia(rmass[j], radius[j]));
      jd_kinematics kin;
      for (int d = 0; d < 3; d++) {
        kin.va[d] = v[i][d];
        kin.wa[d] = omega[i][d];
        kin.vb[d] = v[j][d];
        kin.wb[d] = omega[j][d];
      }
      jd_bond_state st;
      std::memcpy(&st, state(i, k), sizeof st);
      jd_bond_result out;
      const int mode = jd_bond(F, &params, &g, &kin, dt, &st, &out);
      if (mode != JD_BOND_INTACT && commit) {
        Event ev;
        ev.step = step;
        ev.time = time;
        ev.tag_a = tag[i];
        ev.tag_b = partner[i][k];
        ev.mode = mode;
        for (int d = 0; d < 3; d++) {
          ev.x[d] = x[i][d] + g.ra[d];
          ev.n[d] = g.n[d];
        }
        ev.r = out;
        if (record) events.push_back(ev);
        nbroken[mode == JD_BOND_BROKE_TENSION ? 0 : 1] += 1.0;
        jd_bond_harvest(&st, &e_damp, &e_broken);
        /* remove the slot, keeping the others in order (the force summation order) */
        for (int m = k + 1; m < nbond[i]; m++) {
          partner[i][m - 1] = partner[i][m];
          std::memcpy(state(i, m - 1), state(i, m), REC_LEN * sizeof(double));
        }
        nbond[i]--;
        continue;
      }
      jd_bond_harvest(&st, &e_damp, &e_broken); /* every step, as gran/jiang does */
      std::memcpy(state(i, k), &st, sizeof st);
      k++;
      if (mode != JD_BOND_INTACT) continue; /* set-up evaluation of a bond that would fail */
      if (F & JD_B_ENERGY) e_el += st.u_prev;
      for (int d = 0; d < 3; d++) {
        f[i][d] -= out.f[d];
        torque[i][d] += out.ta[d];
      }
      double *fj = j < nlocal ? f[j] : fghost[j], *tj = j < nlocal ? torque[j] : fghost[j] + 3;
      for (int d = 0; d < 3; d++) {
        fj[d] += out.f[d];
        tj[d] += out.tb[d];
      }
    }
  }
  if (comm->nprocs > 1 || periodic) comm->reverse_comm_fix(this);
  e_elastic_now = e_el;
  if (commit) {
    e_damp_cum += e_damp;
    e_broken_cum += e_broken;
  }
}

/* Comm::reverse_comm_fix takes the return value as the datums per atom (at most comm_reverse). */
int FixBondJiang::pack_reverse_comm(int n, int first, double *buf) {
  int m = 0;
  for (int i = first; i < first + n; i++) {
    if (reverse_len == 1) buf[m++] = w2[i];
    else
      for (int d = 0; d < 6; d++) buf[m++] = fghost[i][d];
  }
  return reverse_len;
}

void FixBondJiang::unpack_reverse_comm(int n, int *list, double *buf) {
  double **f = atom->f, **torque = atom->torque;
  int m = 0;
  for (int i = 0; i < n; i++) {
    const int j = list[i];
    if (reverse_len == 1) {
      w2[j] += buf[m++];
      continue;
    }
    for (int d = 0; d < 3; d++) f[j][d] += buf[m++];
    for (int d = 0; d < 3; d++) torque[j][d] += buf[m++];
  }
}

double FixBondJiang::omega2_max() {
  double **x = atom->x;
  const double *radius = atom->radius, *rmass = atom->rmass;
  const int nlocal = atom->nlocal, nall = nlocal + atom->nghost, *mask = atom->mask;
  w2.assign(nall, 0.0);
  for (int i = 0; i < nlocal; i++) {
    for (int k = 0; k < nbond[i]; k++) {
      const int j = atom->map(partner[i][k]);
      if (j < 0) continue; /* check_reach reports it */
      const double d[3] = {x[j][0] - x[i][0], x[j][1] - x[i][1], x[j][2] - x[i][2]};
      const double wk = jd_bond_omega2_pair(&params, radius[i], radius[j], rmass[i], rmass[j],
                                            std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]));
      w2[i] += wk;
      w2[j] += wk;
    }
  }
  for (size_t r = 0; r < rules.size(); r++)
    for (int i = 0; i < nlocal; i++) {
      if (!(mask[i] & rules[r].groupbit)) continue;
      w2[i] += jd_bond_omega2_rule(&params, radius[i], rmass[i]);
    }
  reverse_len = 1;
  comm->reverse_comm_fix(this);
  reverse_len = 6;
  double mine = 0.0, all = 0.0;
  for (int i = 0; i < nlocal; i++) mine = std::fmax(mine, w2[i]);
  MPI_Allreduce(&mine, &all, 1, MPI_DOUBLE, MPI_MAX, world);
  return all;
}

/* ---------------------------------------------------------------------------------------- */
/* What the dump and the observables read.                                                     */

std::vector<FixBondJiang::Event> FixBondJiang::take_events() {
  std::vector<Event> out;
  out.swap(events);
  return out;
}

std::vector<FixBondJiang::Formed> FixBondJiang::take_formed() {
  std::vector<Formed> out;
  out.swap(formed);
  return out;
}

void FixBondJiang::local_bonds(std::vector<int> &pairs) const {
  for (int i = 0; i < atom->nlocal; i++)
    for (int k = 0; k < nbond[i]; k++) {
      pairs.push_back(atom->tag[i]);
      pairs.push_back(partner[i][k]);
    }
}

double FixBondJiang::held_elastic(int i) {
  double e = 0.0;
  for (int k = 0; k < nbond[i] && (features & JD_B_ENERGY); k++) {
    jd_bond_state st;
    std::memcpy(&st, state(i, k), sizeof st);
    e += st.u_prev;
  }
  return e;
}

double FixBondJiang::drop_partners(const std::vector<int> &gone) {
  double e = 0.0;
  for (int i = 0; i < atom->nlocal; i++)
    for (int k = 0; k < nbond[i];) {
      if (!std::binary_search(gone.begin(), gone.end(), partner[i][k])) {
        k++;
        continue;
      }
      jd_bond_state st;
      std::memcpy(&st, state(i, k), sizeof st);
      if (features & JD_B_ENERGY) e += st.u_prev;
      for (int m = k + 1; m < nbond[i]; m++) { /* the others keep their order */
        partner[i][m - 1] = partner[i][m];
        std::memcpy(state(i, m - 1), state(i, m), REC_LEN * sizeof(double));
      }
      nbond[i]--;
    }
  return e;
}

int FixBondJiang::local_count() const {
  int n = 0;
  for (int i = 0; i < atom->nlocal; i++) n += nbond[i];
  return n;
}

double FixBondJiang::compute_scalar() { return compute_vector(0); }

double FixBondJiang::compute_vector(int n) {
  const double mine = n == 0 ? (double)local_count() : nbroken[n - 1];
  double all = 0.0;
  MPI_Allreduce(&mine, &all, 1, MPI_DOUBLE, MPI_SUM, world);
  return all;
}

/* ---------------------------------------------------------------------------------------- */
/* Per-atom bonds that migrate with their atom.                                                */

void FixBondJiang::grow_arrays(int nmax) {
  memory->grow(nbond, nmax, "bond/jiang:nbond");
  memory->grow(partner, nmax, max_bonds, "bond/jiang:partner");
  memory->grow(bstate, nmax, max_bonds * REC_LEN, "bond/jiang:state");
  for (int i = nmax_b; i < nmax; i++) nbond[i] = 0;
  nmax_b = nmax;
}

void FixBondJiang::copy_arrays(int i, int j, int delflag) {
  nbond[j] = nbond[i];
  for (int k = 0; k < nbond[i]; k++) partner[j][k] = partner[i][k];
  std::memcpy(bstate[j], bstate[i], (size_t)nbond[i] * REC_LEN * sizeof(double));
}

void FixBondJiang::set_arrays(int i) { nbond[i] = 0; }

/* nbond, then per bond the partner id and the state (ids are exact in a double) */
int FixBondJiang::pack_exchange(int i, double *buf) {
  int m = 0;
  buf[m++] = nbond[i];
  for (int k = 0; k < nbond[i]; k++) {
    buf[m++] = partner[i][k];
    for (int s = 0; s < REC_LEN; s++) buf[m++] = bstate[i][k * REC_LEN + s];
  }
  return m;
}

int FixBondJiang::unpack_exchange(int nlocal, double *buf) {
  int m = 0;
  nbond[nlocal] = (int)buf[m++];
  for (int k = 0; k < nbond[nlocal]; k++) {
    partner[nlocal][k] = (int)buf[m++];
    for (int s = 0; s < REC_LEN; s++) bstate[nlocal][k * REC_LEN + s] = buf[m++];
  }
  return m;
}

double FixBondJiang::memory_usage() {
  return (double)nmax_b * (sizeof(int) + max_bonds * (sizeof(int) + REC_LEN * sizeof(double))) +
         (double)nmax_ghost * 6 * sizeof(double);
}

/* ---------------------------------------------------------------------------------------- */
/* Restart files (jdem_restart.h): whether the bond file was read and the rules applied, each
 * rank's energies and counts of broken bonds; per atom its bonds (the exchange record).       */

namespace {
enum { BOND_SHARED = 2, BOND_SUMS = 5 };
}

void FixBondJiang::write_restart(FILE *fp) {
  JdemRestartState st;
  st.shared.push_back(file_read ? 1.0 : 0.0);
  st.shared.push_back(jdem_restart_pack_i64(rules_done_at));
  const double sums[BOND_SUMS] = {e_elastic_now, e_damp_cum, e_broken_cum, nbroken[0], nbroken[1]};
  st.sums.assign(sums, sums + BOND_SUMS);
  /* rank 0: the particles ever bonded, as the first dump h5md/jdem (or the file read) knows them */
  std::vector<int> ever = ever_bonded_read;
  for (int k = 0; k < output->ndump; k++) {
    DumpH5mdJdem *d = dynamic_cast<DumpH5mdJdem *>(output->dump[k]);
    if (!d) continue;
    const std::vector<int> seen = d->ever_bonded_ids();
    ever.insert(ever.end(), seen.begin(), seen.end());
    break;
  }
  std::sort(ever.begin(), ever.end());
  ever.erase(std::unique(ever.begin(), ever.end()), ever.end());
  if (comm->me == 0) st.tail.assign(ever.begin(), ever.end());
  jdem_restart_write_state(lmp, fp, st);
}

void FixBondJiang::restart(char *buf) {
  const JdemRestartState st = jdem_restart_read_state(
      lmp, buf, std::string("fix ") + id + " (bond/jiang)", BOND_SHARED, BOND_SUMS);
  file_read = st.shared[0] != 0.0;
  rules_done_at = jdem_restart_unpack_i64(st.shared[1]);
  e_elastic_now = st.sums[0];
  e_damp_cum = st.sums[1];
  e_broken_cum = st.sums[2];
  nbroken[0] = st.sums[3];
  nbroken[1] = st.sums[4];
  ever_bonded_read.assign(st.tail.begin(), st.tail.end());
}

int FixBondJiang::pack_restart(int i, double *buf) { return jdem_pack_restart(this, i, buf); }

void FixBondJiang::unpack_restart(int nlocal, int nth) {
  const int len = jdem_stored_restart_len(lmp, nlocal, nth);
  if (len < 1 || (len - 1) % (1 + REC_LEN) != 0 || (len - 1) / (1 + REC_LEN) > max_bonds)
    error->one(FLERR, (std::string("fix ") + id + " (bond/jiang): an atom of the restart file "
                       "holds more bonds than max_bonds, or records of another length: give "
                       "the max_bonds of the run that wrote it").c_str());
  jdem_unpack_restart(lmp, this, nlocal, nth);
}

int FixBondJiang::size_restart(int i) { return 2 + nbond[i] * (1 + REC_LEN); }

int FixBondJiang::maxsize_restart() { return 2 + max_bonds * (1 + REC_LEN); }
