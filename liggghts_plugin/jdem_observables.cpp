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

#include "dump_h5md_jdem.h"
#include "fix_bond_jiang.h"
#include "fix_jdem_watchdog.h"
#include "fix_jdem_loads.h"
#include "fix_wall_jiang.h"
#include "jdem_kernel.h"
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
