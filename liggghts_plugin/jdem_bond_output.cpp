/* jdem_bond_output.cpp — see jdem_bond_output.h. */
#include "jdem_bond_output.h"

#include <algorithm>
#include <cstdio>

#include "lammps.h"
#include "modify.h"

#include "fix_bond_jiang.h"
#include "fix_jdem_domain.h"
#include "h5md.h"

namespace LAMMPS_NS {

std::vector<double> jdem_gather_rows(MPI_Comm world, const std::vector<double> &mine) {
  int me = 0, nprocs = 1;
  MPI_Comm_rank(world, &me);
  MPI_Comm_size(world, &nprocs);
  const int n = (int)mine.size();
  std::vector<int> counts(nprocs), displs(nprocs);
  MPI_Gather(&n, 1, MPI_INT, counts.data(), 1, MPI_INT, 0, world);
  std::vector<double> all;
  int tot = 0;
  if (me == 0)
    for (int p = 0; p < nprocs; p++) {
      displs[p] = tot;
      tot += counts[p];
    }
  all.resize(me == 0 ? tot : 0);
  MPI_Gatherv(mine.empty() ? NULL : mine.data(), n, MPI_DOUBLE, all.empty() ? NULL : all.data(),
              counts.data(), displs.data(), MPI_DOUBLE, 0, world);
  return all;
}

namespace {

/* Sort rows of ncol doubles lexicographically on the first nkey columns. */
std::vector<double> sorted_rows(const std::vector<double> &rows, int ncol, int nkey) {
  const size_t n = rows.size() / ncol;
  std::vector<size_t> order(n);
  for (size_t i = 0; i < n; i++) order[i] = i;
  std::sort(order.begin(), order.end(), [&](size_t a, size_t b) {
    for (int c = 0; c < nkey; c++)
      if (rows[a * ncol + c] != rows[b * ncol + c]) return rows[a * ncol + c] < rows[b * ncol + c];
    return false;
  });
  std::vector<double> out;
  out.reserve(rows.size());
  for (size_t i : order) out.insert(out.end(), rows.begin() + i * ncol, rows.begin() + (i + 1) * ncol);
  return out;
}

int find_root(std::vector<int> &parent, int a) {
  while (parent[a] != a) a = parent[a] = parent[parent[a]];
  return a;
}

enum { F_STEP = 0, F_RULE, F_TYPE, F_A, F_B, F_N };
enum { E_STEP = 0, E_A, E_B, E_TIME, E_MODE, E_X, E_FN = E_X + 3, E_FT, E_MN, E_MT, E_SIG, E_TAU, E_N };

}  // namespace

int JdemBondOutput::write(LAMMPS *lmp, jd_h5md *h, char *err, size_t errlen) {
  std::vector<double> formed, events, intact;
  int type = 0;
  for (int k = 0; k < lmp->modify->nfix; k++) {
    FixBondJiang *b = dynamic_cast<FixBondJiang *>(lmp->modify->fix[k]);
    if (!b) continue;
    active_ = true;
    for (const FixBondJiang::Formed &f : b->take_formed()) {
      const double row[F_N] = {(double)f.step, (double)f.rule, (double)type, (double)f.tag_a, (double)f.tag_b};
      formed.insert(formed.end(), row, row + F_N);
    }
    for (const FixBondJiang::Event &e : b->take_events()) {
      const double row[E_N] = {(double)e.step, (double)e.tag_a, (double)e.tag_b, e.time, (double)e.mode,
                               e.x[0], e.x[1], e.x[2], e.r.fn, e.r.ft, e.r.mn, e.r.mt, e.r.sigma_max,
                               e.r.tau_max};
      events.insert(events.end(), row, row + E_N);
    }
    std::vector<int> pairs;
    b->local_bonds(pairs);
    intact.insert(intact.end(), pairs.begin(), pairs.end());
    type++;
  }
  if (!active_) return 0;
  MPI_Comm world = lmp->world;
  formed = jdem_gather_rows(world, formed);
  events = jdem_gather_rows(world, events);
  intact = jdem_gather_rows(world, intact);
  int me = 0;
  MPI_Comm_rank(world, &me);
  if (me != 0) return 0;
  mark_restored(lmp);

  formed = sorted_rows(formed, F_N, F_B + 1); /* step, rule, then (type), ids */
  std::vector<jd_h5md_bond> nb(formed.size() / F_N);
  for (size_t i = 0; i < nb.size(); i++) {
    const double *r = &formed[i * F_N];
    nb[i].id[0] = (int64_t)r[F_A];
    nb[i].id[1] = (int64_t)r[F_B];
    nb[i].type = (int32_t)r[F_TYPE];
    nb[i].formed_step = (int64_t)r[F_STEP];
  }
  if (jd_h5md_write_bonds(h, nb.size(), nb.data(), err, errlen) != 0) return -1;

  events = sorted_rows(events, E_N, E_B + 1); /* step, ids */
  std::vector<jd_h5md_bond_break> br(events.size() / E_N);
  for (size_t i = 0; i < br.size(); i++) {
    const double *r = &events[i * E_N];
    br[i].step = (int64_t)r[E_STEP];
    br[i].time = r[E_TIME];
    br[i].id[0] = (int64_t)r[E_A];
    br[i].id[1] = (int64_t)r[E_B];
    br[i].mode = (int32_t)r[E_MODE];
    for (int d = 0; d < 3; d++) br[i].position[d] = r[E_X + d];
    br[i].normal_force = r[E_FN];
    br[i].shear_force = r[E_FT];
    br[i].twisting_moment = r[E_MN];
    br[i].bending_moment = r[E_MT];
    br[i].sigma_max = r[E_SIG];
    br[i].tau_max = r[E_TAU];
  }
  if (jd_h5md_write_bond_breaks(h, br.size(), br.data(), err, errlen) != 0) return -1;

  std::vector<double> formed_pairs;
  for (const jd_h5md_bond &b : nb) {
    formed_pairs.push_back((double)b.id[0]);
    formed_pairs.push_back((double)b.id[1]);
  }
  count_intact(lmp, formed_pairs, intact);
  return 0;
}

void JdemBondOutput::count(LAMMPS *lmp) {
  std::vector<double> formed_pairs, intact;
  for (int k = 0; k < lmp->modify->nfix; k++) {
    FixBondJiang *b = dynamic_cast<FixBondJiang *>(lmp->modify->fix[k]);
    if (!b) continue;
    active_ = true;
    for (const FixBondJiang::Formed &f : b->pending_formed()) {
      formed_pairs.push_back((double)f.tag_a);
      formed_pairs.push_back((double)f.tag_b);
    }
    std::vector<int> pairs;
    b->local_bonds(pairs);
    intact.insert(intact.end(), pairs.begin(), pairs.end());
  }
  if (!active_) return;
  MPI_Comm world = lmp->world;
  formed_pairs = jdem_gather_rows(world, formed_pairs);
  intact = jdem_gather_rows(world, intact);
  int me = 0;
  MPI_Comm_rank(world, &me);
  if (me != 0) return;
  mark_restored(lmp);
  count_intact(lmp, formed_pairs, intact);
}

void JdemBondOutput::mark_restored(LAMMPS *lmp) {
  for (int k = 0; k < lmp->modify->nfix; k++) {
    FixBondJiang *b = dynamic_cast<FixBondJiang *>(lmp->modify->fix[k]);
    for (size_t i = 0; b && i < b->restored_ever_bonded().size(); i++) {
      const size_t id = (size_t)b->restored_ever_bonded()[i];
      if (id >= ever_bonded_.size()) ever_bonded_.resize(id + 1, 0);
      ever_bonded_[id] = 1;
    }
  }
}

std::vector<int> JdemBondOutput::ever_bonded_ids() const {
  std::vector<int> ids;
  for (size_t i = 0; i < ever_bonded_.size(); i++)
    if (ever_bonded_[i]) ids.push_back((int)i);
  return ids;
}

/* fragments: union-find over the ever-bonded particles along the intact bonds; a particle
 * deleted outside the domain (fix jdem/domain) is no longer one, as build/jdem counts them */
void JdemBondOutput::count_intact(LAMMPS *lmp, const std::vector<double> &formed_pairs,
                                  const std::vector<double> &intact) {
  for (const std::vector<double> *pairs : {&formed_pairs, &intact})
    for (double t : *pairs) {
      const size_t id = (size_t)t;
      if (id >= ever_bonded_.size()) ever_bonded_.resize(id + 1, 0);
      ever_bonded_[id] = 1;
    }
  for (int k = 0; k < lmp->modify->nfix; k++)
    if (const FixJdemDomain *d = dynamic_cast<FixJdemDomain *>(lmp->modify->fix[k]))
      for (int id : d->gone_ids())
        if ((size_t)id < ever_bonded_.size()) ever_bonded_[id] = 0;
  std::vector<int> parent(ever_bonded_.size());
  for (size_t i = 0; i < parent.size(); i++) parent[i] = (int)i;
  for (size_t p = 0; p + 1 < intact.size(); p += 2) {
    const int a = find_root(parent, (int)intact[p]), b = find_root(parent, (int)intact[p + 1]);
    if (a != b) parent[std::max(a, b)] = std::min(a, b);
  }
  size_t nfrag = 0;
  for (size_t i = 0; i < ever_bonded_.size(); i++)
    if (ever_bonded_[i] && find_root(parent, (int)i) == (int)i) nfrag++;
  bonds_ = (double)(intact.size() / 2);
  fragments_ = (double)nfrag;
}

}  // namespace LAMMPS_NS
