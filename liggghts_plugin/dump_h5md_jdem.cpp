/* dump_h5md_jdem.cpp — see dump_h5md_jdem.h.  Gathers the per-atom data to rank 0 (one
 * MPI_Gatherv per frame), sorts it by id and hands it to jd_h5md_*. */
#include "dump_h5md_jdem.h"

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <sstream>
#include <unistd.h>

#include "atom.h"
#include "error.h"
#include "force.h"
#include "modify.h"
#include "output.h"
#include "update.h"

#include "fix_jdem_domain.h"
#include "fix_jdem_inlet.h"
#include "fix_wall_jiang.h"
#include "fix_wall_jiang_mesh.h"
#include "h5md.h"
#include "h5md_resume.h"
#include "jdem_observables.h"
#include "pair_gran_jiang.h"

using namespace LAMMPS_NS;

int jdem_dump_close_ok = 0;
int jdem_dump_close_failed = 0;

#include "source_commit.h" /* JDEM_SOURCE_COMMIT (Makefile) */

#ifndef JDEM_VERSION
#define JDEM_VERSION "0.1.0"
#endif

enum { COL_ID = 0, COL_TYPE, COL_R, COL_M, COL_X, COL_V = COL_X + 3, COL_W = COL_V + 3,
       COL_F = COL_W + 3, COL_T = COL_F + 3, NCOL = COL_T + 3 };

DumpH5mdJdem::DumpH5mdJdem(LAMMPS *lmp, int narg, char **arg)
    : Dump(lmp, narg, arg), h5(NULL), energy(true), grow(-1), natoms0(-1), last_step(-1), observables_every(0), stop_frame(false),
      resume_step(-1), resume_opened(false) {
  if (narg < 5) error->all(FLERR, "Illegal dump h5md/jdem command: dump ID group h5md/jdem N FILE.h5");
  frame_every = force->inumeric(FLERR, arg[3]);
  path = arg[4];
  if (path.find('*') != std::string::npos || path.find('%') != std::string::npos)
    error->all(FLERR, "dump h5md/jdem writes one file: no '*' or '%' in the file name");
  for (int i = 5; i < narg; i += 2) {
    if (i + 1 >= narg) error->all(FLERR, "dump h5md/jdem: keyword without a value");
    const std::string k = arg[i];
    if (k == "scene") scene_name = arg[i + 1];
    else if (k == "case") case_name = arg[i + 1];
    else if (k == "scene_yaml") {
      if (me == 0) {
        std::ifstream in(arg[i + 1]);
        if (!in) error->one(FLERR, "dump h5md/jdem: cannot read the scene_yaml file");
        std::stringstream ss;
        ss << in.rdbuf();
        scene_yaml = ss.str();
      }
    } else if (k == "energy") {
      if (std::strcmp(arg[i + 1], "yes") == 0) energy = true;
      else if (std::strcmp(arg[i + 1], "no") == 0) energy = false;
      else error->all(FLERR, "dump h5md/jdem: energy must be yes or no");
    } else if (k == "grow") {
      if (std::strcmp(arg[i + 1], "yes") == 0) grow = 1;
      else if (std::strcmp(arg[i + 1], "no") == 0) grow = 0;
      else error->all(FLERR, "dump h5md/jdem: grow must be yes or no");
    } else if (k == "resume") {
      /* the dump is defined after read_restart: this step is the one the file was written at */
      if (std::strcmp(arg[i + 1], "yes") == 0) resume_step = update->ntimestep;
      else if (std::strcmp(arg[i + 1], "no") != 0)
        error->all(FLERR, "dump h5md/jdem: resume must be yes or no");
    } else {
      error->all(FLERR, "dump h5md/jdem: unknown keyword (valid: scene, case, scene_yaml, energy, "
                 "grow, resume)");
    }
  }
  size_one = NCOL;

}

DumpH5mdJdem::~DumpH5mdJdem() {
  if (h5) {
    char err[1024] = "";
    if (jd_h5md_close(h5, jdem_dump_close_ok, err, sizeof err) != 0) {
      /* no Error::all in a destructor: the message goes to stderr and the log (also under
       * -screen none), and liggghts-jdem's exit status says the output failed */
      std::fprintf(stderr, "ERROR: dump h5md/jdem: closing %s failed: %s\n", path.c_str(), err);
      if (logfile) std::fprintf(logfile, "ERROR: dump h5md/jdem: closing %s failed: %s\n", path.c_str(), err);
      jdem_dump_close_failed = 1;
    }
    h5 = NULL;
  }
}

void DumpH5mdJdem::init_style() {
  if (!atom->sphere_flag || !atom->rmass_flag)
    error->all(FLERR, "dump h5md/jdem requires atom_style granular (sphere)");
  if (!atom->tag_enable) error->all(FLERR, "dump h5md/jdem requires atom IDs");
}

namespace {
struct RowById {
  const double *buf;
  bool operator()(int a, int b) const { return buf[a * NCOL + COL_ID] < buf[b * NCOL + COL_ID]; }
};
}  // namespace

void DumpH5mdJdem::write() {
  gather_mesh_walls(last_step < 0);
  if (resume_step >= 0 && update->ntimestep <= resume_step) {
    /* the interrupted run wrote this step's frame and samples (or the uninterrupted run writes
     * none here): they are in the copied prefix */
    open_resumed();
    last_step = update->ntimestep;
    return;
  }
  if (resume_step >= 0) open_resumed();
  const int nlocal = atom->nlocal;
  const int *mask = atom->mask, *tag = atom->tag, *type = atom->type;
  double **x = atom->x, **v = atom->v, **omega = atom->omega, **f = atom->f, **torque = atom->torque;
  const double *radius = atom->radius, *rmass = atom->rmass;

  /* pack my atoms */
  std::vector<double> mine;
  for (int i = 0; i < nlocal; i++) {
    if (!(mask[i] & groupbit)) continue;
    double row[NCOL];
    row[COL_ID] = tag[i];
    row[COL_TYPE] = type[i];
    row[COL_R] = radius[i];
    row[COL_M] = rmass[i];
    for (int d = 0; d < 3; d++) {
      row[COL_X + d] = x[i][d];
      row[COL_V + d] = v[i][d];
      row[COL_W + d] = omega[i][d];
      row[COL_F + d] = f[i][d];
      row[COL_T + d] = torque[i][d];
    }
    mine.insert(mine.end(), row, row + NCOL);
  }

  /* the observables, summed on rank 0 */
  double all_obs[JDO_N];
  reduce_observables(all_obs);
  const bool sample = stop_frame || observables_due(update->ntimestep);

  /* gather the rows on rank 0 */
  const std::vector<double> all = jdem_gather_rows(world, mine);

  int failed = 0;
  char err[512] = "";
  const double dt = update->dt;
  const bigint step = update->ntimestep;
  const double time = update->atime + (double)(step - update->atimestep) * dt;
  if (me == 0) {
    const size_t nat = all.size() / NCOL;
    std::vector<int> order(nat);
    for (size_t i = 0; i < nat; i++) order[i] = (int)i;
    RowById cmp = {all.data()};
    std::sort(order.begin(), order.end(), cmp);

    /* one spare row: a frame without atoms (before an insertion) still hands the writer arrays */
    std::vector<double> pos(3 * nat + 3), vel(3 * nat + 3), angv(3 * nat + 3), frc(3 * nat + 3),
        trq(3 * nat + 3);
    for (size_t i = 0; i < nat; i++) {
      const double *row = &all[(size_t)order[i] * NCOL];
      for (int d = 0; d < 3; d++) {
        pos[3 * i + d] = row[COL_X + d];
        vel[3 * i + d] = row[COL_V + d];
        angv[3 * i + d] = row[COL_W + d];
        frc[3 * i + d] = row[COL_F + d];
        trq[3 * i + d] = row[COL_T + d];
      }
    }

    if (!h5) {
      if (grow < 0) grow = insertion_fix() ? 1 : 0;
      failed = create_file(all, order, dt, err, sizeof err);
      natoms0 = (bigint)nat;
    } else if (!grow && (bigint)nat != natoms0) {
      std::snprintf(err, sizeof err, "the number of atoms changed (%ld -> %ld); give the dump "
                    "'grow yes' for a particle set that changes", (long)natoms0, (long)nat);
      failed = 1;
    }
    jd_h5md_particles frame_rows;
    if (!failed && grow) {
      place_rows(all, order, pos, vel, angv, frc, trq);
      frame_rows.n = row_id.size();
      frame_rows.id = frame_id.data();
      frame_rows.species = row_species.data();
      frame_rows.radius = row_radius.data();
      frame_rows.mass = row_mass.data();
      frame_rows.growing = 1;
    }
    if (!failed) {
      jd_h5md_frame fr;
      fr.step = (int64_t)step;
      fr.time = time;
      fr.position = pos.data();
      fr.velocity = vel.data();
      fr.angular_velocity = angv.data();
      fr.force = frc.data();
      fr.torque = trq.data();
      fr.rows = grow ? &frame_rows : NULL;
      for (size_t k = 0; k < moved_meshes.size() && !failed; k++)
        if (jd_h5md_move_mesh(h5, moved_meshes[k].first,
                              (const double(*)[3][3])mesh_tris[moved_meshes[k].second].data(), err,
                              sizeof err) != 0)
          failed = 1;
      if (!failed && jd_h5md_write_frame(h5, &fr, err, sizeof err) != 0) failed = 1;
    }
    if (!failed && sample && write_contact_observables(all_obs, step, time, err, sizeof err) != 0)
      failed = 1;
  }
  /* bonds (collective); rank 0 holds a file unless the frame failed */
  MPI_Bcast(&failed, 1, MPI_INT, 0, world);
  if (!failed && bonds.write(lmp, h5, err, sizeof err) != 0) failed = 1;
  if (me == 0 && !failed && sample && write_bond_observables(all_obs, step, time, err, sizeof err) != 0)
    failed = 1;
  /* Like the standalone engine, also write the last step of the run when it is not a multiple of
   * N: Output::write() adds N to next_dump after this call, so aim N steps short of it.  (At
   * set-up Output::setup() overwrites next_dump; a run shorter than N gets no last frame.) */
  for (int k = 0; k < output->ndump; k++)
    if (output->dump[k] == this) {
      const bigint every = output->every_dump[k], last = update->laststep;
      if (every > 0 && step < last && step + every > last) output->next_dump[k] = last - every;
    }

  last_step = step;
  MPI_Bcast(&failed, 1, MPI_INT, 0, world);
  if (failed) {
    MPI_Bcast(err, sizeof err, MPI_CHAR, 0, world);
    std::string msg = std::string("dump h5md/jdem: ") + err;
    error->all(FLERR, msg.c_str());
  }
}

/* A fix that adds or deletes atoms during the run: LIGGGHTS' insertion fixes (insert/pack,
 * insert/stream, insert/rate/region, ...), jdem's inlet and jdem's domain.  With one, the dump
 * writes a growing set (a deleted atom's row is empty). */
bool DumpH5mdJdem::insertion_fix() const {
  for (int k = 0; k < modify->nfix; k++) {
    const char *style = modify->fix[k]->style;
    if (std::strncmp(style, "insert/", 7) == 0 || std::strcmp(style, "jdem/inlet") == 0 ||
        std::strcmp(style, "jdem/domain") == 0)
      return true;
  }
  return false;
}

/* Rank 0, first frame: the file, its particle set (the atoms now, sorted by id) and walls. */
int DumpH5mdJdem::create_file(const std::vector<double> &all, const std::vector<int> &order,
                              double dt, char *err, size_t errlen) {
  const size_t nat = order.size();
  std::vector<int64_t> ids(nat);
  std::vector<int32_t> species(nat);
  std::vector<double> rad(nat), mass(nat);
  for (size_t i = 0; i < nat; i++) {
    const double *row = &all[(size_t)order[i] * NCOL];
    ids[i] = (int64_t)row[COL_ID];
    species[i] = (int32_t)row[COL_TYPE] - 1;
    rad[i] = row[COL_R];
    mass[i] = row[COL_M];
  }
  jd_h5md_particles parts;
  parts.n = nat;
  parts.id = ids.data();
  parts.species = species.data();
  parts.radius = rad.data();
  parts.mass = mass.data();
  parts.growing = grow;
  return open_file(parts, dt, err, errlen);
}

/* Rank 0: the file with the particle set `parts` (a growing set's first rows) and the walls. */
int DumpH5mdJdem::open_file(const jd_h5md_particles &parts, double dt, char *err, size_t errlen) {
  if (parts.growing) {
    row_id.assign(parts.id, parts.id + parts.n);
    row_species.assign(parts.species, parts.species + parts.n);
    row_radius.assign(parts.radius, parts.radius + parts.n);
    row_mass.assign(parts.mass, parts.mass + parts.n);
    for (size_t i = 0; i < parts.n; i++)
      if (parts.id[i] >= 0) row_of[parts.id[i]] = i;
  }
  jd_h5md_meta meta;
  std::memset(&meta, 0, sizeof meta);
  meta.creator = "liggghts-jdem";
  meta.creator_version = JDEM_VERSION "+" JDEM_SOURCE_COMMIT;
  meta.scene_name = scene_name.empty() ? NULL : scene_name.c_str();
  meta.case_name = case_name.empty() ? NULL : case_name.c_str();
  meta.scene_yaml = scene_yaml.empty() ? NULL : scene_yaml.c_str();
  meta.dt = dt;
  h5 = jd_h5md_create(path.c_str(), &meta, &parts, err, errlen);
  if (!h5) return 1;
  std::vector<jd_h5md_wall> walls;
  const double now = update->atime + (double)(update->ntimestep - update->atimestep) * dt;
  for (int k = 0; k < modify->nfix; k++) {
    const FixWallJiang *w = dynamic_cast<FixWallJiang *>(modify->fix[k]);
    if (!w || w->is_mesh()) continue;
    walls.push_back(jd_h5md_wall());
    w->output_geometry(&walls.back(), now);
  }
  /* then the meshes, as build/jdem orders its walls; a moved mesh's triangles at every frame */
  moved_meshes.clear();
  size_t m = 0;
  for (int f = 0; f < modify->nfix; f++) {
    const FixWallJiangMesh *w = dynamic_cast<FixWallJiangMesh *>(modify->fix[f]);
    for (size_t k = 0; w && k < w->n_meshes(); k++, m++) {
      jd_h5md_wall wall;
      std::memset(&wall, 0, sizeof wall);
      wall.name = w->mesh_name(k);
      wall.type = 2;
      wall.n_triangles = mesh_tris[m].size() / 9;
      wall.triangles = (const double(*)[3][3])mesh_tris[m].data();
      wall.moved = w->mesh_moves(k);
      if (wall.moved) moved_meshes.push_back(std::make_pair(walls.size(), m));
      walls.push_back(wall);
    }
  }
  return jd_h5md_set_walls(h5, walls.size(), walls.empty() ? NULL : walls.data(), err, errlen) != 0;
}

/* Collective: the triangles of each mesh of the fixes wall/jiang mesh into mesh_tris (rank 0),
 * in the order of the walls after the plane and cylinder walls: all of them (first frame), else
 * those LIGGGHTS moves (the others are drawn where they were at the first frame). */
void DumpH5mdJdem::gather_mesh_walls(bool all) {
  size_t m = 0;
  for (int f = 0; f < modify->nfix; f++) {
    FixWallJiangMesh *w = dynamic_cast<FixWallJiangMesh *>(modify->fix[f]);
    for (size_t k = 0; w && k < w->n_meshes(); k++, m++) {
      if (mesh_tris.size() <= m) mesh_tris.resize(m + 1);
      if (all || w->mesh_moves(k)) mesh_tris[m] = w->gather_triangles(k);
    }
  }
}

/* Rank 0, resume yes: the interrupted run's OUT.part moved aside, a fresh OUT.part with its
 * particle rows and its prefix up to resume_step copied in (io/h5md_resume.h). */
int DumpH5mdJdem::resume_file(char *err, size_t errlen) {
  char src[4200];
  /* the interrupted run's last frame at or before resume_step; it may have been killed before
   * the frame after it */
  const bigint prefix_frame = resume_step - resume_step % frame_every;
  if (jd_h5md_resume_source(path.c_str(), (int64_t)prefix_frame, src, sizeof src, err, errlen) != 0)
    return 1;
  jd_h5md_particles rows;
  if (jd_h5md_resume_rows(src, (int64_t)resume_step, &rows, err, errlen) != 0) return 1;
  grow = rows.growing;
  natoms0 = (bigint)rows.n;
  int failed = open_file(rows, update->dt, err, errlen);
  jd_h5md_resume_rows_free(&rows);
  if (!failed && jd_h5md_resume_copy(src, h5, (int64_t)resume_step, (int64_t)resume_step, err,
                                     errlen) != 0)
    failed = 1;
  if (!failed) unlink(src); /* its prefix is in OUT.part now, flushed */
  return failed;
}

/* Collective, resume yes: resume_file on rank 0, once, before the first frame or observable
 * sample (the run may resume between two frames). */
void DumpH5mdJdem::open_resumed() {
  if (resume_opened) return;
  resume_opened = true;
  int failed = 0;
  char err[1024] = "";
  if (me == 0) failed = resume_file(err, sizeof err);
  MPI_Bcast(&failed, 1, MPI_INT, 0, world);
  if (failed) {
    MPI_Bcast(err, sizeof err, MPI_CHAR, 0, world);
    error->all(FLERR, (std::string("dump h5md/jdem: ") + err).c_str());
  }
}

/* Rank 0, growing set: the rows of this frame.  An atom keeps the row it got when it first
 * appeared; atoms new since the last frame get new rows in id order (order is by id); the row
 * of an atom that is gone is empty (id -1).  The vectors, sorted by id on entry, come back in
 * row order. */
void DumpH5mdJdem::place_rows(const std::vector<double> &all, const std::vector<int> &order,
                              std::vector<double> &pos, std::vector<double> &vel,
                              std::vector<double> &angv, std::vector<double> &frc,
                              std::vector<double> &trq) {
  for (size_t i = 0; i < order.size(); i++) {
    const double *row = &all[(size_t)order[i] * NCOL];
    const int64_t id = (int64_t)row[COL_ID];
    if (row_of.count(id)) continue;
    row_of[id] = row_id.size();
    row_id.push_back(id);
    row_species.push_back((int32_t)row[COL_TYPE] - 1);
    row_radius.push_back(row[COL_R]);
    row_mass.push_back(row[COL_M]);
  }
  const size_t nrows = row_id.size();
  frame_id.assign(nrows, -1);
  std::vector<double> *vecs[5] = {&pos, &vel, &angv, &frc, &trq};
  std::vector<double> by_row[5];
  for (int k = 0; k < 5; k++) by_row[k].assign(3 * nrows + 3, 0.0); /* + the spare row */
  for (size_t i = 0; i < order.size(); i++) {
    const int64_t id = (int64_t)all[(size_t)order[i] * NCOL + COL_ID];
    const size_t r = row_of[id];
    frame_id[r] = id;
    for (int k = 0; k < 5; k++)
      for (int d = 0; d < 3; d++) by_row[k][3 * r + d] = (*vecs[k])[3 * i + d];
  }
  for (int k = 0; k < 5; k++) vecs[k]->swap(by_row[k]);
}

void DumpH5mdJdem::reduce_observables(double all_obs[JDO_N]) {
  double obs[JDO_N];
  jdem_local_observables(lmp, groupbit, obs);
  MPI_Reduce(obs, all_obs, JDO_N, MPI_DOUBLE, MPI_SUM, 0, world);
  jdem_wall_observables(lmp, wall_names, wall_values);
}

bool DumpH5mdJdem::observables_due(bigint step) const {
  return observables_every <= 0 || step == 0 || step == update->laststep ||
         step % observables_every == 0;
}

/* Rank 0: the contact observables of this sample; the kinetic, rotational and gravitational
 * energies always, the others with pair_style gran/jiang (the energies not with energy no). */
int DumpH5mdJdem::write_contact_observables(const double all_obs[JDO_N], bigint step, double time,
                                            char *err, size_t errlen) {
  const bool pair = dynamic_cast<PairGranJiang *>(force->pair) != NULL;
  for (int k = 0; k < JD_N_OBSERVABLES; k++) {
    const bool always = k == JDO_KINETIC || k == JDO_ROTATIONAL || k == JDO_GRAVITATIONAL;
    if ((always || (pair && (energy || !jd_observable_is_energy[k]))) &&
        jd_h5md_write_observable(h5, jd_observable_names[k], (int64_t)step, time, all_obs[k], err,
                                 errlen) != 0)
      return -1;
  }
  bool inlets = false; /* the inflow, as the stepper writes it with inlets */
  double inflow = 0.0, skipped = 0.0;
  for (int k = 0; k < modify->nfix; k++) {
    const FixJdemInlet *in = dynamic_cast<FixJdemInlet *>(modify->fix[k]);
    if (in) inflow += in->inflow_energy(), skipped += (double)in->skipped(), inlets = true;
  }
  if (inlets && (jd_h5md_write_observable(h5, jd_obs_inlet_energy, (int64_t)step, time, inflow,
                                          err, errlen) != 0 ||
                 jd_h5md_write_observable(h5, jd_obs_skipped_particles, (int64_t)step, time,
                                          skipped, err, errlen) != 0))
    return -1;
  for (int k = 0; k < modify->nfix; k++) /* the outflow, as the stepper writes it with a domain */
    if (const FixJdemDomain *d = dynamic_cast<FixJdemDomain *>(modify->fix[k]))
      if (jd_h5md_write_observable(h5, jd_obs_lost_particles, (int64_t)step, time,
                                   d->lost_particles(), err, errlen) != 0 ||
          jd_h5md_write_observable(h5, jd_obs_lost_energy, (int64_t)step, time, d->lost_energy(),
                                   err, errlen) != 0)
        return -1;
  for (size_t k = 0; k < wall_names.size(); k++)
    if (jd_h5md_write_observable(h5, wall_names[k].c_str(), (int64_t)step, time, wall_values[k],
                                 err, errlen) != 0)
      return -1;
  return 0;
}

/* Rank 0: the bond observables of this sample, when some fix bond/jiang exists (the energies
 * not with energy no). */
int DumpH5mdJdem::write_bond_observables(const double all_obs[JDO_N], bigint step, double time,
                                         char *err, size_t errlen) {
  if (!bonds.active()) return 0;
  const double bv[JD_N_BOND_OBSERVABLES] = {bonds.bonds(), bonds.fragments(),
                                            all_obs[JDO_BOND_ELASTIC], all_obs[JDO_BOND_DAMPING],
                                            all_obs[JDO_BOND_BREAKAGE]};
  for (int k = 0; k < JD_N_BOND_OBSERVABLES; k++)
    if ((energy || !jd_bond_observable_is_energy[k]) &&
        jd_h5md_write_observable(h5, jd_bond_observable_names[k], (int64_t)step, time, bv[k], err,
                                 errlen) != 0)
      return -1;
  return 0;
}

void DumpH5mdJdem::write_observable_sample() {
  if (resume_step >= 0 && update->ntimestep <= resume_step) return; /* in the copied prefix */
  if (resume_step >= 0) open_resumed();
  double all_obs[JDO_N];
  reduce_observables(all_obs);
  bonds.count(lmp);
  const bigint step = update->ntimestep;
  const double time = update->atime + (double)(step - update->atimestep) * update->dt;
  int failed = 0;
  char err[512] = "";
  if (me == 0) {
    if (!h5) std::snprintf(err, sizeof err, "no frame written before the observables of step %ld", (long)step);
    failed = !h5 || write_contact_observables(all_obs, step, time, err, sizeof err) != 0 ||
             write_bond_observables(all_obs, step, time, err, sizeof err) != 0;
  }
  MPI_Bcast(&failed, 1, MPI_INT, 0, world);
  if (failed) {
    MPI_Bcast(err, sizeof err, MPI_CHAR, 0, world);
    error->all(FLERR, (std::string("dump h5md/jdem: ") + err).c_str());
  }
}
