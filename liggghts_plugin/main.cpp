/* main.cpp — liggghts-jdem: Debian's libliggghts with jdem's styles registered at start-up.
 *
 * Same command line as `liggghts` (-in, -var, -log, -echo, -screen, ...; works under mpirun).
 * Registered styles:
 *   pair_style gran/jiang   force->pair_map (public)
 *   fix wall/jiang          modify->fix_map (private: explicit-instantiation access idiom)
 *   fix jdem/watchdog       idem
 *   fix bond/jiang          idem
 *   fix jdem/loads          idem
 *   fix jdem/guard          idem
 *   fix jdem/observables    idem
 *   fix jdem/inlet          idem
 *   fix jdem/domain         idem
 *   fix jdem/restart        idem (defined by pair_style gran/jiang itself: fix_jdem_restart.h)
 *   dump h5md/jdem          LIGGGHTS 3.8 has no dump map: Output::add_dump() is an if-else chain
 *                           over style_dump.h.  We interpose Output::add_dump (libliggghts.so
 *                           calls it through its PLT, so the executable's definition wins) and
 *                           forward every other style to the library's original via
 *                           dlsym(RTLD_NEXT).  Output::delete_dump (undump) is interposed the
 *                           same way, so that h5md/jdem can tell a normal end from LIGGGHTS'
 *                           error path (Error::all deletes Output) and keep PATH.part then.
 * SIGINT/SIGTERM stop a run cleanly (jdem_stop.h: Integrate::ev_set is interposed the same way).
 * Error::all/one are interposed too (jdem_error.h): every rank's error reaches stderr and the log.
 * Do not use the `clear` command: it re-creates Force and Modify and drops the registrations. */
#include <dlfcn.h>
#include <mpi.h>

#include <cstdio>
#include <cstring>
#include <fstream>
#include <map>
#include <string>

#include "error.h"
#include "force.h"
#include "group.h"
#include "input.h"
#include "lammps.h"
#include "memory.h"
#include "modify.h"
#include "output.h"
#include "update.h"

#include "dump_h5md_jdem.h"
#include "fix_bond_jiang.h"
#include "fix_jdem_loads.h"
#include "fix_jdem_guard.h"
#include "fix_jdem_domain.h"
#include "fix_jdem_inlet.h"
#include "fix_jdem_observables.h"
#include "fix_jdem_restart.h"
#include "fix_jdem_watchdog.h"
#include "fix_wall_jiang.h"
#include "fix_wall_jiang_mesh.h"
#include "jdem_error.h"
#include "jdem_input_file.h"
#include "jdem_stop.h"
#include "pair_gran_jiang.h"

using namespace LAMMPS_NS;

/* ---- access to the private Modify::fix_map (legal: access checks are waived in explicit
 * template instantiations) ---- */
typedef std::map<std::string, Fix *(*)(LAMMPS *, int, char **)> FixMap;
template <typename Tag, typename Tag::type M>
struct Rob {
  friend typename Tag::type get(Tag) { return M; }
};
struct ModifyFixMap {
  typedef FixMap *Modify::*type;
  friend type get(ModifyFixMap);
};
template struct Rob<ModifyFixMap, &Modify::fix_map>;

static Pair *create_pair_gran_jiang(LAMMPS *lmp) { return new PairGranJiang(lmp); }
static Fix *create_fix_wall_jiang(LAMMPS *lmp, int narg, char **arg) {
  if (narg > 3 && std::strcmp(arg[3], "mesh") == 0) return new FixWallJiangMesh(lmp, narg, arg);
  return new FixWallJiang(lmp, narg, arg);
}

static Fix *create_fix_bond_jiang(LAMMPS *lmp, int narg, char **arg) {
  return new FixBondJiang(lmp, narg, arg);
}

static Fix *create_fix_jdem_loads(LAMMPS *lmp, int narg, char **arg) {
  return new FixJdemLoads(lmp, narg, arg);
}

static Fix *create_fix_jdem_watchdog(LAMMPS *lmp, int narg, char **arg) {
  return new FixJdemWatchdog(lmp, narg, arg);
}

static Fix *create_fix_jdem_guard(LAMMPS *lmp, int narg, char **arg) {
  return new FixJdemGuard(lmp, narg, arg);
}

static Fix *create_fix_jdem_observables(LAMMPS *lmp, int narg, char **arg) {
  return new FixJdemObservables(lmp, narg, arg);
}

static Fix *create_fix_jdem_inlet(LAMMPS *lmp, int narg, char **arg) {
  return new FixJdemInlet(lmp, narg, arg);
}

static Fix *create_fix_jdem_domain(LAMMPS *lmp, int narg, char **arg) {
  return new FixJdemDomain(lmp, narg, arg);
}

static Fix *create_fix_jdem_restart(LAMMPS *lmp, int narg, char **arg) {
  return new FixJdemRestart(lmp, narg, arg);
}

static void register_jdem_styles(LAMMPS *lmp) {
  (*lmp->force->pair_map)["gran/jiang"] = &create_pair_gran_jiang;
  FixMap *fix_map = lmp->modify->*get(ModifyFixMap());
  (*fix_map)["wall/jiang"] = &create_fix_wall_jiang;
  (*fix_map)["jdem/watchdog"] = &create_fix_jdem_watchdog;
  (*fix_map)["bond/jiang"] = &create_fix_bond_jiang;
  (*fix_map)["jdem/loads"] = &create_fix_jdem_loads;
  (*fix_map)["jdem/guard"] = &create_fix_jdem_guard;
  (*fix_map)["jdem/observables"] = &create_fix_jdem_observables;
  (*fix_map)["jdem/inlet"] = &create_fix_jdem_inlet;
  (*fix_map)["jdem/restart"] = &create_fix_jdem_restart;
  (*fix_map)["jdem/domain"] = &create_fix_jdem_domain;
}

/* ---- dump h5md/jdem: interposed Output::add_dump ---- */
namespace LAMMPS_NS {
void Output::add_dump(int narg, char **arg) {
  if (narg < 3 || std::strcmp(arg[2], "h5md/jdem") != 0) {
    typedef void (*AddDump)(Output *, int, char **);
    static AddDump original = NULL;
    if (!original) {
      void *sym = dlsym(RTLD_NEXT, "_ZN9LAMMPS_NS6Output8add_dumpEiPPc");
      if (!sym) error->all(FLERR, "liggghts-jdem: cannot find libliggghts' Output::add_dump");
      std::memcpy(&original, &sym, sizeof original);
    }
    original(this, narg, arg);
    return;
  }
  /* the library's add_dump, for our style */
  if (narg < 5) error->all(FLERR, "Illegal dump command");
  for (int idump = 0; idump < ndump; idump++)
    if (std::strcmp(arg[0], dump[idump]->id) == 0) error->all(FLERR, "Reuse of dump ID");
  if (group->find(arg[1]) == -1) error->all(FLERR, "Could not find dump group ID");
  const int every = force->inumeric(FLERR, arg[3]);
  if (every <= 0) error->all(FLERR, "Invalid dump frequency");
  if (ndump == max_dump) {
    max_dump += 1;
    dump = (Dump **)memory->srealloc(dump, max_dump * sizeof(Dump *), "output:dump");
    memory->grow(every_dump, max_dump, "output:every_dump");
    memory->grow(next_dump, max_dump, "output:next_dump");
    memory->grow(last_dump, max_dump, "output:last_dump");
    var_dump = (char **)memory->srealloc(var_dump, max_dump * sizeof(char *), "output:var_dump");
    memory->grow(ivar_dump, max_dump, "output:ivar_dump");
  }
  /* the scene_yaml file is copied whole into /parameters: a directory, /dev/zero or an empty
   * file is refused here, with its name (every rank sees the same file) */
  for (int i = 5; i + 1 < narg; i++)
    if (std::strcmp(arg[i], "scene_yaml") == 0) {
      std::ifstream in;
      const std::string why = jdem_open_input("dump h5md/jdem: scene_yaml", arg[i + 1], in);
      if (!why.empty()) error->all(FLERR, why.c_str());
    }
  dump[ndump] = new DumpH5mdJdem(lmp, narg, arg);
  every_dump[ndump] = every;
  last_dump[ndump] = -1;
  var_dump[ndump] = NULL;
  ndump++;
}

/* `undump` ends a dump normally: let h5md/jdem complete its file (see jdem_dump_close_ok). */
void Output::delete_dump(char *id) {
  typedef void (*DeleteDump)(Output *, char *);
  static DeleteDump original = NULL;
  if (!original) {
    void *sym = dlsym(RTLD_NEXT, "_ZN9LAMMPS_NS6Output11delete_dumpEPc");
    if (!sym) error->all(FLERR, "liggghts-jdem: cannot find libliggghts' Output::delete_dump");
    std::memcpy(&original, &sym, sizeof original);
  }
  const int saved = jdem_dump_close_ok;
  jdem_dump_close_ok = 1;
  original(this, id);
  jdem_dump_close_ok = saved;
}
}  // namespace LAMMPS_NS

static const char *jdem_help =
    "\nStyles added by liggghts-jdem (jdem's C contact kernel; see docs/liggghts.md):\n"
    "* Pair styles:  gran/jiang   [wall_rule hertz|jiang2021] [damping jiang2021|exact_restitution]\n"
    "                             [tangential_limit coulomb|unconstrained] [mu_r X] [rolling on|off]\n"
    "                             [energy yes|no]   (no: no energy accounts, a shorter history)\n"
    "                             [tangential_stiffness jiang2021|mindlin]\n"
    "                             [normal_law hertz|mepa] [mepa_exponent N] [mepa_plastic_depth X]\n"
    "                             (mepa: fix property/global LoadingStiffness, UnloadingStiffness,\n"
    "                              CohesiveStiffness peratomtype, Del Cid 2015)\n"
    "* Fix styles:   wall/jiang   plane corners x1 y1 z1 ... x4 y4 z4 type T [velocity vx vy vz]\n"
    "                             cylinder axis x1 y1 z1 x2 y2 z2 radius R side outside|inside type T\n"
    "                                 [velocity vx vy vz]\n"
    "                             mesh n_meshes N meshes ID1 ... IDN   (fix mesh/surface IDs)\n"
    "                jdem/watchdog N [overlap F] [energy J|off]   (stop a run that goes wrong)\n"
    "                jdem/guard vmax V [coordination C] [force]   (refuse an unsafe timestep)\n"
    "                jdem/inlet file SECTION origin X Y Z velocity VX VY VZ plane PX PY PZ NX NY NZ\n"
    "                           period L [offset D] first_id ID stop sections N|time T|height H\n"
    "                           [below_speed V] [every N] [record FILE]   (conveyor inlet)\n"
    "* Dump styles:  h5md/jdem    N FILE.h5 [scene NAME] [case NAME] [scene_yaml PATH]\n"
    "                             [energy yes|no]\n"
    "(gran/jiang presents itself as \"gran\" to LIGGGHTS; do not use `clear`.  Restart files:\n"
    " docs/liggghts.md, \"Restarts\".)\n\n";

int main(int argc, char **argv) {
  MPI_Init(&argc, &argv);
  int me = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &me);
  /* LIGGGHTS prints its own help and exits inside the LAMMPS constructor: print ours first. */
  for (int i = 1; i < argc; i++)
    if ((std::strcmp(argv[i], "-h") == 0 || std::strcmp(argv[i], "-help") == 0) && me == 0) {
      std::fputs(jdem_help, stdout);
      std::fflush(stdout);
    }
  for (int i = 1; i + 1 < argc; i++)
    if (std::strcmp(argv[i], "-log") == 0 || std::strcmp(argv[i], "-l") == 0)
      jdem_error_log_path(std::strcmp(argv[i + 1], "none") == 0 ? NULL : argv[i + 1]);
  LAMMPS *lmp = new LAMMPS(argc, argv, MPI_COMM_WORLD);
  register_jdem_styles(lmp);
  jdem_catch_stop_signals();
  lmp->input->file();
  /* a signal after the last run: stopped all the same (exit 128 + N, files kept as .part);
   * forget the last step's agreement, a signal may have come since */
  jdem_stop_agreed(-1, 0);
  jdem_stop_if_signalled(lmp, (long long)lmp->update->ntimestep);
  jdem_dump_close_ok = 1; /* the input finished: dumps complete their files */
  delete lmp;
  MPI_Barrier(MPI_COMM_WORLD);
  MPI_Finalize();
  return jdem_dump_close_failed ? 3 : 0;
}
