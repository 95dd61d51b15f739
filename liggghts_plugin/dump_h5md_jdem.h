/* dump_h5md_jdem.h — `dump ID group h5md/jdem N FILE.h5 [scene NAME] [case NAME]
 *                    [scene_yaml PATH] [energy yes|no] [grow yes|no] [resume yes|no]`: jdem's H5MD trajectory (io/h5md.h),
 * written on rank 0 through the shared C writer.
 *
 * Every N steps: position, velocity, angular velocity, force, torque of the group's atoms,
 * sorted by id (species = type - 1), and the observables kinetic_energy, rotational_energy,
 * gravitational_energy (with fix gravity) and, with pair_style gran/jiang and fix wall/jiang,
 * elastic_energy, damping_dissipation, friction_dissipation, wall_work, contacts,
 * wall_contacts; with fix bond/jiang the bonds formed and broken (/connectivity) and the
 * observables bonds, fragments, bond_elastic_energy, bond_damping_dissipation,
 * bond_breakage_energy (jdem_bond_output.h); with fix jdem/observables the observables on their
 * own cadence instead (fix_jdem_observables.h); also the last step of a run that is not a multiple of N (runs of at least N
 * steps), like build/jdem.  The file is FILE.h5.part while the run goes on and is renamed to FILE.h5
 * when LIGGGHTS ends normally or at `undump`; after an error it stays FILE.h5.part.  The optional keywords scene, case
 * and scene_yaml only annotate /parameters.  energy no (build/jdem's output.energy: false)
 * leaves out elastic_energy, damping_dissipation, friction_dissipation and wall_work, so that
 * pair_style gran/jiang can run without energy accounts (energy no).  grow yes writes a particle
 * set that changes (H5MD 1.1's time-dependent id, -1 in empty rows; an atom keeps its row, new
 * atoms get new rows in id order); the default is yes when the input has an insertion fix
 * (style insert/... or jdem/inlet) at the first frame, else the set must not change.  The
 * walls of every fix wall/jiang go to /jdem/walls, the meshes of fix wall/jiang mesh after the
 * planes and cylinders (their triangles at every frame when fix move/mesh moves them).  resume yes, in a script that continues an
 * interrupted run from its restart file (the dump defined after read_restart): the interrupted
 * run's FILE.h5.part (or FILE.h5.resume, after an interrupted resume) is moved to
 * FILE.h5.resume, and its frames, observables and bond tables up to the restart file's step
 * are copied into a fresh FILE.h5.part (io/h5md_resume.h), which the run then continues: the
 * result equals the uninterrupted run's trajectory when that run wrote its restart files at the
 * same steps. */
#ifndef JDEM_DUMP_H5MD_JDEM_H
#define JDEM_DUMP_H5MD_JDEM_H

#include <map>
#include <string>
#include <vector>

#include "dump.h"

#include "jdem_bond_output.h"
#include "jdem_observables.h"

struct jd_h5md;
struct jd_h5md_particles;

/* Set by liggghts-jdem's main() once the input script has finished, and around `undump`: the
 * dump's destructor then completes the file (PATH.part -> PATH).  Any other destruction is
 * LIGGGHTS' error path (Error::all deletes Output to flush dumps), which keeps PATH.part so that
 * an aborted run never looks complete. */
extern int jdem_dump_close_ok;
/* Set when a dump's final close failed (the result is not complete: its message is on stderr
 * and in the log); liggghts-jdem then exits with status 3, an I/O failure as in build/jdem. */
extern int jdem_dump_close_failed;

namespace LAMMPS_NS {

class DumpH5mdJdem : public Dump {
 public:
  DumpH5mdJdem(class LAMMPS *, int, char **);
  virtual ~DumpH5mdJdem();
  virtual void write();
  const std::string &file_name() const { return path; } /* FILE.h5 (FILE.h5.part while open) */
  /* A run stopped early (jdem_stop.h): write the frame of `step` and its observables unless it
   * is the last one written (collective, like write()). */
  void write_stop_frame(bigint step) {
    if (step == last_step) return;
    stop_frame = true; /* with its observables, whatever their cadence */
    write();
    stop_frame = false;
  }
  bigint last_frame_step() const { return last_step; } /* -1: no frame yet */
  bool writes_energy() const { return energy; }         /* keyword energy (default yes) */
  /* fix jdem/observables M: the observables at step 0, every M steps and the last step, as
   * build/jdem's output.observables_every (0, the default: at every frame). */
  void set_observables_every(bigint every) { observables_every = every; }
  bool observables_due(bigint step) const;
  /* The contact and bond observables of this step, between frames (collective; error->all on
   * failure). */
  void write_observable_sample();
  /* The ids of the particles ever bonded so far (rank 0; restart files keep them). */
  std::vector<int> ever_bonded_ids() const { return bonds.ever_bonded_ids(); }

 protected:
  virtual void init_style();
  virtual void write_header(bigint) {}
  virtual void pack(int *) {}
  virtual void write_data(int, double *) {}
  void reduce_observables(double all_obs[JDO_N]);
  int write_contact_observables(const double all_obs[JDO_N], bigint step, double time, char *err,
                                size_t errlen);
  int write_bond_observables(const double all_obs[JDO_N], bigint step, double time, char *err,
                             size_t errlen);
  bool insertion_fix() const;
  int create_file(const std::vector<double> &all, const std::vector<int> &order, double dt,
                  char *err, size_t errlen);
  int open_file(const struct jd_h5md_particles &parts, double dt, char *err, size_t errlen);
  int resume_file(char *err, size_t errlen);
  void gather_mesh_walls(bool all);
  void open_resumed();
  void place_rows(const std::vector<double> &all, const std::vector<int> &order,
                  std::vector<double> &pos, std::vector<double> &vel, std::vector<double> &angv,
                  std::vector<double> &frc, std::vector<double> &trq);

 private:
  struct jd_h5md *h5;
  std::string path, scene_name, case_name, scene_yaml;
  bool energy;
  int grow;       /* keyword grow: 1 yes, 0 no, -1 (default) yes when an insertion fix exists */
  bigint natoms0;
  /* growing set (rank 0): the particle of each row, its constants, and this frame's ids */
  std::map<int64_t, size_t> row_of;
  std::vector<int64_t> row_id, frame_id;
  std::vector<int32_t> row_species;
  std::vector<double> row_radius, row_mass;
  bigint last_step; /* of the last frame written; -1: none */
  bigint observables_every; /* steps between observable samples; 0: at the frames */
  /* this sample's wall observables (jdem_wall_observables), set by reduce_observables */
  std::vector<std::string> wall_names;
  std::vector<double> wall_values;
  bool stop_frame;          /* write() is writing the frame of a run stopped early */
  bigint resume_step;       /* resume yes: the step read_restart resumed at; -1: a new file */
  bool resume_opened;       /* resume yes: the file is open with the interrupted run's prefix */
  bigint frame_every;       /* N of `dump ID group h5md/jdem N FILE`: steps between frames */
  /* the mesh walls (after the plane and cylinder walls): each one's triangles [ntri][3][3] (rank
   * 0), and (wall index, mesh) of those LIGGGHTS moves, whose triangles go with every frame */
  std::vector<std::vector<double> > mesh_tris;
  std::vector<std::pair<size_t, size_t> > moved_meshes;
  JdemBondOutput bonds;
};

}  // namespace LAMMPS_NS

#endif
