/* jdem_restart.cpp — see jdem_restart.h.  Also the interposed WriteRestart::write and
 * Force::create_pair (libliggghts calls them through its PLT, as Output::add_dump in main.cpp). */
#include "jdem_restart.h"

#include <dlfcn.h>
#include <mpi.h>

#include <cmath>
#include <cstring>
#include <map>

#include "atom.h"
#include "comm.h"
#include "error.h"
#include "fix.h"
#include "fix_contact_history.h"
#include "force.h"
#include "lammps.h"
#include "modify.h"
#include "write_restart.h"

#include "fix_jdem_restart.h"
#include "pair_gran_jiang.h"

namespace LAMMPS_NS {

/* ---- the state blocks ---- */

/* "jdem" and the block's version: a block without them is not ours */
static const double state_magic = 1785964909.0, state_version = 1.0;

void jdem_restart_write_state(LAMMPS *lmp, FILE *fp, const JdemRestartState &mine) {
  MPI_Comm world = lmp->world;
  int me = 0, nprocs = 1;
  MPI_Comm_rank(world, &me);
  MPI_Comm_size(world, &nprocs);
  const int nsums = (int)mine.sums.size(), ntail = (int)mine.tail.size();
  std::vector<double> sums((size_t)nprocs * nsums);
  std::vector<int> tails(nprocs), at(nprocs, 0);
  MPI_Gather(const_cast<double *>(mine.sums.data()), nsums, MPI_DOUBLE, sums.data(), nsums,
             MPI_DOUBLE, 0, world);
  MPI_Gather(const_cast<int *>(&ntail), 1, MPI_INT, tails.data(), 1, MPI_INT, 0, world);
  int total = 0;
  for (int r = 0; r < nprocs; r++) at[r] = total, total += tails[r];
  std::vector<double> tail(total > 0 ? total : 1);
  MPI_Gatherv(const_cast<double *>(mine.tail.data()), ntail, MPI_DOUBLE, tail.data(), tails.data(),
              at.data(), MPI_DOUBLE, 0, world);
  if (me != 0) return;
  std::vector<double> block;
  block.push_back(state_magic);
  block.push_back(state_version);
  block.push_back((double)mine.shared.size());
  block.push_back((double)nsums);
  block.push_back((double)nprocs);
  block.insert(block.end(), mine.shared.begin(), mine.shared.end());
  block.insert(block.end(), sums.begin(), sums.end());
  for (int r = 0; r < nprocs; r++) block.push_back((double)tails[r]);
  block.insert(block.end(), tail.begin(), tail.begin() + total);
  const int size = (int)(block.size() * sizeof(double));
  std::fwrite(&size, sizeof(int), 1, fp);
  std::fwrite(block.data(), sizeof(double), block.size(), fp);
}

JdemRestartState jdem_restart_read_state(LAMMPS *lmp, const char *buf, const std::string &who,
                                         size_t nshared, size_t nsums, size_t older_nshared) {
  const double *b = reinterpret_cast<const double *>(buf);
  if (older_nshared && b[2] == (double)older_nshared) nshared = older_nshared;
  if (b[0] != state_magic || b[1] != state_version || b[2] != (double)nshared ||
      b[3] != (double)nsums)
    lmp->error->all(FLERR, (who + ": the restart file holds this fix's state in another layout "
                                  "(written by another version of liggghts-jdem): continue the "
                                  "run with the version that wrote it").c_str());
  int me = 0, nprocs = 1;
  MPI_Comm_rank(lmp->world, &me);
  MPI_Comm_size(lmp->world, &nprocs);
  const int written_on = (int)b[4];
  JdemRestartState st;
  const double *p = b + 5;
  st.shared.assign(p, p + nshared);
  p += nshared;
  const double *sums = p, *tails = p + (size_t)written_on * nsums;
  const double *tail = tails + written_on;
  st.sums.assign(nsums, 0.0);
  size_t from = 0;
  for (int r = 0; r < written_on; r++) {
    const size_t n = (size_t)tails[r];
    const bool mine = written_on == nprocs ? r == me : me == 0;
    if (mine) {
      for (size_t k = 0; k < nsums; k++) st.sums[k] += sums[(size_t)r * nsums + k];
      st.tail.insert(st.tail.end(), tail + from, tail + from + n);
    }
    from += n;
  }
  return st;
}

double jdem_restart_peek_shared(const char *buf, size_t k) {
  const double *b = reinterpret_cast<const double *>(buf);
  if (b[0] != state_magic || b[1] != state_version || (double)k >= b[2]) return NAN;
  return b[5 + k];
}

/* ---- per-atom records ---- */

int jdem_pack_restart(Fix *fix, int i, double *buf) {
  const int n = fix->pack_exchange(i, buf + 1);
  buf[0] = n + 1;
  return n + 1;
}

/* atom->extra[nlocal] holds every fix's record in the file's order; record nth starts after
 * the lengths of the ones before */
static int record_start(LAMMPS *lmp, int nlocal, int nth) {
  double **extra = lmp->atom->extra;
  int m = 0;
  for (int k = 0; k < nth; k++) m += (int)extra[nlocal][m];
  return m;
}

int jdem_stored_restart_len(LAMMPS *lmp, int nlocal, int nth) {
  return (int)lmp->atom->extra[nlocal][record_start(lmp, nlocal, nth)] - 1;
}

void jdem_unpack_restart(LAMMPS *lmp, Fix *fix, int nlocal, int nth) {
  fix->unpack_exchange(nlocal, &lmp->atom->extra[nlocal][record_start(lmp, nlocal, nth) + 1]);
}

bool jdem_restart_resuming(LAMMPS *lmp) {
  for (int k = 0; k < lmp->modify->nfix; k++) {
    const FixJdemRestart *r = dynamic_cast<const FixJdemRestart *>(lmp->modify->fix[k]);
    if (r) return r->resuming();
  }
  return false;
}

/* ---- the fix states read from a file, before the fixes are defined again ---- */

/* Modify keeps them in protected members; access checks are waived in explicit template
 * instantiations (the idiom of main.cpp's fix map). */
template <typename Tag, typename Tag::type M>
struct RestartRob {
  friend typename Tag::type get(Tag) { return M; }
};
#define JDEM_MODIFY_MEMBER(Name, Type, member)            \
  struct Name {                                           \
    typedef Type Modify::*type;                           \
    friend type get(Name);                                \
  };                                                      \
  template struct RestartRob<Name, &Modify::member>;
JDEM_MODIFY_MEMBER(StoredGlobalId, char **, id_restart_global)
JDEM_MODIFY_MEMBER(StoredGlobalStyle, char **, style_restart_global)
JDEM_MODIFY_MEMBER(StoredGlobalState, char **, state_restart_global)
JDEM_MODIFY_MEMBER(StoredAtomId, char **, id_restart_peratom)
JDEM_MODIFY_MEMBER(StoredAtomStyle, char **, style_restart_peratom)
#undef JDEM_MODIFY_MEMBER

/* The stored global state of the first fix of `style`, or NULL. */
static const char *stored_state(Modify *modify, const char *style) {
  char **styles = modify->*get(StoredGlobalStyle());
  for (int i = 0; i < modify->nfix_restart_global; i++)
    if (std::strcmp(styles[i], style) == 0) return (modify->*get(StoredGlobalState()))[i];
  return NULL;
}

/* Renames the stored states of `style` so that no fix defined later picks them up. */
static void drop_stored(Modify *modify, const char *style) {
  char **ids[2] = {modify->*get(StoredGlobalId()), modify->*get(StoredAtomId())};
  char **styles[2] = {modify->*get(StoredGlobalStyle()), modify->*get(StoredAtomStyle())};
  const int n[2] = {modify->nfix_restart_global, modify->nfix_restart_peratom};
  for (int list = 0; list < 2; list++)
    for (int i = 0; i < n[list]; i++) {
      if (std::strcmp(styles[list][i], style) != 0) continue;
      const std::string dropped = std::string("dropped ") + ids[list][i];
      delete[] ids[list][i];
      ids[list][i] = new char[dropped.size() + 1];
      std::strcpy(ids[list][i], dropped.c_str());
    }
}

void jdem_restart_warn_unclaimed_motion(LAMMPS *lmp) {
  Modify *modify = lmp->modify;
  char **ids = modify->*get(StoredGlobalId());
  char **styles = modify->*get(StoredGlobalStyle());
  for (int i = 0; i < modify->nfix_restart_global; i++) {
    if (std::strcmp(styles[i], "move/mesh") != 0) continue;
    const int k = modify->find_fix(ids[i]);
    if (k >= 0 && std::strcmp(modify->fix[k]->style, "move/mesh") == 0) continue;
    lmp->error->warning(FLERR, (std::string("read_restart: the restart file holds the motion of fix ") +
                                ids[i] + " (move/mesh), which this script does not define before "
                                "its first run: that mesh stays where the file put it").c_str());
  }
}

void jdem_restart_check_pair_style(LAMMPS *lmp, const char *style, int history_len) {
  const bool gran_jiang = std::strcmp(style, "gran/jiang") == 0;
  Modify *modify = lmp->modify;
  const char *history = stored_state(modify, "contacthistory");
  const char *ours = stored_state(modify, "jdem/restart");
  if (!history) return; /* no file read, or one without contacts */
  const int file_len = (int)reinterpret_cast<const double *>(history)[0];
  if (gran_jiang && ours) {
    const std::string file = FixJdemRestart::describe_pair_options(lmp, ours);
    if (file_len != history_len) {
      char text[160];
      std::snprintf(text, sizeof text, " (%d values of history per contact); this pair_style "
                    "keeps %d: ", file_len, history_len);
      lmp->error->all(FLERR, ("pair_style gran/jiang: the restart file was written with "
                              "pair_style gran/jiang " + file + text + "give the rolling, "
                              "energy and normal_law options of the run that wrote it").c_str());
    }
    return;
  }
  if (!gran_jiang && !ours) return; /* LIGGGHTS' own file for LIGGGHTS' own pair style */
  const std::string writer = ours ? "pair_style gran/jiang" : "LIGGGHTS' own pair_style gran";
  const std::string reader = std::strcmp(style, "gran") == 0 ? "LIGGGHTS' own pair_style gran"
                                                             : std::string("pair_style ") + style;
  lmp->error->warning(FLERR, ("read_restart: the contact history in the restart file belongs to " +
                              writer + ", which " + reader + " cannot continue: every contact "
                              "starts from zero history (positions, velocities and the other "
                              "fixes' states continue)").c_str());
  drop_stored(modify, "contacthistory");
  drop_stored(modify, "jdem/restart");
}

/* ---- interposed library functions ---- */

/* Looks up the library's definition of an interposed function. */
static void *library_function(Error *error, const char *symbol) {
  void *sym = dlsym(RTLD_NEXT, symbol);
  if (!sym) error->all(FLERR, (std::string("liggghts-jdem: cannot find libliggghts' ") + symbol).c_str());
  return sym;
}

/* The file names the pair "gran/jiang" (our pair presents itself as "gran" during a run: see
 * pair_gran_jiang.h), so that read_restart creates ours.  `restart N` writes after the step's
 * forces, when the contact history in the neighbour lists is newer than fix contacthistory's
 * copy, which the file stores: bring the copy up to date first (what write_restart's own
 * set-up does; nothing when the copy is current). */
void WriteRestart::write(char *file) {
  typedef void (*Write)(WriteRestart *, char *);
  static Write original = NULL;
  if (!original) {
    void *sym = library_function(error, "_ZN9LAMMPS_NS12WriteRestart5writeEPc");
    std::memcpy(&original, &sym, sizeof original);
  }
  PairGranJiang *pair = dynamic_cast<PairGranJiang *>(force->pair);
  if (!pair) {
    original(this, file);
    return;
  }
  for (int k = 0; k < modify->nfix; k++) {
    FixContactHistory *history = dynamic_cast<FixContactHistory *>(modify->fix[k]);
    if (history && std::strcmp(history->style, "contacthistory") == 0) history->setup_pre_exchange();
  }
  char *presented = force->pair_style;
  char recorded[] = "gran/jiang";
  force->pair_style = recorded;
  original(this, file);
  force->pair_style = presented;
}

/* pair_style of LIGGGHTS' own styles after read_restart of our file (pair_style gran/jiang
 * checks the file in its settings). */
void Force::create_pair(const char *style, const char *suffix) {
  typedef void (*Create)(Force *, const char *, const char *);
  static Create original = NULL;
  if (!original) {
    void *sym = library_function(error, "_ZN9LAMMPS_NS5Force11create_pairEPKcS2_");
    std::memcpy(&original, &sym, sizeof original);
  }
  if (std::strcmp(style, "gran/jiang") != 0) jdem_restart_check_pair_style(lmp, style, 0);
  original(this, style, suffix);
}

}  // namespace LAMMPS_NS
