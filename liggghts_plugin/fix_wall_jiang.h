/* fix_wall_jiang.h — `fix wall/jiang`: a particle–wall contact through jdem's C kernel.
 *
 *   fix ID group wall/jiang plane corners x1 y1 z1 x2 y2 z2 x3 y3 z3 x4 y4 z4 type T
 *                           [velocity vx vy vz] [name NAME]
 *                           [servo target S gain G tolerance E max_speed V hold H]
 *   fix ID group wall/jiang cylinder axis x1 y1 z1 x2 y2 z2 radius R side outside|inside type T
 *                           [velocity vx vy vz]
 *   either with [until_step S]: the wall vanishes, from the forces of step S on (a LIGGGHTS
 *   user's unfix at S, in one run; build/jdem's `until`): its contacts end, the elastic energy
 *   their springs held booked as work the wall did (not with servo)
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
 * name NAME: the wall's total force (summed over the ranks, in rank order) becomes the
 * observables wall_force/NAME/{x,y,z}, and its contacts count in the boundary stress tensor
 * (jdem_observables.h).  servo (plane walls, with name): the wall moves along its normal by the
 * kernel's servo law (kernel/jdem_servo.h) instead of a velocity: S [Pa], G [m/(s Pa)], E [Pa],
 * V [m/s] (inf: no cap), H [s]; after every force evaluation the speed for the next step is set
 * from the measured stress; observables servo_stress/NAME and servo_position/NAME.
 *
 * Restart files (jdem_restart.h) carry where the wall is, how it moves, the servo's state, the
 * energies and the per-atom history: a wall of the same ID continues from them.
 *
 * Cost: each step only the particles found near the wall at the last neighbour build are
 * evaluated (with neigh_modify every 1 delay 0; see refresh_candidates). */
#ifndef JDEM_FIX_WALL_JIANG_H
#define JDEM_FIX_WALL_JIANG_H

#include <string>
#include <vector>

#include "fix.h"

#include "jdem_dispatch.h"
#include "jdem_geometry.h"
#include "jdem_overlap.h"
#include "jdem_servo.h"

struct jd_h5md_wall;

namespace LAMMPS_NS {

class FixWallJiang : public Fix {
 public:
  int wall_type() const { return wtype; } /* the wall's atom type (material) */
  bool is_mesh() const { return shape == 2; } /* fix wall/jiang mesh */
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

  /* restart files (jdem_restart.h) */
  void write_restart(FILE *);
  void restart(char *);
  int pack_restart(int, double *);
  void unpack_restart(int, int);
  int size_restart(int);
  int maxsize_restart();

  /* Observables of this rank: cumulative dissipation and wall work [J]; at the last force
   * evaluation the elastic energy [J] and the number of wall contacts carrying force. */
  double e_damp_cum, e_fric_cum, work_cum, e_elastic_now, contacts_now;

  /* name NAME (empty: none).  At the last force evaluation: the wall's total force over all
   * ranks [N], and this rank's contacts that carry force as contact points and forces on the
   * wall (3 per contact) for the stress tensor. */
  std::string name;
  double force_all[3];
  std::vector<double> contact_x, contact_f;
  /* servo: the law's state, measured stress [Pa], displacement along n [m] */
  bool servo;
  jd_servo_spec servo_spec;
  jd_servo_state servo_state;
  double servo_hold, servo_area, servo_stress, servo_speed, servo_position;
  /* the plane where it is now, for the stress tensor's box; NULL for a cylinder */
  const jd_plane *plane_wall() const { return shape == 0 ? &plane : NULL; }

  /* As PairGranJiang's: set by fix jdem/watchdog; INFINITY (the default): never. */
  double overlap_limit;
  JdOverlapTrip overlap_trip;

 protected:
  template <unsigned F> JD_SPECIALISED void loop(bool commit);
  template <unsigned F> void retire_loop();
  void compute(bool commit);
  void retire();
  void refresh_candidates();
  void sum_force_and_servo();
  void check_winding();
  void parse_servo(int narg, char **arg, int &iarg);

  int shape; /* 0 plane, 1 cylinder, 2 mesh (FixWallJiangMesh) */
  jd_plane plane;
  jd_cylinder cyl;
  double vel[3];
  double spin; /* cylinder: angular velocity about its axis, right-handed about a1 - a0 [rad/s] */
  bigint until_step; /* until_step S: gone from the forces of step S on (MAXBIGINT: never) */
  bool retired;      /* retire() has run: the wall is gone and its contacts are cleared */
  int wtype;
  int slen; /* doubles of history per atom (a mesh: JD_MESH_SLOTS x (normal, state)) */
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
