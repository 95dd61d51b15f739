/* fix_wall_jiang.h — `fix wall/jiang`: a particle–wall contact through jdem's C kernel.
 *
 *   fix ID group wall/jiang plane corners x1 y1 z1 x2 y2 z2 x3 y3 z3 x4 y4 z4 type T
 *                           [velocity vx vy vz]
 *   fix ID group wall/jiang cylinder axis x1 y1 z1 x2 y2 z2 radius R side outside|inside type T
 *                           [velocity vx vy vz]
 *
 * The plane is a finite quadrilateral, counter-clockwise seen from the active side (normal
 * (P2-P1) x (P3-P1)); the cylinder is the lateral surface of the axis segment.  T is the
 * wall's atom type: its coefficients (restitution, friction, rolling friction against each
 * particle type) come from the same fix property/global tables as gran/jiang's.  The particle's
 * own E and nu give the wall stiffness (jd_kn_wall, rule from pair_style gran/jiang).  Moving
 * walls translate at the given velocity (x += v dt every step, as the standalone engine).
 * Requires pair_style gran/jiang defined before the fix.  Geometry: kernel/jdem_geometry.h.
 *
 * History: one contact record per atom in gran/jiang's layout (jdem_history.h: jd_contact_state,
 * + jd_rolling_state with rolling on, or only their law fields with energy no), migrating with
 * the atom; reset when the particle leaves the wall.
 *
 * Cost: each step only the particles found near the wall at the last neighbour build are
 * evaluated (with neigh_modify every 1 delay 0; see refresh_candidates). */
#ifndef JDEM_FIX_WALL_JIANG_H
#define JDEM_FIX_WALL_JIANG_H

#include <vector>

#include "fix.h"

#include "jdem_dispatch.h"
#include "jdem_geometry.h"
#include "jdem_overlap.h"

struct jd_h5md_wall;

namespace LAMMPS_NS {

class FixWallJiang : public Fix {
 public:
  int wall_type() const { return wtype; } /* the wall's atom type (material) */
  /* The wall for the trajectory (io/h5md.h): its geometry at time 0, i.e. now (`time` [s])
   * less velocity x time, its velocity, and the fix ID as its name. */
  void output_geometry(jd_h5md_wall *w, double time) const;
  FixWallJiang(class LAMMPS *, int, char **);
  ~FixWallJiang();
  int setmask();
  void init();
  void setup(int);
  void post_force(int);

  void grow_arrays(int);
  void copy_arrays(int, int, int);
  void set_arrays(int);
  int pack_exchange(int, double *);
  int unpack_exchange(int, double *);
  double memory_usage();

  /* Observables of this rank: cumulative dissipation and wall work [J]; at the last force
   * evaluation the elastic energy [J] and the number of wall contacts carrying force. */
  double e_damp_cum, e_fric_cum, work_cum, e_elastic_now, contacts_now;

  /* As PairGranJiang's: set by fix jdem/watchdog; INFINITY (the default): never. */
  double overlap_limit;
  JdOverlapTrip overlap_trip;

 private:
  template <unsigned F> JD_SPECIALISED void loop(bool commit);
  void compute(bool commit);
  void refresh_candidates();

  int shape; /* 0 plane, 1 cylinder */
  jd_plane plane;
  jd_cylinder cyl;
  double vel[3];
  int wtype;
  int slen; /* doubles of history per atom */
  double **hist;
  int nmax_hist;
  class PairGranJiang *pair;

  /* Candidate list (refresh_candidates): local indices of the particles that can touch the
   * wall before the next neighbour build; valid while LIGGGHTS' neighbour count is cand_ncalls,
   * nlocal is cand_nlocal and the wall has moved by less than skin/2 (shift) since. */
  bool use_candidates;
  std::vector<int> candidates;
  bigint cand_ncalls;
  int cand_nlocal;
  double shift[3];
};

}  // namespace LAMMPS_NS

#endif
