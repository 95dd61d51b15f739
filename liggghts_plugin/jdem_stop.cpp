/* jdem_stop.cpp — see jdem_stop.h. */
#include "jdem_stop.h"

#include <dlfcn.h>
#include <mpi.h>
#include <signal.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>

#include "integrate.h"
#include "lammps.h"
#include "output.h"
#include "universe.h"
#include "update.h"

#include "dump_h5md_jdem.h"

using namespace LAMMPS_NS;

/* Set by the handler (no I/O there), read at the start of every step. */
static volatile sig_atomic_t stop_signal = 0;

static void on_stop_signal(int sig) { stop_signal = sig; }

void jdem_catch_stop_signals() {
  struct sigaction sa;
  std::memset(&sa, 0, sizeof sa);
  sa.sa_handler = on_stop_signal;
  sigemptyset(&sa.sa_mask);
  /* SA_RESETHAND: a second signal takes the default action; SA_RESTART: HDF5's and MPI's
   * system calls are not cut short by the first one. */
  sa.sa_flags = SA_RESETHAND | SA_RESTART;
  sigaction(SIGINT, &sa, NULL);
  sigaction(SIGTERM, &sa, NULL);
}

/* The signal all ranks agreed on at the end of step agreed_step (jdem_stop_agreed). */
static long long agreed_step = -1;
static int agreed_signal = 0;

int jdem_stop_pending() { return stop_signal; }

void jdem_stop_agreed(long long step, int sig) {
  agreed_step = step;
  agreed_signal = sig;
}

void jdem_stop_if_signalled(LAMMPS *lmp, long long step) {
  int sig = stop_signal;
  int nprocs = 1;
  MPI_Comm_size(lmp->world, &nprocs);
  if (nprocs > 1) {
    if (agreed_step == step) sig = agreed_signal; /* reduced at the end of this step already */
    else MPI_Allreduce(MPI_IN_PLACE, &sig, 1, MPI_INT, MPI_MAX, lmp->world);
  }
  if (sig == 0) return;

  /* The frame of the step reached, then every dump h5md/jdem keeps FILE.part (Output's
   * destructor closes the dumps; jdem_dump_close_ok is 0 until the input script ends). */
  lmp->update->ntimestep = step;
  std::string files;
  Output *output = lmp->output;
  for (int k = 0; output && k < output->ndump; k++) {
    DumpH5mdJdem *d = dynamic_cast<DumpH5mdJdem *>(output->dump[k]);
    if (!d) continue;
    d->write_stop_frame(step);
    files += (files.empty() ? "" : ", ") + d->file_name() + ".part";
  }
  jdem_dump_close_ok = 0;

  int me = 0;
  MPI_Comm_rank(lmp->world, &me);
  if (me == 0) {
    char msg[4096];
    const char *what = sig == SIGINT ? "interrupted (SIGINT)" : "terminated (SIGTERM)";
    if (files.empty())
      std::snprintf(msg, sizeof msg, "jdem: %s at step %lld\n", what, step);
    else
      std::snprintf(msg, sizeof msg, "jdem: %s at step %lld; the trajectory up to step %lld is "
                    "kept, closed, as %s\n", what, step, step, files.c_str());
    std::fputs(msg, stderr);
    if (lmp->logfile) std::fputs(msg, lmp->logfile);
  }
  /* as LIGGGHTS' Error::all, with the signal's exit status */
  delete lmp->output;
  lmp->output = NULL;
  if (lmp->screen && lmp->screen != stdout) std::fclose(lmp->screen);
  if (lmp->logfile) std::fclose(lmp->logfile);
  lmp->screen = lmp->logfile = NULL;
  if (lmp->universe->nworlds > 1) MPI_Abort(lmp->universe->uworld, 128 + sig);
  MPI_Finalize();
  std::exit(128 + sig);
}

/* ---- the check at the start of every step: interposed Integrate::ev_set ---- */
namespace LAMMPS_NS {
void Integrate::ev_set(bigint ntimestep) {
  typedef void (*EvSet)(Integrate *, bigint);
  static EvSet original = NULL;
  if (!original) {
    void *sym = dlsym(RTLD_NEXT, "_ZN9LAMMPS_NS9Integrate6ev_setEl");
    if (!sym) {
      std::fputs("liggghts-jdem: cannot find libliggghts' Integrate::ev_set\n", stderr);
      std::abort();
    }
    std::memcpy(&original, &sym, sizeof original);
  }
  /* the step counter is already incremented; nothing has moved yet */
  jdem_stop_if_signalled(lmp, (long long)ntimestep - 1);
  original(this, ntimestep);
}
}  // namespace LAMMPS_NS
