/* fix_jdem_inlet.cpp — see fix_jdem_inlet.h. */
#include "fix_jdem_inlet.h"

#include <mpi.h>

#include <algorithm>
#include <cerrno>
#include <climits>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <sstream>

#include "atom.h"
#include "atom_vec.h"
#include "comm.h"
#include "domain.h"
#include "error.h"
#include "modify.h"
#include "update.h"

#include "fix_bond_jiang.h"
#include "jdem_input_file.h"
#include "jdem_restart.h"
#include "jdem_kernel.h"
#include "jdem_observables.h"

using namespace LAMMPS_NS;
using namespace FixConst;

static const char *USAGE =
    "fix ID group jdem/inlet file SECTION origin X Y Z velocity VX VY VZ plane PX PY PZ NX NY NZ "
    "period L [offset D] first_id ID stop sections N|time T|height H [below_speed V] [every N] "
    "[overlap_tol F] [max_insert_overlap F|inf] [record FILE|append_record FILE]";

FixJdemInlet::FixJdemInlet(LAMMPS *lmp, int narg, char **arg)
    : Fix(lmp, narg, arg), spec(), stream(), started(false), stop_time(-1.0), height(-1.0),
      below_speed(0.1), every(1000), gravity(), energy_in(0.0), insert_seconds(0.0), record(NULL) {
  if (!atom->radius_flag || !atom->rmass_flag || !atom->omega_flag || !atom->density_flag)
    error->all(FLERR, "fix jdem/inlet needs atom_style granular (radius, density, mass, spin)");
  if (!atom->tag_enable || atom->map_style == 0)
    error->all(FLERR, "fix jdem/inlet needs atom IDs and `atom_modify map array` (or hash)");
  spec.overlap_tol = JD_INLET_OVERLAP_TOL;
  spec.max_insert_overlap = JD_INLET_MAX_INSERT_OVERLAP;
  parse(narg, arg);
  force_reneighbor = 1;
  next_reneighbor = -1; /* set by init() once dt is known */
  nevery = 1;
  restart_global = 1; /* the position in the stream (jdem_restart.h) */
  scalar_flag = 1;    /* compute_scalar: the work still to come, at any step */
  global_freq = 1;
  extscalar = 0;
}

FixJdemInlet::~FixJdemInlet() {
  if (record) std::fclose(record);
}

int FixJdemInlet::setmask() { return PRE_EXCHANGE | END_OF_STEP; }

/* ---- arguments ---- */

/* The n numbers after keyword arg[i] into out; a clear message naming the keyword otherwise. */
static void numbers(Error *error, int narg, char **arg, int i, int n, double *out) {
  if (i + n >= narg) {
    char msg[160];
    std::snprintf(msg, sizeof msg, "fix jdem/inlet: %s needs %d number%s", arg[i], n, n > 1 ? "s" : "");
    error->all(FLERR, msg);
  }
  for (int k = 0; k < n; k++) {
    char *end = NULL;
    errno = 0;
    out[k] = std::strtod(arg[i + 1 + k], &end);
    if (end == arg[i + 1 + k] || *end != '\0' || errno == ERANGE || !std::isfinite(out[k])) {
      char msg[256];
      std::snprintf(msg, sizeof msg, "fix jdem/inlet: %s: '%.64s' is not a finite number", arg[i],
                    arg[i + 1 + k]);
      error->all(FLERR, msg);
    }
  }
}

/* An integer >= lowest after keyword arg[i]. */
static long long integer(Error *error, int narg, char **arg, int i, long long lowest, const char *what) {
  double v;
  numbers(error, narg, arg, i, 1, &v);
  if (v != std::floor(v) || v < (double)lowest || v > 9.0e15) {
    char msg[200];
    std::snprintf(msg, sizeof msg, "fix jdem/inlet: %s must be an integer >= %lld", what, lowest);
    error->all(FLERR, msg);
  }
  return (long long)v;
}

static double positive(Error *error, int narg, char **arg, int i, const char *what) {
  double v;
  numbers(error, narg, arg, i, 1, &v);
  if (!(v > 0.0)) {
    char msg[160];
    std::snprintf(msg, sizeof msg, "fix jdem/inlet: %s must be a number > 0", what);
    error->all(FLERR, msg);
  }
  return v;
}

void FixJdemInlet::parse(int narg, char **arg) {
  const char *section = NULL, *record_path = NULL;
  bool append = false;
  bool have[5] = {false, false, false, false, false}; /* origin velocity plane period first_id */
  bool have_stop = false;
  for (int i = 3; i < narg;) {
    const std::string key = arg[i];
    if (key == "file" || key == "record" || key == "append_record") {
      if (i + 1 >= narg) error->all(FLERR, ("fix jdem/inlet: " + key + " needs a file name").c_str());
      if (key != "file" && record_path)
        error->all(FLERR, "fix jdem/inlet: record and append_record exclude each other; valid: one record file");
      (key == "file" ? section : record_path) = arg[i + 1];
      append = key == "append_record" ? true : key == "record" ? false : append;
      i += 2;
    } else if (key == "origin" || key == "velocity") {
      numbers(error, narg, arg, i, 3, key == "origin" ? spec.origin : spec.velocity);
      have[key == "origin" ? 0 : 1] = true;
      i += 4;
    } else if (key == "plane") {
      double pn[6];
      numbers(error, narg, arg, i, 6, pn);
      for (int d = 0; d < 3; d++) spec.plane_point[d] = pn[d], spec.plane_normal[d] = pn[3 + d];
      have[2] = true;
      i += 7;
    } else if (key == "period" || key == "offset") {
      numbers(error, narg, arg, i, 1, key == "period" ? &spec.period : &spec.offset);
      if (key == "period") have[3] = true;
      i += 2;
    } else if (key == "overlap_tol") { /* a section cut from a settled deposit keeps its contacts */
      spec.overlap_tol = positive(error, narg, arg, i, "overlap_tol");
      i += 2;
    } else if (key == "max_insert_overlap") { /* a fraction of the smaller radius, or inf */
      if (i + 1 < narg && !std::strcmp(arg[i + 1], "inf")) {
        spec.max_insert_overlap = INFINITY;
      } else {
        numbers(error, narg, arg, i, 1, &spec.max_insert_overlap);
        if (!(spec.max_insert_overlap >= 0.0))
          error->all(FLERR, "fix jdem/inlet: max_insert_overlap must be a number >= 0 (a fraction "
                            "of the smaller radius) or inf");
      }
      i += 2;
    } else if (key == "first_id") {
      spec.first_id = integer(error, narg, arg, i, 1, "first_id");
      have[4] = true;
      i += 2;
    } else if (key == "stop") {
      if (have_stop) error->all(FLERR, "fix jdem/inlet: stop is given twice; valid: one stop rule");
      have_stop = true;
      const std::string rule = i + 1 < narg ? arg[i + 1] : "";
      if (rule == "sections") {
        spec.max_sections = integer(error, narg, arg, i + 1, 1, "stop sections");
        i += 3;
      } else if (rule == "time") {
        stop_time = positive(error, narg, arg, i + 1, "stop time");
        i += 3;
      } else if (rule == "height") {
        height = positive(error, narg, arg, i + 1, "stop height");
        for (i += 3; i < narg && (!std::strcmp(arg[i], "below_speed") || !std::strcmp(arg[i], "every")); i += 2)
          if (!std::strcmp(arg[i], "below_speed")) below_speed = positive(error, narg, arg, i, "below_speed");
          else every = integer(error, narg, arg, i, 1, "every");
      } else {
        error->all(FLERR, "fix jdem/inlet: stop needs 'sections N', 'time T' or 'height H "
                          "[below_speed V] [every N]'");
      }
    } else {
      const std::string msg = "fix jdem/inlet: unknown keyword '" + key.substr(0, 64) +
                              "'; valid: file, origin, velocity, plane, period, offset, first_id, "
                              "stop, overlap_tol, max_insert_overlap, record, append_record";
      error->all(FLERR, msg.c_str());
    }
  }
  const char *names[5] = {"origin", "velocity", "plane", "period", "first_id"};
  for (int k = 0; k < 5; k++)
    if (!have[k]) error->all(FLERR, (std::string("fix jdem/inlet: missing keyword '") + names[k] +
                                     "'; usage: " + USAGE).c_str());
  if (!section) error->all(FLERR, (std::string("fix jdem/inlet: missing keyword 'file'; usage: ") + USAGE).c_str());
  if (!have_stop)
    error->all(FLERR, "fix jdem/inlet: missing keyword 'stop'; valid: stop sections N, stop time T "
                      "or stop height H");
  read_section(section);
  if (record_path) open_record(record_path, append);
}

/* A section line "bond I J T" (the word "bond" read) into out as I J T; a message otherwise. */
static bool bond_line(std::istringstream &ls, std::vector<int> &out) {
  long long v[3];
  std::string rest;
  if (!(ls >> v[0] >> v[1] >> v[2]) || (ls >> rest) || v[0] < 0 || v[1] < 0 || v[2] < 0 ||
      v[0] == v[1] || v[0] > INT_MAX || v[1] > INT_MAX || v[2] > INT_MAX)
    return false;
  out.insert(out.end(), {(int)v[0], (int)v[1], (int)v[2]});
  return true;
}

/* Rank 0 reads the section file and broadcasts it: "TYPE RADIUS DENSITY X Y Z" per particle,
 * "bond I J T" per bond. */
void FixJdemInlet::read_section(const char *path) {
  std::vector<double> rows; /* type radius density x y z */
  std::vector<int> bonds;   /* i j type */
  char msg[512] = "";
  int bad = 0;
  if (comm->me == 0) {
    std::ifstream in;
    std::string why = jdem_open_input("fix jdem/inlet: section file", path, in);
    std::string line;
    for (int lineno = 1; !bad && why.empty() && std::getline(in, line); lineno++) {
      why = jdem_text_line("fix jdem/inlet: section file", path, lineno, line);
      if (!why.empty()) break;
      const size_t hash = line.find('#');
      if (hash != std::string::npos) line.erase(hash);
      std::istringstream ls(line);
      std::string first;
      if (!(ls >> first)) continue;
      if (first == "bond") {
        if (!bond_line(ls, bonds)) {
          std::snprintf(msg, sizeof msg, "fix jdem/inlet: section file %s line %d: expected \"bond I J "
                        "T\": two different section particle indices I, J >= 0 and a bond type T >= 0",
                        path, lineno);
          bad = 1;
        }
        continue;
      }
      std::istringstream nums(line);
      double v[6];
      std::string rest;
      bool ok = (nums >> v[0] >> v[1] >> v[2] >> v[3] >> v[4] >> v[5]) && !(nums >> rest) &&
                v[0] >= 1 && v[0] <= atom->ntypes && v[0] == std::floor(v[0]) && v[1] > 0.0 && v[2] > 0.0;
      for (int k = 0; k < 6 && ok; k++) ok = std::isfinite(v[k]);
      if (!ok) {
        std::snprintf(msg, sizeof msg, "fix jdem/inlet: section file %s line %d: expected \"TYPE RADIUS "
                      "DENSITY X Y Z\" with TYPE between 1 and %d, RADIUS > 0 and DENSITY > 0, or "
                      "\"bond I J T\"", path, lineno, atom->ntypes);
        bad = 1;
      }
      rows.insert(rows.end(), v, v + 6);
    }
    if (why.empty() && !bad && rows.empty())
      why = std::string("fix jdem/inlet: section file ") + path +
            ": holds no particles (lines \"TYPE RADIUS DENSITY X Y Z\")";
    for (size_t b = 0; why.empty() && !bad && b < bonds.size(); b += 3)
      if (bonds[b] >= (int)(rows.size() / 6) || bonds[b + 1] >= (int)(rows.size() / 6)) {
        std::snprintf(msg, sizeof msg, "fix jdem/inlet: section file %s: bond %d %d joins a particle "
                      "that does not exist; valid: indices 0 to %d (the particle lines in order)",
                      path, bonds[b], bonds[b + 1], (int)(rows.size() / 6) - 1);
        bad = 1;
      }
    if (!why.empty() && !bad) {
      std::snprintf(msg, sizeof msg, "%s", why.c_str());
      bad = 1;
    }
  }
  jdem_share_input(lmp, bad, msg, sizeof msg, rows);
  jdem_share_input(lmp, 0, msg, sizeof msg, bonds);
  const int n = (int)rows.size();
  for (int r = 0; r < n; r += 6) {
    type0.push_back((int32_t)rows[r] - 1);
    radius.push_back(rows[r + 1]);
    density.push_back(rows[r + 2]);
    rel.insert(rel.end(), &rows[r + 3], &rows[r + 6]);
  }
  spec.n = type0.size();
  spec.rel = rel.data();
  spec.radius = radius.data();
  spec.species = type0.data();
  sort_bonds(bonds, path);
  make_groups();
}

/* The section's bonds in the kernel's order (jd_inlet_sort_bonds), as build/jdem resolves them. */
void FixJdemInlet::sort_bonds(const std::vector<int> &bonds, const char *path) {
  for (size_t k = 0; k < bonds.size(); k += 3) {
    bond_pair.insert(bond_pair.end(), {bonds[k], bonds[k + 1]});
    bond_type.push_back(bonds[k + 2]);
  }
  const size_t k = jd_inlet_sort_bonds(bond_type.size(), bond_pair.data(), bond_type.data());
  if (k < bond_type.size()) {
    char msg[400];
    std::snprintf(msg, sizeof msg, "fix jdem/inlet: section file %s: section particles %d and %d "
                  "are bonded twice; valid: at most one bond per pair", path, bond_pair[2 * k],
                  bond_pair[2 * k + 1]);
    error->all(FLERR, msg);
  }
}

/* The groups the kernel inserts whole: the bonds' connected components (jd_inlet_groups). */
void FixJdemInlet::make_groups() {
  if (bond_type.empty()) return;
  std::vector<int32_t> parent(spec.n);
  group_of.resize(spec.n);
  group_first.resize(spec.n + 1);
  group_member.resize(spec.n);
  spec.n_groups = jd_inlet_groups(spec.n, bond_type.size(), bond_pair.data(), parent.data(),
                                  group_of.data(), group_first.data(), group_member.data());
  spec.group_first = group_first.data();
  spec.group_member = group_member.data();
  spec.group_of = group_of.data();
}

/* The fix bond/jiang of each bond type (the n-th of the input is type n - 1). */
void FixJdemInlet::find_bond_fixes() {
  bond_fix.clear();
  for (int k = 0; k < modify->nfix; k++) {
    FixBondJiang *b = dynamic_cast<FixBondJiang *>(modify->fix[k]);
    if (b) bond_fix.push_back(b);
  }
  for (size_t k = 0; k < bond_type.size(); k++)
    if (bond_type[k] >= (int)bond_fix.size()) {
      char msg[300];
      std::snprintf(msg, sizeof msg, "fix %s jdem/inlet: a section bond has type %d, but the input "
                    "defines %d fix bond/jiang; valid: types 0 to %d (the n-th fix bond/jiang is type "
                    "n - 1)", id, bond_type[k], (int)bond_fix.size(), (int)bond_fix.size() - 1);
      error->all(FLERR, msg);
    }
}

double FixJdemInlet::section_bond_omega2() {
  if (bond_type.empty()) return 0.0;
  std::vector<const jd_bond_params *> params;
  for (size_t t = 0; t < bond_fix.size(); t++) params.push_back(&bond_fix[t]->bond_params());
  std::vector<double> mass(spec.n), work(spec.n);
  for (size_t p = 0; p < spec.n; p++) mass[p] = jd_sphere_mass(radius[p], density[p]);
  return jd_inlet_bond_omega2(&spec, mass.data(), bond_type.size(), bond_pair.data(),
                              bond_type.data(), params.data(), work.data());
}

/* A new record (its header first), or the record an earlier fix jdem/inlet of the deck started:
 * the fixes write their lines at pre_exchange in their order, each step's lines flushed, and
 * every fix holds the file in append mode, so that each write lands at its end. */
void FixJdemInlet::open_record(const char *path, bool append) {
  char msg[512] = "";
  if (comm->me == 0) {
    bool header_ok = append;
    if (!append) {
      FILE *fresh = std::fopen(path, "w");
      const bool wrote = fresh && std::fputs(JD_INLET_RECORD_HEADER, fresh) >= 0;
      header_ok = fresh && std::fclose(fresh) == 0 && wrote;
    }
    record = header_ok ? std::fopen(path, "a") : NULL;
    if (!record)
      std::snprintf(msg, sizeof msg, "fix jdem/inlet: record file %s: %s", path, std::strerror(errno));
  }
  MPI_Bcast(msg, sizeof msg, MPI_CHAR, 0, world);
  if (msg[0]) error->all(FLERR, msg);
}

double FixJdemInlet::max_rad(int t) {
  double r = 0.0;
  for (size_t p = 0; p < type0.size(); p++)
    if (type0[p] + 1 == t && radius[p] > r) r = radius[p];
  return r;
}

int FixJdemInlet::min_type() { return *std::min_element(type0.begin(), type0.end()) + 1; }

int FixJdemInlet::max_type() { return *std::max_element(type0.begin(), type0.end()) + 1; }

/* ---- the stream ---- */

/* At the first run: the time step is known now (the deck sets it after the fixes). */
void FixJdemInlet::init() {
  find_bond_fixes();
  if (started) {
    if (update->dt != spec.dt)
      error->all(FLERR, "fix jdem/inlet: the time step changed after the stream started; valid: "
                        "one timestep for the whole stream");
    return;
  }
  start_stream();
}

void FixJdemInlet::start_stream() {
  spec.dt = update->dt;
  spec.stop_step = stop_time > 0.0 ? jd_inlet_stop_step_of_time(stop_time, spec.dt) : JD_INLET_NO_STOP;
  char msg[512];
  if (jd_inlet_check(&spec, height > 0.0, msg, sizeof msg) != JD_INLET_OK)
    error->all(FLERR, (std::string("fix jdem/inlet: ") + msg).c_str());
  int mine = 0, largest = 0;
  for (int i = 0; i < atom->nlocal; i++) mine = atom->tag[i] > mine ? atom->tag[i] : mine;
  MPI_Allreduce(&mine, &largest, 1, MPI_INT, MPI_MAX, world);
  if (spec.first_id <= largest) {
    std::snprintf(msg, sizeof msg, "fix jdem/inlet: first_id %lld is not above the largest atom id %d; "
                  "valid: first_id > %d", (long long)spec.first_id, largest, largest);
    error->all(FLERR, msg);
  }
  cursor.resize(spec.n);
  jd_inlet_stream_init(&spec, &stream, cursor.data());
  next_reneighbor = stream.next_step == JD_INLET_NEVER ? -1 : stream.next_step;
  started = true;
}

/* One particle on this rank: LIGGGHTS' atom creation, then the stream's state. */
void FixJdemInlet::create(const jd_inlet_particle &p, const double g[3]) {
  atom->avec->create_atom((int)p.species + 1, const_cast<double *>(p.position));
  const int i = atom->nlocal - 1;
  atom->tag[i] = (int)p.id;
  atom->mask[i] = 1 | groupbit;
  atom->radius[i] = p.radius;
  atom->density[i] = density[p.index];
  atom->rmass[i] = jd_sphere_mass(p.radius, density[p.index]);
  for (int d = 0; d < 3; d++) {
    atom->v[i][d] = p.velocity[d];
    atom->omega[i][d] = 0.0;
    atom->f[i][d] = atom->rmass[i] * g[d];
    atom->torque[i][d] = 0.0;
  }
  for (int k = 0; k < modify->nfix; k++)
    if (modify->fix[k]->create_attribute) modify->fix[k]->set_arrays(i);
}

/* Every due particle was created by exactly one rank (one reduction per insertion step). */
void FixJdemInlet::check_created(const std::vector<jd_inlet_particle> &due, int created_here) {
  int total = 0;
  MPI_Allreduce(&created_here, &total, 1, MPI_INT, MPI_SUM, world);
  if (total == (int)due.size()) return;
  std::vector<int> mine(due.size(), 0), all(due.size(), 0);
  for (size_t q = 0; q < due.size(); q++) mine[q] = domain->is_in_subdomain(const_cast<double *>(due[q].position));
  MPI_Allreduce(mine.data(), all.data(), (int)due.size(), MPI_INT, MPI_SUM, world);
  for (size_t q = 0; q < due.size(); q++)
    if (all[q] != 1) {
      char msg[400];
      std::snprintf(msg, sizeof msg, "fix jdem/inlet: step %lld: particle %lld at (%g, %g, %g) lies %s; "
                    "valid: a simulation box that holds the inlet plane's crossing points",
                    (long long)due[q].step, (long long)due[q].id, due[q].position[0], due[q].position[1],
                    due[q].position[2], all[q] ? "in more than one subdomain" : "outside the simulation box");
      error->all(FLERR, msg);
    }
}

/* The due particles whose place is free (kernel/jdem_inlet.h "Insertion into an occupied
 * place"): the owner of each position measures its worst overlap with the atoms at this step
 * (the ghosts brought up to date first), one reduction shares them, and every rank applies the
 * kernel's rule to the same numbers. */
std::vector<jd_inlet_particle> FixJdemInlet::kept_of(const std::vector<jd_inlet_particle> &due) {
  if (std::isinf(spec.max_insert_overlap)) return due;
  comm->forward_comm();
  const size_t n = due.size();
  std::vector<double> mine(n), worst(n);
  std::vector<size_t> with(n);
  std::vector<int> mine_tag(n, -1), with_tag(n, -1);
  const int nall = atom->nlocal + atom->nghost;
  jd_inlet_worst_overlaps(due.data(), n, (size_t)nall, nall ? atom->x[0] : NULL, atom->radius,
                          mine.data(), with.data());
  for (size_t q = 0; q < n; q++) {
    if (!domain->is_in_subdomain(const_cast<double *>(due[q].position))) mine[q] = -INFINITY;
    else if (with[q] != SIZE_MAX) mine_tag[q] = atom->tag[with[q]];
  }
  MPI_Allreduce(mine.data(), worst.data(), (int)n, MPI_DOUBLE, MPI_MAX, world);
  MPI_Allreduce(mine_tag.data(), with_tag.data(), (int)n, MPI_INT, MPI_MAX, world);
  std::vector<unsigned char> skip(n);
  if (!jd_inlet_skip_groups(&spec, due.data(), n, worst.data(), skip.data())) return due;
  std::vector<jd_inlet_particle> kept;
  for (size_t q = 0; q < n; q++) {
    if (!skip[q]) {
      kept.push_back(due[q]);
      continue;
    }
    report_skip(due[q], worst[q], with_tag[q]);
    jd_inlet_book_skipped(&stream, 1);
  }
  return kept;
}

/* Rank 0 reports the first JD_INLET_REPORTED skips of the run, in build/jdem's words. */
void FixJdemInlet::report_skip(const jd_inlet_particle &p, double worst, int with_tag) {
  const long long nth = skipped() + 1;
  if (comm->me != 0 || nth > JD_INLET_REPORTED) return;
  char why[256], line[512];
  jd_inlet_skip_reason(why, sizeof why, worst, with_tag, spec.max_insert_overlap, nth);
  std::snprintf(line, sizeof line, "fix %s jdem/inlet: step %lld: skips particle id %lld: %s\n", id,
                (long long)update->ntimestep, (long long)p.id, why);
  if (screen) std::fputs(line, screen);
  if (logfile) std::fputs(line, logfile);
}

/* The particles due at this step (after the contact histories were saved by atom id: LIGGGHTS
 * runs fix contacthistory's pre_exchange first, so the new atoms may overwrite ghosts). */
void FixJdemInlet::pre_exchange() {
  if (update->ntimestep != stream.next_step) return;
  const double t0 = MPI_Wtime();
  jdem_gravity(lmp, gravity);
  std::vector<jd_inlet_particle> due, buf(spec.n);
  size_t got;
  while (stream.next_step == update->ntimestep &&
         (got = jd_inlet_pop(&spec, &stream, update->ntimestep, buf.data(), buf.size())) > 0)
    due.insert(due.end(), buf.begin(), buf.begin() + got);
  next_reneighbor = stream.next_step == JD_INLET_NEVER ? -1 : stream.next_step;
  new_ids.clear();
  if (due.empty()) return;
  if (due.back().id > INT_MAX)
    error->all(FLERR, "fix jdem/inlet: the stream's ids pass 2147483647, LIGGGHTS' largest atom id");
  due = kept_of(due);
  int created = 0;
  for (size_t q = 0; q < due.size(); q++) {
    const jd_inlet_particle &p = due[q];
    const double m = jd_sphere_mass(p.radius, density[p.index]);
    energy_in += 0.5 * m * jd_dot(p.velocity, p.velocity) - m * jd_dot(gravity, p.position);
    new_ids.push_back((int)p.id);
    char line[JD_INLET_RECORD_LINE_MAX];
    if (record && jd_inlet_record_line(&p, line, sizeof line) > 0) std::fputs(line, record);
    if (domain->is_in_subdomain(const_cast<double *>(p.position))) {
      create(p, gravity);
      created++;
    }
  }
  if (record) std::fflush(record);
  check_created(due, created);
  atom->natoms += (bigint)due.size();
  atom->nghost = 0; /* the ghosts are rebuilt by this step's borders() */
  atom->map_init();
  atom->map_set();
  if (!due.empty()) form_block_bonds(due);
  insert_seconds += MPI_Wtime() - t0;
}

/* The section bonds of the groups inserted at this step (due: in increasing id): a group is
 * inserted whole, so a bond of copy c forms exactly when its lower id is due; the rank owning
 * that atom stores it. */
void FixJdemInlet::form_block_bonds(const std::vector<jd_inlet_particle> &due) {
  if (bond_type.empty()) return;
  const auto is_due = [&due](int64_t tag) {
    const auto at = std::lower_bound(due.begin(), due.end(), tag,
                                     [](const jd_inlet_particle &p, int64_t t) { return p.id < t; });
    return at != due.end() && at->id == tag;
  };
  for (int64_t c = due.front().copy; c <= due.back().copy; c++)
    for (size_t b = 0; b < bond_type.size(); b++) {
      int64_t ids[2];
      jd_inlet_bond_ids(&spec, c, (size_t)bond_pair[2 * b], (size_t)bond_pair[2 * b + 1], ids);
      if (!is_due(ids[0])) continue; /* its group was inserted at another step */
      if (!is_due(ids[1]))
        error->all(FLERR, "fix jdem/inlet: a section bond joins a particle not inserted with its "
                          "block (internal error)");
      const int i = atom->map((int)ids[0]);
      if (i >= 0 && i < atom->nlocal) bond_fix[bond_type[b]]->form_inlet_bond(i, (int)ids[1]);
    }
}

/* The stepper's state of a particle at its insertion step (the step's final half kick left out). */
void FixJdemInlet::settle_new_particles() {
  for (size_t q = 0; q < new_ids.size(); q++) {
    const int i = atom->map(new_ids[q]);
    if (i < 0 || i >= atom->nlocal) continue;
    for (int d = 0; d < 3; d++) {
      atom->v[i][d] = spec.velocity[d];
      atom->omega[i][d] = 0.0;
      atom->f[i][d] = atom->rmass[i] * gravity[d];
      atom->torque[i][d] = 0.0;
    }
  }
  new_ids.clear();
}

void FixJdemInlet::height_rule() {
  const double mine = jd_inlet_deposit_top((size_t)atom->nlocal, atom->nlocal ? atom->x[0] : NULL,
                                           atom->nlocal ? atom->v[0] : NULL, atom->radius, below_speed);
  double top = mine;
  MPI_Allreduce(&mine, &top, 1, MPI_DOUBLE, MPI_MAX, world);
  jd_inlet_height_stop(&stream, update->ntimestep, top, height);
}

void FixJdemInlet::end_of_step() {
  if (!new_ids.empty()) settle_new_particles();
  if (height > 0.0 && jd_inlet_height_due(update->ntimestep, every)) height_rule();
  if (update->ntimestep > stream.next_step)
    error->all(FLERR, "fix jdem/inlet: a due step passed without its insertion (internal error)");
}

double FixJdemInlet::compute_scalar() {
  if (!started) return 0.0;
  const int64_t last = (int64_t)update->laststep;
  return jd_inlet_pending_particle_steps(&spec, cursor.data(),
                                         jd_inlet_copies_by(&spec, stream.stop_step, last), last);
}

/* The run's account: every rank's time spent inserting, the slowest one reported. */
void FixJdemInlet::post_run() {
  double slowest = insert_seconds;
  MPI_Allreduce(&insert_seconds, &slowest, 1, MPI_DOUBLE, MPI_MAX, world);
  if (comm->me != 0) return;
  const long long n = inserted();
  char line[320];
  std::snprintf(line, sizeof line, "fix %s jdem/inlet: inserted %lld particles, skipped %lld, "
                "inflow energy %.17g J, insertion %.6f s, %.1f ns per particle\n", id, n,
                skipped(), energy_in, slowest, n ? 1e9 * slowest / (double)n : 0.0);
  if (screen) std::fputs(line, screen);
  if (logfile) std::fputs(line, logfile);
}

/* ---- restart files: the position in the stream (every rank computes the whole stream) ---- */

namespace {
enum { INLET_SHARED_HEAD = 10 }; /* then 2 per section particle: its cursor */
}

void FixJdemInlet::write_restart(FILE *fp) {
  JdemRestartState st;
  const double head[INLET_SHARED_HEAD] = {
      started ? 1.0 : 0.0, spec.dt, jdem_restart_pack_i64(spec.stop_step), (double)spec.n,
      jdem_restart_pack_i64(stream.started), jdem_restart_pack_i64(stream.stop_step),
      jdem_restart_pack_i64(stream.next_step), jdem_restart_pack_i64(stream.inserted), energy_in,
      jdem_restart_pack_i64(stream.skipped)};
  st.shared.assign(head, head + INLET_SHARED_HEAD);
  for (size_t p = 0; p < spec.n; p++) {
    st.shared.push_back(jdem_restart_pack_i64(started ? cursor[p].copy : 0));
    st.shared.push_back(jdem_restart_pack_i64(started ? cursor[p].step : 0));
  }
  jdem_restart_write_state(lmp, fp, st);
}

void FixJdemInlet::restart(char *buf) {
  const std::string who = std::string("fix ") + id + " (jdem/inlet)";
  if (jdem_restart_peek_shared(buf, 3) != (double)spec.n)
    error->all(FLERR, (who + ": the restart file's stream has another section (another number "
                             "of particles): give the SECTION file of the run that wrote it").c_str());
  const JdemRestartState st =
      jdem_restart_read_state(lmp, buf, who, INLET_SHARED_HEAD + 2 * spec.n, 0);
  const double *s = st.shared.data();
  if (s[0] == 0.0) return; /* written before the stream started */
  spec.dt = s[1];
  spec.overlap_tol = JD_INLET_OVERLAP_TOL;
  spec.stop_step = jdem_restart_unpack_i64(s[2]);
  cursor.resize(spec.n);
  for (size_t p = 0; p < spec.n; p++) {
    cursor[p].copy = jdem_restart_unpack_i64(s[INLET_SHARED_HEAD + 2 * p]);
    cursor[p].step = jdem_restart_unpack_i64(s[INLET_SHARED_HEAD + 2 * p + 1]);
  }
  stream.cursor = cursor.data();
  stream.started = jdem_restart_unpack_i64(s[4]);
  stream.stop_step = jdem_restart_unpack_i64(s[5]);
  stream.next_step = jdem_restart_unpack_i64(s[6]);
  stream.inserted = jdem_restart_unpack_i64(s[7]);
  energy_in = s[8];
  stream.skipped = jdem_restart_unpack_i64(s[9]);
  next_reneighbor = stream.next_step == JD_INLET_NEVER ? -1 : stream.next_step;
  started = true;
}
