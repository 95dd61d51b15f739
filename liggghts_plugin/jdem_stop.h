/* jdem_stop.h — liggghts-jdem stops cleanly on SIGINT or SIGTERM, as build/jdem does: the run
 * ends at the next step, every dump h5md/jdem writes the frame of the step reached (if it does
 * not have it yet) and keeps its file, closed and readable, as FILE.h5.part, and the process exits
 * with 128 + the signal number (130 SIGINT, 143 SIGTERM) after the message
 *   jdem: interrupted (SIGINT) at step N; the trajectory up to step N is kept, closed, as FILE.h5.part
 * A second signal takes the default action (for a run that does not reach its next step).
 *
 * How: the handler only records the signal.  liggghts-jdem interposes Integrate::ev_set(), which
 * LIGGGHTS' run loops call (through libliggghts' PLT) at the start of every step, right after the
 * step counter was incremented and before anything moves: there the state is that of the step
 * just completed.  On more than one MPI rank the ranks must agree on the step (mpirun forwards
 * SIGINT/SIGTERM to the ranks as SIGTERM): fix jdem/watchdog carries the signal in the reduction
 * it does at the end of every step anyway (jdem_stop_pending / jdem_stop_agreed); without it,
 * ev_set does one reduction per step itself.  A signal that arrives after the last run stops at
 * the end of the input script the same way. */
#ifndef JDEM_STOP_H
#define JDEM_STOP_H

namespace LAMMPS_NS {
class LAMMPS;
}

/* Install the SIGINT/SIGTERM handlers (once, before the input script runs). */
void jdem_catch_stop_signals();

/* If a stop signal arrived (on any rank: collective), end the process as described above, with
 * the state of `step`.  Returns only when no signal arrived. */
void jdem_stop_if_signalled(LAMMPS_NS::LAMMPS *lmp, long long step);

/* For a reduction that every rank does at the end of step `step` anyway: this rank's signal
 * number (0: none) to reduce with MPI_MAX, and the reduced value to record, which the start of
 * the next step then uses instead of a reduction of its own. */
int jdem_stop_pending();
void jdem_stop_agreed(long long step, int sig);

#endif
