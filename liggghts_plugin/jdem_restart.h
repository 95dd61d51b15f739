/* jdem_restart.h — LIGGGHTS restart files (write_restart, restart N, read_restart) with our
 * styles: the pieces every style uses to save its state and continue bit for bit.
 *
 * What a continuation needs beyond LIGGGHTS' own restart data (docs/liggghts.md, "Restarts"):
 *  - the state of each fix of ours: its global state through Fix::write_restart/restart (the
 *    same on every rank, plus each rank's own accumulated energies, JdemRestartState), its
 *    per-atom state through Fix::pack_restart/unpack_restart (the fix's exchange packers);
 *  - the forces and torques of the step the file was written at (fix jdem/restart): velocity
 *    Verlet's first half kick of the next step needs them, and the set-up evaluation of a new
 *    run cannot reproduce them (it sees the full-step velocities);
 *  - no set-up evaluation that changes the history or the servo state: while a run resumes
 *    from a file (jdem_restart_resuming), the set-up of pair_style gran/jiang, fix wall/jiang
 *    and fix bond/jiang keeps the state that was read.
 * The interposed WriteRestart::write (jdem_restart.cpp) records the pair as "gran/jiang" in the
 * file and brings fix contacthistory's copy of the history up to date first (`restart N`
 * writes in the middle of a step, after the step's forces). */
#ifndef JDEM_RESTART_H
#define JDEM_RESTART_H

#include <cstdint>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

namespace LAMMPS_NS {
class Fix;
class LAMMPS;

/* A fix's global state in a restart file.
 *   shared: the same on every rank (rank 0's values are written);
 *   sums:   this rank's additive values (cumulative energies, counts), a fixed number per fix;
 *   tail:   this rank's list of values (e.g. contact points), concatenated across ranks.
 * Read on as many ranks as it was written on, every rank gets its own sums and tail back (the
 * same bits as the uninterrupted run); on another number of ranks rank 0 gets the totals and
 * the whole tail, the others zeros (the totals are then summed in another order). */
struct JdemRestartState {
  std::vector<double> shared, sums, tail;
};

/* Fix::write_restart of our fixes: gathers every rank's part and writes the block on rank 0.
 * Collective (LIGGGHTS calls write_restart on every rank). */
void jdem_restart_write_state(LAMMPS *lmp, FILE *fp, const JdemRestartState &mine);

/* Fix::restart of our fixes: this rank's part of the block `buf`.  `who` names the fix in the
 * messages ("fix ID (style)"); nshared and nsums are the counts this fix writes: a block with
 * other counts (another version of the style) stops with a message, but for older_nshared
 * shared values (when not 0: an older layout the fix still reads; st.shared's size says which
 * it got). */
JdemRestartState jdem_restart_read_state(LAMMPS *lmp, const char *buf, const std::string &who,
                                         size_t nshared, size_t nsums, size_t older_nshared = 0);

/* An int64 carried bit for bit in a double of a state block (steps such as INT64_MAX, "never",
 * are not exact as a double's value). */
static inline double jdem_restart_pack_i64(int64_t v) {
  double d;
  std::memcpy(&d, &v, sizeof d);
  return d;
}
static inline int64_t jdem_restart_unpack_i64(double d) {
  int64_t v;
  std::memcpy(&v, &d, sizeof v);
  return v;
}

/* Value k of the shared part of block `buf` (before its counts are known; k must be within
 * the part), or NAN for a block that is not ours. */
double jdem_restart_peek_shared(const char *buf, size_t k);

/* Per-atom restart data through a fix's exchange packers: the record is the pack_exchange
 * record after a length word.  jdem_unpack_restart returns the length of the stored record
 * (without the length word), so that the fix can check it before using the values. */
int jdem_pack_restart(Fix *fix, int i, double *buf);
int jdem_stored_restart_len(LAMMPS *lmp, int nlocal, int nth);
void jdem_unpack_restart(LAMMPS *lmp, Fix *fix, int nlocal, int nth);

/* True from the creation of fix jdem/restart with a restart file's data until the end of the
 * first set-up that follows (see fix_jdem_restart.h). */
bool jdem_restart_resuming(LAMMPS *lmp);

/* At the first run's set-up (before LIGGGHTS drops the states read from a file): a warning for
 * each fix move/mesh of the file that the script does not define again with its ID, whose
 * mesh would otherwise stop moving without a word. */
void jdem_restart_warn_unclaimed_motion(LAMMPS *lmp);

/* The restart file that was read (if any) against the pair style the script now defines,
 * called when pair_style is given (`style`; for gran/jiang with `history_len` doubles per
 * contact).  A file whose contact history belongs to the
 * other kind of pair style: its contact history is dropped and a warning says so (contacts
 * then start from zero history).  Our pair style with another history layout than the file's:
 * an error that names the options to use. */
void jdem_restart_check_pair_style(LAMMPS *lmp, const char *style, int history_len);

}  // namespace LAMMPS_NS

#endif
