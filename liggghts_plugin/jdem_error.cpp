/* jdem_error.cpp — see jdem_error.h. */
#include "jdem_error.h"

#include <mpi.h>
#include <sys/stat.h>

#include <cstdio>
#include <cstdlib>
#include <string>

#include "compute.h"
#include "error.h"
#include "fix.h"
#include "output.h"
#include "universe.h"

using namespace LAMMPS_NS;

static std::string log_path = "log.lammps";

void jdem_error_log_path(const char *path) { log_path = path ? path : ""; }

/* Both streams write to one file (a terminal that is the screen and stderr): print once. */
static bool same_file(FILE *a, FILE *b) {
  struct stat sa, sb;
  return fstat(fileno(a), &sa) == 0 && fstat(fileno(b), &sb) == 0 && sa.st_dev == sb.st_dev &&
         sa.st_ino == sb.st_ino;
}

/* TEXT on the screen, in the log and on stderr, flushed: MPI_Abort ends the process without
 * flushing stdio, which lost every message of Error::one on a pipe.  A rank without the log
 * (ranks > 0 open none) appends to rank 0's log file by name. */
static void report(FILE *screen, FILE *logfile, const std::string &text) {
  if (screen) {
    std::fputs(text.c_str(), screen);
    std::fflush(screen);
  }
  if (logfile) {
    std::fputs(text.c_str(), logfile);
    std::fflush(logfile);
  } else if (!log_path.empty()) {
    FILE *f = std::fopen(log_path.c_str(), "a");
    if (f) {
      std::fputs(text.c_str(), f);
      std::fclose(f);
    }
  }
  if (!screen || !same_file(screen, stderr)) {
    std::fputs(text.c_str(), stderr);
    std::fflush(stderr);
  }
}

static std::string where(const char *file, int line) {
  return std::string(" (") + file + ":" + std::to_string(line) + ")\n";
}

namespace LAMMPS_NS {

/* As the library's Error::all, without its second, "special" line (a dangling string in
 * Debian's build: garbage bytes after every run-time error), and on stderr too. */
void Error::all(const char *file, int line, const char *str) {
  MPI_Barrier(world);
  int me = 0;
  MPI_Comm_rank(world, &me);
  if (me == 0) report(screen, logfile, std::string("ERROR: ") + str + where(file, line));
  if (output) delete output;
  if (screen && screen != stdout) std::fclose(screen);
  if (logfile) std::fclose(logfile);
  if (universe->nworlds > 1) MPI_Abort(universe->uworld, 1);
  MPI_Finalize();
  std::exit(1);
}

void Error::fix_error(const char *file, int line, Fix *fix, const char *str) {
  fix_error(file, line, fix, fix->style, str);
}

void Error::fix_error(const char *file, int line, Fix *fix, const char *fixstylestr, const char *str) {
  const std::string head = std::string("Fix ") + fixstylestr + " (id " + fix->id + ")";
  all(file, line, (std::string(str).size() > 2 ? head + ": " + str : "Illegal " + head + " command").c_str());
}

void Error::compute_error(const char *file, int line, Compute *compute, const char *str) {
  const std::string head = std::string("Compute ") + compute->style + " (id " + compute->id + ")";
  all(file, line, (std::string(str).size() > 2 ? head + ": " + str : "Illegal " + head + " command").c_str());
}

/* As the library's Error::one (one rank stops the world), with the message flushed to the
 * screen, the log and stderr before MPI_Abort. */
void Error::one(const char *file, int line, const char *str) {
  int me = 0;
  MPI_Comm_rank(world, &me);
  const std::string text = "ERROR on proc " + std::to_string(me) + ": " + str + where(file, line);
  report(screen, logfile, text);
  if (universe->nworlds > 1 && universe->uscreen) {
    std::fputs(text.c_str(), universe->uscreen);
    std::fflush(universe->uscreen);
  }
  std::fflush(NULL);
  MPI_Abort(world, 1);
  std::exit(1); /* not reached: MPI_Abort does not return */
}

}  // namespace LAMMPS_NS
