/* fix_wall_jiang.cpp — see fix_wall_jiang.h.  Glue only: the geometry is jdem_geometry.h, the
 * law jd_contact(). */
#include "fix_wall_jiang.h"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <mpi.h>
#include <string>

#include "atom.h"
#include "error.h"
#include "force.h"
#include "group.h"
#include "memory.h"
#include "neighbor.h"
#include "update.h"

#include "h5md.h"
#include "jdem_dispatch.h"
#include "jdem_history.h"
#include "jdem_mesh.h"
#include "jdem_restart.h"
#include "jdem_watchdog.h"
#include "pair_gran_jiang.h"

using namespace LAMMPS_NS;
using namespace FixConst;

FixWallJiang::FixWallJiang(LAMMPS *lmp, int narg, char **arg)
    : Fix(lmp, narg, arg), e_damp_cum(0.0), e_fric_cum(0.0), work_cum(0.0),
      e_elastic_now(0.0), contacts_now(0.0), overlap_limit(INFINITY), shape(-1), wtype(0), slen(0), hist(NULL),
      nmax_hist(0), pair(NULL), use_candidates(false), cand_ncalls(-1), cand_nlocal(0) {
  servo = false;
  until_step = MAXBIGINT;
  retired = false;
  servo_state = jd_servo_state();
  servo_hold = servo_area = servo_stress = servo_speed = servo_position = 0.0;
  force_all[0] = force_all[1] = force_all[2] = 0.0;
  const char *usage =
      "Illegal fix wall/jiang command: fix ID group wall/jiang plane corners x1 y1 z1 x2 y2 z2 "
      "x3 y3 z3 x4 y4 z4 type T [velocity vx vy vz] [name NAME] [servo target S gain G tolerance "
      "E max_speed V hold H] | cylinder axis x1 y1 z1 x2 y2 z2 radius R side outside|inside type T "
      "[velocity vx vy vz] [omega W] [name NAME] | mesh n_meshes N meshes ID1 ... IDN";
  std::memset(&plane, 0, sizeof plane);
  std::memset(&cyl, 0, sizeof cyl);
  vel[0] = vel[1] = vel[2] = 0.0;
  spin = 0.0;
  int iarg = 3;
  if (narg < 4) error->all(FLERR, usage);
  const std::string kind = arg[iarg++];
  if (kind == "plane") {
    shape = 0;
    if (iarg + 13 > narg || std::strcmp(arg[iarg], "corners") != 0) error->all(FLERR, usage);
    iarg++;
    double c[4][3];
    for (int p = 0; p < 4; p++)
      for (int k = 0; k < 3; k++) c[p][k] = force->numeric(FLERR, arg[iarg++]);
    const int rc = jd_plane_init(&plane, c, 1e-9);
    if (rc == JD_GEOM_DEGENERATE) error->all(FLERR, "fix wall/jiang: P1, P2, P3 are collinear");
    if (rc == JD_GEOM_NOT_PLANAR) error->all(FLERR, "fix wall/jiang: the four corners are not coplanar");
  } else if (kind == "cylinder") {
    shape = 1;
    if (iarg + 7 > narg || std::strcmp(arg[iarg], "axis") != 0) error->all(FLERR, usage);
    iarg++;
    for (int k = 0; k < 3; k++) cyl.a0[k] = force->numeric(FLERR, arg[iarg++]);
    for (int k = 0; k < 3; k++) cyl.a1[k] = force->numeric(FLERR, arg[iarg++]);
    cyl.rc = -1.0;
    cyl.inside = 0;
  } else if (kind == "mesh") {
    shape = 2; /* FixWallJiangMesh reads the rest */
    iarg = narg;
  } else {
    error->all(FLERR, usage);
  }
  while (iarg < narg) {
    const std::string k = arg[iarg];
    if (k == "type" && iarg + 1 < narg) {
      wtype = force->inumeric(FLERR, arg[iarg + 1]);
      iarg += 2;
    } else if (k == "velocity" && iarg + 3 < narg) {
      for (int d = 0; d < 3; d++) vel[d] = force->numeric(FLERR, arg[iarg + 1 + d]);
      iarg += 4;
    } else if (k == "name" && iarg + 1 < narg) {
      name = arg[iarg + 1];
      iarg += 2;
    } else if (shape != 2 && k == "until_step" && iarg + 1 < narg) {
      char *end = NULL;
      const long long step = std::strtoll(arg[iarg + 1], &end, 10);
      if (end == arg[iarg + 1] || *end != '\0' || step < 1)
        error->all(FLERR, "fix wall/jiang: until_step must be a step >= 1");
      until_step = (bigint)step;
      iarg += 2;
    } else if (shape == 0 && k == "servo") {
      parse_servo(narg, arg, ++iarg);
    } else if (shape == 1 && k == "radius" && iarg + 1 < narg) {
      cyl.rc = force->numeric(FLERR, arg[iarg + 1]);
      iarg += 2;
    } else if (shape == 1 && k == "omega" && iarg + 1 < narg) {
      spin = force->numeric(FLERR, arg[iarg + 1]);
      if (!std::isfinite(spin)) error->all(FLERR, "fix wall/jiang: omega must be a finite angular velocity [rad/s]");
      iarg += 2;
    } else if (shape == 1 && k == "side" && iarg + 1 < narg) {
      const std::string s = arg[iarg + 1];
      if (s == "outside") cyl.inside = 0;
      else if (s == "inside") cyl.inside = 1;
      else error->all(FLERR, "fix wall/jiang: side must be outside or inside");
      iarg += 2;
    } else {
      error->all(FLERR, usage);
    }
  }
  if (shape != 2 && (wtype < 1 || wtype > atom->ntypes))
    error->all(FLERR, "fix wall/jiang: 'type T' is required, 1 <= T <= ntypes");
  if (shape == 1) {
    if (!(cyl.rc > 0.0)) error->all(FLERR, "fix wall/jiang: cylinder needs 'radius R' > 0");
    double ab[3];
    for (int k = 0; k < 3; k++) ab[k] = cyl.a1[k] - cyl.a0[k];
    if (!(jd_dot(ab, ab) > 0.0)) error->all(FLERR, "fix wall/jiang: the cylinder axis has zero length");
  }

  if (servo && until_step != MAXBIGINT)
    error->all(FLERR, "fix wall/jiang: a servo wall cannot vanish; no until_step with servo");
  if (servo && name.empty()) error->all(FLERR, "fix wall/jiang: a servo wall needs 'name NAME' (its observables)");
  if (servo && (vel[0] != 0.0 || vel[1] != 0.0 || vel[2] != 0.0))
    error->all(FLERR, "fix wall/jiang: a servo wall moves by its servo law; no velocity with servo");
  if (servo) servo_area = jd_servo_area(plane.p);
  shift[0] = shift[1] = shift[2] = 0.0;

  pair = dynamic_cast<PairGranJiang *>(force->pair);
  if (!pair) error->all(FLERR, "fix wall/jiang requires pair_style gran/jiang (defined before the fix)");
  slen = shape == 2 ? JD_MESH_SLOTS * (3 + pair->state_len()) : pair->state_len();

  create_attribute = 1;
  restart_global = restart_peratom = 1; /* jdem_restart.h */
  grow_arrays(atom->nmax);
  atom->add_callback(0);
  atom->add_callback(1);
}

/* servo target S gain G tolerance E max_speed V hold H, all five, in this order (the deck
 * generator writes them from the resolved scene); checked by the kernel once dt is known. */
void FixWallJiang::parse_servo(int narg, char **arg, int &iarg) {
  static const char *const keys[5] = {"target", "gain", "tolerance", "max_speed", "hold"};
  double value[5];
  for (int k = 0; k < 5; k++) {
    if (iarg + 1 >= narg || std::strcmp(arg[iarg], keys[k]) != 0)
      error->all(FLERR, "fix wall/jiang: servo needs target S gain G tolerance E max_speed V hold H");
    const std::string v = arg[iarg + 1];
    value[k] = (k == 3 && v == "inf") ? INFINITY : force->numeric(FLERR, arg[iarg + 1]);
    iarg += 2;
  }
  servo = true;
  servo_spec.target = value[0];
  servo_spec.gain = value[1];
  servo_spec.tolerance = value[2];
  servo_spec.max_speed = value[3];
  servo_hold = value[4];
  servo_spec.hold_steps = 1;
}

FixWallJiang::~FixWallJiang() {
  atom->delete_callback(id, 0);
  atom->delete_callback(id, 1);
  memory->destroy(hist);
}

int FixWallJiang::setmask() { return POST_FORCE; }

void FixWallJiang::init() {
  pair = dynamic_cast<PairGranJiang *>(force->pair);
  if (!pair) error->all(FLERR, "fix wall/jiang requires pair_style gran/jiang");
  if (pair->state_len() != slen)
    error->all(FLERR, "fix wall/jiang: pair_style gran/jiang changed its rolling or energy option after the wall was defined");
  if (!atom->radius_flag || !atom->rmass_flag || !atom->omega_flag || !atom->torque_flag)
    error->all(FLERR, "fix wall/jiang requires atom_style granular (sphere)");
  /* The candidate list relies on LIGGGHTS' guarantee that no atom has moved more than skin/2
   * since the last neighbour build when the forces are computed: true when the distance is
   * checked every step (or the lists are rebuilt every step), i.e. neigh_modify every 1
   * delay 0.  Otherwise every particle is tested every step. */
  use_candidates = neighbor->every == 1 && neighbor->delay == 0 && neighbor->skin > 0.0;
  cand_ncalls = -1;
  if (servo) {
    if (!(servo_hold > 0.0)) error->all(FLERR, "fix wall/jiang: servo hold must be > 0 [s]");
    servo_spec.hold_steps = jd_servo_hold_steps(servo_hold, update->dt);
    char msg[256];
    if (jd_servo_check(&servo_spec, msg, sizeof msg) != JD_SERVO_OK)
      error->all(FLERR, (std::string("fix wall/jiang: ") + msg).c_str());
  }
}

/* The set-up force evaluation does not advance the history (as LIGGGHTS' pair set-up).  It
 * tests every particle; the first step of the run builds the candidate list. */
void FixWallJiang::setup(int vflag) {
  cand_ncalls = -1;
  if (shape == 0) check_winding();
  if (jdem_restart_resuming(lmp)) return; /* the state read from the file stands */
  compute(false);
  sum_force_and_servo();
}

/* A plane acts on its active side only: a plane wound the wrong way lets every particle pass.
 * The group's particles over the quadrilateral are counted in front of it and behind it (over
 * all ranks) and judged by the kernel's rule (jd_plane_wound_away; a plane with no particle
 * over it has nothing to say yet: a later run's set-up, after an insertion, checks again). */
void FixWallJiang::check_winding() {
  double side[2] = {0.0, 0.0}, all[2]; /* in front, behind */
  for (int i = 0; i < atom->nlocal; i++) {
    if (!(atom->mask[i] & groupbit)) continue;
    const int s = jd_plane_side(&plane, atom->x[i]);
    if (s != 0) side[s > 0 ? 0 : 1] += 1.0;
  }
  MPI_Allreduce(side, all, 2, MPI_DOUBLE, MPI_SUM, world);
  if (!jd_plane_wound_away(all[0], all[1])) return;
  char msg[768];
  std::snprintf(msg, sizeof msg,
                "fix %s wall/jiang plane: its active side, normal (%g, %g, %g) = (P2-P1) x (P3-P1), "
                "faces away from the particles: all %.0f particles of group %s over the plane are "
                "behind it, so they would pass through it. List the corners counter-clockwise as "
                "seen from the particles: reverse their order (P4 P3 P2 P1), which turns the normal "
                "to (%g, %g, %g)",
                id, plane.n[0], plane.n[1], plane.n[2], all[1], group->names[igroup], 0.0 - plane.n[0],
                0.0 - plane.n[1], 0.0 - plane.n[2]);
  error->all(FLERR, msg);
}

void FixWallJiang::post_force(int vflag) {
  if (jd_wall_gone(update->ntimestep, until_step)) { /* vanished, once (the kernel's rule) */
    if (!retired) {
      retire();
      sum_force_and_servo();
      retired = true;
    }
    return;
  }
  /* translate the wall first: x += v dt per defining point, as the standalone engine does */
  if (vel[0] != 0.0 || vel[1] != 0.0 || vel[2] != 0.0) {
    const double dt = update->dt;
    for (int d = 0; d < 3; d++) {
      const double dx = vel[d] * dt;
      for (int c = 0; c < 4; c++) plane.p[c][d] += dx;
      cyl.a0[d] += dx;
      cyl.a1[d] += dx;
      shift[d] += dx;
    }
    if (servo) servo_position += servo_speed * dt;
  }
  if (use_candidates) {
    const double halfskin = 0.5 * neighbor->skin;
    if (neighbor->ncalls != cand_ncalls || atom->nlocal != cand_nlocal ||
        !(jd_dot(shift, shift) <= halfskin * halfskin))
      refresh_candidates();
  }
  compute(true);
  sum_force_and_servo();
}

/* With a name: the wall's force over all ranks, each rank's sum added in rank order (the same
 * bits on every rank); then the servo's speed for the next step, as build/jdem's walls.c. */
void FixWallJiang::sum_force_and_servo() {
  if (name.empty()) return;
  double local[3] = {0.0, 0.0, 0.0};
  for (size_t c = 0; c < contact_f.size(); c += 3)
    for (int d = 0; d < 3; d++) local[d] += contact_f[c + d];
  int nprocs = 1;
  MPI_Comm_size(world, &nprocs);
  std::vector<double> all(3 * (size_t)nprocs);
  MPI_Allgather(local, 3, MPI_DOUBLE, all.data(), 3, MPI_DOUBLE, world);
  force_all[0] = force_all[1] = force_all[2] = 0.0;
  for (int r = 0; r < nprocs; r++)
    for (int d = 0; d < 3; d++) force_all[d] += all[3 * (size_t)r + d];
  if (!servo) return;
  servo_stress = jd_servo_stress(force_all, plane.n, servo_area);
  servo_speed = jd_servo_speed(&servo_spec, &servo_state, servo_stress);
  for (int d = 0; d < 3; d++) vel[d] = servo_speed * plane.n[d];
}

/* The particles of the group that can touch the wall before the next neighbour build: each
 * moves at most skin/2 from where it is now (LIGGGHTS' rebuild criterion), and a moving wall at
 * most skin/2 before the list is refreshed (post_force).  The others do not touch the wall now,
 * so their history is reset here, as the full loop would reset it this step; until the next
 * refresh they cannot touch it, so nothing else would change it.  Ascending indices: the
 * forces and energies are summed in the same order as by the full loop. */
void FixWallJiang::refresh_candidates() {
  double **x = atom->x;
  const double *radius = atom->radius;
  const int *mask = atom->mask;
  const int nlocal = atom->nlocal;
  /* a servo wall can start moving at any step: its margin is always a moving wall's */
  const bool moving = servo || vel[0] != 0.0 || vel[1] != 0.0 || vel[2] != 0.0;
  const double margin = 0.5 * neighbor->skin * (moving ? 2.0 : 1.0);
  candidates.clear();
  for (int i = 0; i < nlocal; i++) {
    if (!(mask[i] & groupbit)) continue;
    const bool near = shape == 0 ? jd_geom_plane_near(&plane, x[i], radius[i], margin)
                                 : jd_geom_cylinder_near(&cyl, x[i], radius[i], margin);
    if (near) candidates.push_back(i);
    else
      for (int k = 0; k < slen; k++) hist[i][k] = 0.0;
  }
  cand_ncalls = neighbor->ncalls;
  cand_nlocal = nlocal;
  shift[0] = shift[1] = shift[2] = 0.0;
}

/* The wall has vanished: every contact ends, the work the wall does leaving it booked
 * (jd_wall_vanish_work, as build/jdem's force loops).  Once: afterwards no particle can touch
 * the wall, so the histories, the force and the energies stay zero (a run continued from a
 * restart file retires it again, on histories already empty). */
void FixWallJiang::retire() {
#define JD_RETIRE_LOOP(b) \
  case (b): retire_loop<(b)>(); break;
  JD_DISPATCH(pair->features(), JD_RETIRE_LOOP)
#undef JD_RETIRE_LOOP
}

template <unsigned F>
void FixWallJiang::retire_loop() {
  const int roll_at = pair->rolling_at();
  for (int i = 0; i < atom->nlocal; i++) {
    double *h = hist[i];
    if (F & JD_F_ENERGY) {
      JdHistory<F> hs(h, roll_at, false);
      work_cum += jd_wall_vanish_work(hs.st);
    }
    for (int k = 0; k < slen; k++) h[k] = 0.0;
  }
  e_elastic_now = contacts_now = 0.0;
  overlap_trip = JdOverlapTrip();
  contact_x.clear();
  contact_f.clear();
}

void FixWallJiang::compute(bool commit) {
#define JD_WALL_LOOP(b) \
  case (b): loop<(b)>(commit); break;
  JD_DISPATCH(pair->features(), JD_WALL_LOOP)
#undef JD_WALL_LOOP
}

template <unsigned F>
void FixWallJiang::loop(bool commit) {
  double **x = atom->x, **v = atom->v, **f = atom->f;
  double **omega = atom->omega, **torque = atom->torque;
  const double *radius = atom->radius, *rmass = atom->rmass;
  const int *type = atom->type, *mask = atom->mask;
  const int nlocal = atom->nlocal;
  const double dt = update->dt;
  const int roll_at = pair->rolling_at();
  pair->refresh_prefactors();
  const unsigned laws = jd_law_set_of_loop(F, pair->features()); /* with the run-time laws */
  const double *kw = pair->wall_prefactors();
  double e_damp = 0.0, e_fric = 0.0, e_el = 0.0, ncontacts = 0.0, work = 0.0;
  const int *tag = atom->tag;
  overlap_trip = JdOverlapTrip();
  contact_x.clear();
  contact_f.clear();
  /* the candidates (refresh_candidates), or every particle of the group */
  const bool listed = commit && use_candidates;
  const int n = listed ? (int)candidates.size() : nlocal;

  for (int c = 0; c < n; c++) {
    const int i = listed ? candidates[c] : c;
    if (!listed && !(mask[i] & groupbit)) continue;
    const double R = radius[i];
    double *h = hist[i];
    jd_contact_geom g;
    const int hit = shape == 0 ? jd_geom_plane(&plane, x[i], R, &g) : jd_geom_cylinder(&cyl, x[i], R, &g);
    if (!hit) {
      if (commit)
        for (int k = 0; k < slen; k++) h[k] = 0.0;
      continue;
    }
    if (g.delta > overlap_limit * R && /* skips the exact test's libm fmin call (pair loop) */
        jd_overlap_excessive(g.delta, R, INFINITY, overlap_limit))
      overlap_trip.note(g.delta, R, tag[i], 0, id);
    const double m = rmass[i];
    jd_geom_wall_material(F, &g, kw[i], m, jd_sphere_inertia(m, R));
    jd_kinematics k;
    jd_copy3(k.va, v[i]);
    jd_copy3(k.wa, omega[i]);
    if (shape == 1) /* the surface's velocity where the sphere touches it */
      jd_cylinder_surface_velocity(&cyl, vel, spin, x[i], g.ra, k.vb);
    else
      jd_copy3(k.vb, vel);
    k.wb[0] = k.wb[1] = k.wb[2] = 0.0;
    JdHistory<F> hs(h, roll_at, commit);
    jd_contact_result out;
    double f_prev[3] = {0.0, 0.0, 0.0};
    if (F & JD_F_ENERGY) jd_copy3(f_prev, hs.st->f_prev);
    const jd_pair_coeffs co = jd_wall_coeffs(&pair->coeffs(type[i], wtype));
    const int carries = jd_contact(laws, &co, &g, &k, dt, hs.st, hs.rs, &out);
    if (F & JD_F_ENERGY) {
      /* f_prev is booked only with the energies; the work also over the step a contact ends */
      work += jd_wall_work(f_prev, out.f, k.vb, dt);
      jd_contact_harvest(hs.st, 1.0, &e_damp, &e_fric);
      if (carries) e_el += jd_contact_elastic_energy(hs.st);
    }
    hs.finish();
    if (!carries) continue;
    ncontacts += 1.0;
    jd_sub3(f[i], out.f);
    jd_add3(torque[i], out.ta);
    if (name.empty()) continue;
    for (int d = 0; d < 3; d++) {
      contact_x.push_back(x[i][d] + g.ra[d]);
      contact_f.push_back(out.f[d]);
    }
  }
  if (commit) {
    e_damp_cum += e_damp;
    e_fric_cum += e_fric;
    work_cum += work;
  }
  e_elastic_now = e_el;
  contacts_now = ncontacts;
}

/* ---------------------------------------------------------------------------------------- */
/* Per-atom history that migrates with the atoms.                                             */

void FixWallJiang::grow_arrays(int nmax) {
  memory->grow(hist, nmax, slen, "wall/jiang:hist");
  for (int i = nmax_hist; i < nmax; i++)
    for (int k = 0; k < slen; k++) hist[i][k] = 0.0;
  nmax_hist = nmax;
}

void FixWallJiang::copy_arrays(int i, int j, int delflag) {
  for (int k = 0; k < slen; k++) hist[j][k] = hist[i][k];
}

void FixWallJiang::set_arrays(int i) {
  for (int k = 0; k < slen; k++) hist[i][k] = 0.0;
}

int FixWallJiang::pack_exchange(int i, double *buf) {
  for (int k = 0; k < slen; k++) buf[k] = hist[i][k];
  return slen;
}

int FixWallJiang::unpack_exchange(int nlocal, double *buf) {
  for (int k = 0; k < slen; k++) hist[nlocal][k] = buf[k];
  return slen;
}

double FixWallJiang::memory_usage() { return (double)nmax_hist * slen * sizeof(double); }

void FixWallJiang::output_geometry(jd_h5md_wall *w, double time) const {
  std::memset(w, 0, sizeof *w);
  w->name = id;
  w->type = shape;
  for (int d = 0; d < 3; d++) {
    const double back = vel[d] * time;
    for (int c = 0; c < 4; c++) w->corners[c][d] = plane.p[c][d] - back;
    w->axis[0][d] = cyl.a0[d] - back;
    w->axis[1][d] = cyl.a1[d] - back;
    w->velocity[d] = vel[d];
  }
  w->radius = cyl.rc;
  w->inside = cyl.inside;
}

/* ---------------------------------------------------------------------------------------- */
/* Restart files (jdem_restart.h): where the wall is and how it moves, the servo's state, the
 * force and contacts of the last evaluation, each rank's energies; per atom the history.      */

namespace {
enum { WALL_SHARED = 34, WALL_SUMS = 5 };
}

void FixWallJiang::write_restart(FILE *fp) {
  JdemRestartState st;
  std::vector<double> &s = st.shared;
  s.push_back(shape);
  s.push_back(slen);
  s.insert(s.end(), &plane.p[0][0], &plane.p[0][0] + 12);
  s.insert(s.end(), plane.n, plane.n + 3);
  s.insert(s.end(), cyl.a0, cyl.a0 + 3);
  s.insert(s.end(), cyl.a1, cyl.a1 + 3);
  s.insert(s.end(), vel, vel + 3);
  s.insert(s.end(), force_all, force_all + 3);
  s.push_back(jdem_restart_pack_i64(servo_state.held));
  s.push_back(servo_state.done);
  s.push_back(servo_stress);
  s.push_back(servo_speed);
  s.push_back(servo_position);
  const double sums[WALL_SUMS] = {e_damp_cum, e_fric_cum, work_cum, e_elastic_now, contacts_now};
  st.sums.assign(sums, sums + WALL_SUMS);
  for (size_t c = 0; c < contact_f.size(); c += 3) {
    st.tail.insert(st.tail.end(), &contact_x[c], &contact_x[c] + 3);
    st.tail.insert(st.tail.end(), &contact_f[c], &contact_f[c] + 3);
  }
  jdem_restart_write_state(lmp, fp, st);
}

void FixWallJiang::restart(char *buf) {
  const std::string who = std::string("fix ") + id + " (wall/jiang)";
  const JdemRestartState st = jdem_restart_read_state(lmp, buf, who, WALL_SHARED, WALL_SUMS);
  const double *s = st.shared.data();
  static const char *const shapes[3] = {"plane", "cylinder", "mesh"};
  const int written = (int)s[0];
  if (written != shape)
    error->all(FLERR, (who + ": the restart file's wall of this ID is a " +
                       (written >= 0 && written <= 2 ? shapes[written] : "wall of another kind") +
                       ", not a " + shapes[shape]).c_str());
  if ((int)s[1] != slen)
    error->all(FLERR, (who + ": the restart file's wall history has another length: give "
                             "pair_style gran/jiang the rolling and energy options of the run "
                             "that wrote it").c_str());
  std::memcpy(&plane.p[0][0], s + 2, 12 * sizeof(double));
  std::memcpy(plane.n, s + 14, 3 * sizeof(double));
  std::memcpy(cyl.a0, s + 17, 3 * sizeof(double));
  std::memcpy(cyl.a1, s + 20, 3 * sizeof(double));
  std::memcpy(vel, s + 23, 3 * sizeof(double));
  std::memcpy(force_all, s + 26, 3 * sizeof(double));
  servo_state.held = jdem_restart_unpack_i64(s[29]);
  servo_state.done = (int)s[30];
  servo_stress = s[31];
  servo_speed = s[32];
  servo_position = s[33];
  e_damp_cum = st.sums[0];
  e_fric_cum = st.sums[1];
  work_cum = st.sums[2];
  e_elastic_now = st.sums[3];
  contacts_now = st.sums[4];
  contact_x.clear();
  contact_f.clear();
  for (size_t c = 0; c + 6 <= st.tail.size(); c += 6) {
    contact_x.insert(contact_x.end(), &st.tail[c], &st.tail[c] + 3);
    contact_f.insert(contact_f.end(), &st.tail[c + 3], &st.tail[c + 3] + 3);
  }
}

int FixWallJiang::pack_restart(int i, double *buf) { return jdem_pack_restart(this, i, buf); }

void FixWallJiang::unpack_restart(int nlocal, int nth) {
  if (jdem_stored_restart_len(lmp, nlocal, nth) != slen)
    error->one(FLERR, (std::string("fix ") + id + " (wall/jiang): the restart file's wall "
                       "history has another length: give pair_style gran/jiang the rolling and "
                       "energy options of the run that wrote it").c_str());
  jdem_unpack_restart(lmp, this, nlocal, nth);
}

int FixWallJiang::size_restart(int) { return slen + 1; }

int FixWallJiang::maxsize_restart() { return slen + 1; }
