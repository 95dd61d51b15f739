/* fix_jdem_watchdog.cpp — see fix_jdem_watchdog.h.  Each check finds this rank's worst case,
 * then one MINLOC/MAXLOC reduction picks the global one and its owner broadcasts the details,
 * so that every rank builds the same message for error->all. */
#include "fix_jdem_watchdog.h"

#include <mpi.h>

#include <cmath>
#include <cstdint>
#include <cstdarg>
#include <cstdio>
#include <cstring>

#include "atom.h"
#include "comm.h"
#include "error.h"
#include "force.h"
#include "modify.h"
#include "output.h"
#include "update.h"

#include "fix_insert.h"

#include "dump_h5md_jdem.h"
#include "fix_jdem_domain.h"
#include "fix_jdem_inlet.h"
#include "fix_wall_jiang.h"
#include "jdem_observables.h"
#include "jdem_restart.h"
#include "jdem_stop.h"
#include "pair_gran_jiang.h"

using namespace LAMMPS_NS;

static std::string format(const char *fmt, ...) __attribute__((format(printf, 1, 2)));

/* LIGGGHTS keeps fix insert's compress_tags flag protected, with no accessor; a class derived
 * from it may name it ([class.protected]). */
namespace {
struct InsertPeek : FixInsert {
  using FixInsert::compress_flag;
};
}  // namespace

FixJdemWatchdog::FixJdemWatchdog(LAMMPS *lmp, int narg, char **arg)
    : Fix(lmp, narg, arg), energy_every(1), max_overlap(0.5), max_energy_jump(0.05),
      has_ref(false), ref(), ref_step(0), last_tag(0), inserted_energy(0.0), inserted_atoms(0.0) {
  if (narg < 4) error->all(FLERR, "Illegal fix jdem/watchdog command: fix ID group jdem/watchdog N [overlap F] [energy J|off]");
  energy_every = force->inumeric(FLERR, arg[3]);
  if (energy_every < 1) error->all(FLERR, "fix jdem/watchdog: N must be >= 1");
  for (int i = 4; i < narg; i += 2) {
    if (i + 1 >= narg) error->all(FLERR, "fix jdem/watchdog: keyword without a value");
    if (std::strcmp(arg[i], "energy") == 0 && std::strcmp(arg[i + 1], "off") == 0) {
      max_energy_jump = 0.0;
      continue;
    }
    const double value = force->numeric(FLERR, arg[i + 1]);
    if (!(value > 0.0)) error->all(FLERR, "fix jdem/watchdog: limits must be > 0 (energy: > 0 or off)");
    if (std::strcmp(arg[i], "overlap") == 0) max_overlap = value;
    else if (std::strcmp(arg[i], "energy") == 0) max_energy_jump = value;
    else error->all(FLERR, "fix jdem/watchdog: unknown keyword (valid: overlap, energy)");
  }
  nevery = 1; /* the cheap checks run every step; the energy check every energy_every */
  restart_global = 1; /* the energy account continues (jdem_restart.h) */
  scalar_flag = 1;    /* f_ID: the energy booked for fix insert/...'s atoms */
  global_freq = 1;
  extscalar = 0;
}

int FixJdemWatchdog::setmask() { return FixConst::END_OF_STEP; }

/* Hand the overlap limit to the force loops, which note what exceeds it as they go. */
void FixJdemWatchdog::init() {
  PairGranJiang *pair = dynamic_cast<PairGranJiang *>(force->pair);
  if (!pair) error->all(FLERR, "fix jdem/watchdog requires pair_style gran/jiang");
  pair->overlap_limit = max_overlap;
  inserts.clear();
  bool inlet = false;
  for (int k = 0; k < modify->nfix; k++) {
    FixInsert *ins = dynamic_cast<FixInsert *>(modify->fix[k]);
    if (ins && ins->*(&InsertPeek::compress_flag))
      error->all(FLERR, (std::string("fix jdem/watchdog cannot tell the atoms that fix ") + ins->id +
                         " inserts from the others: compress_tags yes renumbers every atom; use "
                         "compress_tags no, or energy off").c_str());
    if (ins) inserts.push_back(ins);
    inlet = inlet || dynamic_cast<FixJdemInlet *>(modify->fix[k]);
  }
  if (inlet && !inserts.empty())
    error->all(FLERR, "fix jdem/watchdog books the energy of fix jdem/inlet or of LIGGGHTS' fix "
                      "insert/..., not of both in one run: their new atoms' ids overlap");
  for (int k = 0; k < modify->nfix; k++) {
    FixWallJiang *w = dynamic_cast<FixWallJiang *>(modify->fix[k]);
    if (w) w->overlap_limit = max_overlap;
  }
}

void FixJdemWatchdog::setup(int) {
  note_last_tag();
  check();
}

/* Restart files: the energy account of the last check (the reference of the next one). */
namespace {
enum { WATCHDOG_SHARED = 11 };
}

void FixJdemWatchdog::write_restart(FILE *fp) {
  JdemRestartState st;
  const double terms[7] = {ref.kinetic, ref.rotational, ref.elastic, ref.gravitational,
                           ref.damping, ref.friction, ref.wall_work};
  st.shared.push_back(has_ref ? 1.0 : 0.0);
  st.shared.insert(st.shared.end(), terms, terms + 7);
  st.shared.push_back(jdem_restart_pack_i64(ref_step));
  st.shared.push_back(inserted_energy);
  st.shared.push_back(inserted_atoms);
  jdem_restart_write_state(lmp, fp, st);
}

void FixJdemWatchdog::restart(char *buf) {
  const JdemRestartState st = jdem_restart_read_state(
      lmp, buf, std::string("fix ") + id + " (jdem/watchdog)", WATCHDOG_SHARED, 0);
  const double *s = st.shared.data();
  has_ref = s[0] != 0.0;
  ref.kinetic = s[1];
  ref.rotational = s[2];
  ref.elastic = s[3];
  ref.gravitational = s[4];
  ref.damping = s[5];
  ref.friction = s[6];
  ref.wall_work = s[7];
  ref_step = jdem_restart_unpack_i64(s[8]);
  inserted_energy = s[9];
  inserted_atoms = s[10];
}

void FixJdemWatchdog::end_of_step() {
  book_insertions();
  if (inserting_at(update->ntimestep + 1)) note_last_tag();
  check();
}

void FixJdemWatchdog::post_run() {
  if (comm->me != 0 || inserts.empty()) return;
  const std::string line = format("fix %s jdem/watchdog: booked the energy of %.0f atoms inserted by "
                                  "fix insert: %.17g J\n", id, inserted_atoms, inserted_energy);
  if (screen) std::fputs(line.c_str(), screen);
  if (logfile) std::fputs(line.c_str(), logfile);
}

/* Does a fix insert/... insert at STEP (at the run's first step: it was scheduled before)? */
bool FixJdemWatchdog::inserting_at(bigint step) const {
  for (size_t k = 0; k < inserts.size(); k++)
    if (inserts[k]->next_reneighbor == step) return true;
  return false;
}

/* The largest atom id present (all ranks), when an insertion is due next step: the atoms of
 * that insertion get larger ids (Atom::tag_extend). */
void FixJdemWatchdog::note_last_tag() {
  if (inserts.empty()) return;
  int mine = 0;
  for (int i = 0; i < atom->nlocal; i++) mine = atom->tag[i] > mine ? atom->tag[i] : mine;
  MPI_Allreduce(&mine, &last_tag, 1, MPI_INT, MPI_MAX, world);
}

/* After a step on which a fix insert/... inserted: book the energy of its atoms, in the state the
 * energy account sees them first (the end of this step: the insertion's position, its velocity
 * after the step's last half kick), as input. */
void FixJdemWatchdog::book_insertions() {
  bool inserted = false;
  for (size_t k = 0; k < inserts.size(); k++) inserted = inserted || inserts[k]->has_inserted();
  if (!inserted) return;
  double g[3];
  jdem_gravity(lmp, g);
  double mine[2] = {0.0, 0.0}, all[2];
  for (int i = 0; i < atom->nlocal; i++) {
    if (atom->tag[i] <= last_tag || !(atom->mask[i] & groupbit)) continue;
    const double m = atom->rmass[i];
    mine[0] += 0.5 * m * jd_dot(atom->v[i], atom->v[i]) +
               0.5 * jd_sphere_inertia(m, atom->radius[i]) * jd_dot(atom->omega[i], atom->omega[i]) -
               m * jd_dot(g, atom->x[i]);
    mine[1] += 1.0;
  }
  MPI_Allreduce(mine, all, 2, MPI_DOUBLE, MPI_SUM, world);
  inserted_energy += all[0];
  inserted_atoms += all[1];
}

/* Is every component of x, v, omega, f and torque of this rank's atoms finite?  x - x is +0
 * (all bits zero) for every finite x and NaN for an infinity or a NaN (IEEE 754; GCC does not
 * fold it without -ffinite-math-only), so the OR of the bits of x - x over the contiguous
 * per-atom arrays is zero exactly when all are finite.  No comparison and no chain of dependent
 * additions: the compiler vectorises it, 3 instructions per 2 components when unrolled.  This
 * scan runs every step over 120 bytes per atom, about 5 % of a step of the 20k bench bed
 * (docs/liggghts.md, "Cost"), so its instruction count matters: the previous test, (exponent
 * bits + 2^52) into the sign bit, took 3.5 instructions per component. */
static bool all_finite(Atom *atom) {
  double *const q[] = {atom->x[0], atom->v[0], atom->omega[0], atom->f[0], atom->torque[0]};
  const int n = 3 * atom->nlocal;
  uint64_t acc = 0;
  for (int k = 0; k < 5; k++) {
    const double *p = q[k];
#pragma GCC unroll 8
    for (int i = 0; i < n; i++) {
      const double z = p[i] - p[i];
      uint64_t bits;
      std::memcpy(&bits, &z, sizeof bits);
      acc |= bits;
    }
  }
  return acc == 0;
}

/* The worst overlap beyond the limit that the force loops of this rank noted. */
static JdOverlapTrip worst_overlap(LAMMPS *lmp) {
  JdOverlapTrip worst = dynamic_cast<PairGranJiang *>(lmp->force->pair)->overlap_trip;
  for (int k = 0; k < lmp->modify->nfix; k++) {
    FixWallJiang *w = dynamic_cast<FixWallJiang *>(lmp->modify->fix[k]);
    if (w && w->overlap_trip.fraction > worst.fraction) worst = w->overlap_trip;
  }
  return worst;
}

/* The stepper's order: the state, the overlaps, then the energy at its samples.  One
 * reduction answers "anything non-finite? any overlap beyond the limit?" for the whole run;
 * only then do the searches that name the particle run (each with its own reduction).  The
 * same reduction carries a pending SIGINT/SIGTERM (jdem_stop.h), so that stopping costs the
 * next step no reduction of its own. */
void FixJdemWatchdog::check() {
  std::string msg;
  double mine[3] = {atom->nlocal > 0 && !all_finite(atom) ? 1.0 : 0.0,
                    worst_overlap(lmp).fraction, (double)jdem_stop_pending()},
         any[3];
  MPI_Allreduce(mine, any, 3, MPI_DOUBLE, MPI_MAX, world);
  jdem_stop_agreed((long long)update->ntimestep, (int)any[2]);
  if (any[0] > 0.0 && nonfinite(msg)) trip(msg, false);
  if (any[1] > 0.0 && overlap(msg)) trip(msg, true);
  const bigint step = update->ntimestep;
  if (checks_energy() && (step % energy_every == 0 || step == update->laststep) && energy(msg))
    trip(msg, true);
}

static std::string format(const char *fmt, ...) {
  char buf[1024];
  va_list ap;
  va_start(ap, fmt);
  std::vsnprintf(buf, sizeof buf, fmt, ap);
  va_end(ap);
  return buf;
}

/* Forces first (a non-finite force is the cause of the velocity it produces), then the
 * smallest id: the key quantity * 2^31 + id orders both in one MINLOC. */
bool FixJdemWatchdog::nonfinite(std::string &msg) {
  double **q[] = {atom->f, atom->torque, atom->x, atom->v, atom->omega};
  const double id_range = 2147483648.0;
  struct { double key; int rank; } mine = {INFINITY, comm->me}, all;
  double value = 0.0;
  for (int k = 0; k < JD_N_WATCHDOG_QUANTITIES && mine.key == INFINITY; k++)
    for (int i = 0; i < atom->nlocal; i++)
      for (int d = 0; d < 3; d++)
        if ((atom->mask[i] & groupbit) && !std::isfinite(q[k][i][d]) &&
            k * id_range + atom->tag[i] < mine.key) {
          mine.key = k * id_range + atom->tag[i];
          value = q[k][i][d];
        }
  MPI_Allreduce(&mine, &all, 1, MPI_DOUBLE_INT, MPI_MINLOC, world);
  if (all.key == INFINITY) return false;
  MPI_Bcast(&value, 1, MPI_DOUBLE, all.rank, world);
  const int k = (int)(all.key / id_range);
  char text[512];
  jd_watchdog_nonfinite_message(text, sizeof text, (long long)update->ntimestep, k, value,
                                (long long)(all.key - k * id_range));
  msg = std::string("jdem: ") + text;
  return true;
}

bool FixJdemWatchdog::overlap(std::string &msg) {
  const JdOverlapTrip worst = worst_overlap(lmp);
  struct { double fraction; int rank; } mine = {worst.fraction, comm->me}, all;
  MPI_Allreduce(&mine, &all, 1, MPI_DOUBLE_INT, MPI_MAXLOC, world);
  if (!(all.fraction > 0.0)) return false;
  int tags[2] = {worst.tag_a < worst.tag_b || !worst.tag_b ? worst.tag_a : worst.tag_b,
                 worst.tag_a < worst.tag_b || !worst.tag_b ? worst.tag_b : worst.tag_a};
  char wall[128] = "";
  if (worst.wall) std::snprintf(wall, sizeof wall, "%s", worst.wall);
  MPI_Bcast(tags, 2, MPI_INT, all.rank, world);
  MPI_Bcast(wall, sizeof wall, MPI_CHAR, all.rank, world);
  char text[512];
  jd_watchdog_overlap_message(text, sizeof text, (long long)update->ntimestep, all.fraction, tags[0],
                              tags[1] ? tags[1] : -1, wall, max_overlap);
  msg = std::string("jdem: ") + text;
  return true;
}

/* Id of the atom with the largest kinetic energy: where a spurious energy gain usually sits. */
int FixJdemWatchdog::most_energetic() {
  struct { double e; int rank; } mine = {-1.0, comm->me}, all;
  int tag = 0;
  for (int i = 0; i < atom->nlocal; i++) {
    const double e = atom->rmass[i] * jd_dot(atom->v[i], atom->v[i]);
    if ((atom->mask[i] & groupbit) && e > mine.e) {
      mine.e = e;
      tag = atom->tag[i];
    }
  }
  MPI_Allreduce(&mine, &all, 1, MPI_DOUBLE_INT, MPI_MAXLOC, world);
  MPI_Bcast(&tag, 1, MPI_INT, all.rank, world);
  return tag;
}

bool FixJdemWatchdog::energy(std::string &msg) {
  double local[JDO_N], sum[JDO_N];
  jdem_local_observables(lmp, groupbit, local);
  MPI_Allreduce(local, sum, JDO_N, MPI_DOUBLE, MPI_SUM, world);
  double bond[JD_N_BOND_OBSERVABLES] = {0.0};
  bond[JD_OBS_BOND_ELASTIC] = sum[JDO_BOND_ELASTIC];
  bond[JD_OBS_BOND_DAMPING] = sum[JDO_BOND_DAMPING];
  bond[JD_OBS_BOND_BREAKAGE] = sum[JDO_BOND_BREAKAGE];
  jd_energy_terms now = jd_energy_terms_of(sum, bond);
  /* the energy the inlets brought in is input, and the energy the atoms deleted outside the
   * domain took is output, as the stepper books them (stepper/watchdog.c) */
  for (int k = 0; k < modify->nfix; k++) {
    const FixJdemInlet *in = dynamic_cast<const FixJdemInlet *>(modify->fix[k]);
    if (in) now.wall_work += in->inflow_energy();
    const FixJdemDomain *dom = dynamic_cast<const FixJdemDomain *>(modify->fix[k]);
    if (dom) now.wall_work -= dom->lost_energy();
  }
  now.wall_work += inserted_energy;
  const double jump = has_ref ? jd_energy_jump(&ref, &now) : 0.0;
  if (!(jump <= max_energy_jump)) { /* NaN trips too */
    const int id = most_energetic();
    char text[512];
    jd_watchdog_energy_message(text, sizeof text, (long long)update->ntimestep, jump, id,
                               max_energy_jump, jd_energy_total(&ref), (long long)ref_step,
                               jd_energy_total(&now));
    msg = std::string("jdem: ") + text;
    return true;
  }
  ref = now;
  ref_step = update->ntimestep;
  has_ref = true;
  return false;
}

/* Write the frame of this step (the dumps' collective write), name the file each h5md/jdem dump
 * keeps, and stop through LIGGGHTS' error path (the dumps keep FILE.part). */
void FixJdemWatchdog::trip(const std::string &msg, bool write_frame) {
  if (write_frame) output->write_dump(update->ntimestep);
  std::string full = msg;
  for (int k = 0; k < output->ndump; k++) {
    DumpH5mdJdem *d = dynamic_cast<DumpH5mdJdem *>(output->dump[k]);
    if (d && d->last_frame_step() < 0) /* a non-finite state at set-up: no frame, no file */
      full += format("; no trajectory was written (%s: the run failed before its first frame)",
                     d->file_name().c_str());
    else if (d) /* a non-finite state gets no frame: the file ends with the step before */
      full += format("; the trajectory up to step " BIGINT_FORMAT " is kept, closed, as %s.part "
                     "(the run failed)", d->last_frame_step(), d->file_name().c_str());
  }
  error->all(FLERR, full.c_str());
}
