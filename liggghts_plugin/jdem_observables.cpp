/* jdem_observables.cpp — see jdem_observables.h. */
#include "jdem_observables.h"

#include "atom.h"
#include "fix_gravity.h"
#include "force.h"
#include "lammps.h"
#include "modify.h"
#include "output.h"
#include "dump.h"
#include "fix.h"

#include <mpi.h>

#include "dump_h5md_jdem.h"
#include "fix_bond_jiang.h"
#include "fix_jdem_watchdog.h"
#include "fix_jdem_loads.h"
#include "fix_wall_jiang.h"
#include "jdem_kernel.h"
#include "jdem_servo.h"
#include "pair_gran_jiang.h"

namespace LAMMPS_NS {

void jdem_gravity(LAMMPS *lmp, double g[3]) {
  Modify *modify = lmp->modify;
  g[0] = g[1] = g[2] = 0.0;
  for (int k = 0; k < modify->nfix; k++) {
    FixGravity *fg = dynamic_cast<FixGravity *>(modify->fix[k]);
    if (!fg) continue;
    double gk[3];
    fg->get_gravity(gk);
    for (int d = 0; d < 3; d++) g[d] += gk[d];
  }
}

void jdem_local_observables(LAMMPS *lmp, int groupbit, double out[JDO_N]) {
  Atom *atom = lmp->atom;
  for (int k = 0; k < JDO_N; k++) out[k] = 0.0;
  double g[3];
  jdem_gravity(lmp, g);
  const int *mask = atom->mask;
  double **x = atom->x, **v = atom->v, **omega = atom->omega;
  for (int i = 0; i < atom->nlocal; i++) {
    if (!(mask[i] & groupbit)) continue;
    const double m = atom->rmass[i];
    out[JDO_KINETIC] += 0.5 * m * jd_dot(v[i], v[i]);
    out[JDO_ROTATIONAL] += 0.5 * jd_sphere_inertia(m, atom->radius[i]) * jd_dot(omega[i], omega[i]);
    out[JDO_GRAVITATIONAL] -= m * jd_dot(g, x[i]);
  }
  for (int k = 0; k < lmp->modify->nfix; k++) {
    FixJdemLoads *l = dynamic_cast<FixJdemLoads *>(lmp->modify->fix[k]);
    if (l) out[JDO_WALL_WORK] += l->work_cum; /* the external work (docs/scenes.md) */
  }
  for (int k = 0; k < lmp->modify->nfix; k++) {
    FixBondJiang *b = dynamic_cast<FixBondJiang *>(lmp->modify->fix[k]);
    if (!b) continue;
    out[JDO_BOND_ELASTIC] += b->e_elastic_now;
    out[JDO_BOND_DAMPING] += b->e_damp_cum;
    out[JDO_BOND_BREAKAGE] += b->e_broken_cum;
  }
  PairGranJiang *pair = dynamic_cast<PairGranJiang *>(lmp->force->pair);
  if (!pair) return;
  out[JDO_ELASTIC] += pair->e_elastic_now;
  out[JDO_DAMPING] += pair->e_damp_cum;
  out[JDO_FRICTION] += pair->e_fric_cum;
  out[JDO_CONTACTS] += pair->contacts_now;
  for (int k = 0; k < lmp->modify->nfix; k++) {
    FixWallJiang *w = dynamic_cast<FixWallJiang *>(lmp->modify->fix[k]);
    if (!w) continue;
    out[JDO_ELASTIC] += w->e_elastic_now;
    out[JDO_DAMPING] += w->e_damp_cum;
    out[JDO_FRICTION] += w->e_fric_cum;
    out[JDO_WALL_WORK] += w->work_cum;
    out[JDO_WALL_CONTACTS] += w->contacts_now;
  }
}

/* The stress tensor of the named walls' contacts on this rank, in the box of all plane walls. */
static void local_stress_tensor(Modify *modify, double sigma[9]) {
  std::vector<double> corners, normals;
  for (int k = 0; k < modify->nfix; k++) {
    FixWallJiang *w = dynamic_cast<FixWallJiang *>(modify->fix[k]);
    if (!w || !w->plane_wall()) continue;
    const jd_plane *p = w->plane_wall();
    for (int c = 0; c < 4; c++) corners.insert(corners.end(), p->p[c], p->p[c] + 3);
    normals.insert(normals.end(), p->n, p->n + 3);
  }
  double centre[3] = {0.0, 0.0, 0.0}, volume = 0.0, part[9];
  if (!normals.empty()) jd_servo_box(normals.size() / 3, corners.data(), normals.data(), centre, &volume);
  for (int k = 0; k < 9; k++) sigma[k] = 0.0;
  for (int k = 0; k < modify->nfix; k++) {
    FixWallJiang *w = dynamic_cast<FixWallJiang *>(modify->fix[k]);
    if (!w || w->name.empty()) continue;
    jd_stress_tensor(w->contact_f.size() / 3, w->contact_x.data(), w->contact_f.data(), centre,
                     volume, part);
    for (int c = 0; c < 9; c++) sigma[c] += part[c];
  }
}

void jdem_wall_observables(LAMMPS *lmp, std::vector<std::string> &names,
                           std::vector<double> &values) {
  names.clear();
  values.clear();
  Modify *modify = lmp->modify;
  for (int k = 0; k < modify->nfix; k++) {
    FixWallJiang *w = dynamic_cast<FixWallJiang *>(modify->fix[k]);
    if (!w || w->name.empty()) continue;
    for (int d = 0; d < 3; d++) {
      names.push_back(std::string(jd_obs_wall_force) + "/" + w->name + "/" + jd_obs_axes[d]);
      values.push_back(w->force_all[d]);
    }
    if (!w->servo) continue;
    names.push_back(std::string(jd_obs_servo_stress) + "/" + w->name);
    values.push_back(w->servo_stress);
    names.push_back(std::string(jd_obs_servo_position) + "/" + w->name);
    values.push_back(w->servo_position);
  }
  if (names.empty()) return;
  double sigma[9], all[9];
  local_stress_tensor(modify, sigma);
  MPI_Reduce(sigma, all, 9, MPI_DOUBLE, MPI_SUM, 0, lmp->world);
  for (int c = 0; c < 9; c++) {
    names.push_back(std::string(jd_obs_stress_tensor) + "/" + jd_obs_tensor_components[c]);
    values.push_back(all[c]);
  }
}

bool jdem_wants_energy(LAMMPS *lmp) {
  for (int k = 0; k < lmp->output->ndump; k++) {
    DumpH5mdJdem *d = dynamic_cast<DumpH5mdJdem *>(lmp->output->dump[k]);
    if (d && d->writes_energy()) return true;
  }
  for (int k = 0; k < lmp->modify->nfix; k++) {
    FixJdemWatchdog *w = dynamic_cast<FixJdemWatchdog *>(lmp->modify->fix[k]);
    if (w && w->checks_energy()) return true;
  }
  return false;
}

std::string jdem_contact_energy_user(LAMMPS *lmp) {
  for (int k = 0; k < lmp->output->ndump; k++) {
    DumpH5mdJdem *d = dynamic_cast<DumpH5mdJdem *>(lmp->output->dump[k]);
    if (d && d->writes_energy())
      return std::string("dump ") + d->id + " (h5md/jdem) writes the energy observables: add "
             "'energy no' to the dump";
  }
  for (int k = 0; k < lmp->modify->nfix; k++) {
    FixJdemWatchdog *w = dynamic_cast<FixJdemWatchdog *>(lmp->modify->fix[k]);
    if (w && w->checks_energy())
      return std::string("fix ") + w->id + " (jdem/watchdog) checks the energy balance: add "
             "'energy off' to the fix";
  }
  return std::string();
}

}  // namespace LAMMPS_NS
