/* fix_wall_jiang_mesh.cpp — see fix_wall_jiang_mesh.h.  Glue only: the triangle rule and the
 * history matching are kernel/jdem_mesh.h, the law jd_contact(). */
#include "fix_wall_jiang_mesh.h"

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <string>

#include "atom.h"
#include "error.h"
#include "fix_mesh_surface.h"
#include "fix_neighlist_mesh.h"
#include "force.h"
#include "modify.h"
#include "neighbor.h"
#include "tri_mesh.h"
#include "update.h"

#include "jdem_bond_output.h"
#include "jdem_dispatch.h"
#include "jdem_history.h"
#include "jdem_restart.h"
#include "jdem_watchdog.h"
#include "pair_gran_jiang.h"

using namespace LAMMPS_NS;

static const char *const mesh_usage =
    "Illegal fix wall/jiang mesh command: fix ID group wall/jiang mesh n_meshes N meshes ID1 ... IDN "
    "(IDs of fix mesh/surface, all of the same type)";

FixWallJiangMesh::FixWallJiangMesh(LAMMPS *lmp, int narg, char **arg)
    : FixWallJiang(lmp, narg, arg), state_len(pair->state_len()) {
  if (narg < 7 || std::strcmp(arg[4], "n_meshes") != 0 || std::strcmp(arg[6], "meshes") != 0)
    error->all(FLERR, mesh_usage);
  const int n = force->inumeric(FLERR, arg[5]);
  if (n < 1 || narg != 7 + n) error->all(FLERR, mesh_usage);
  for (int k = 0; k < n; k++) {
    const int f = modify->find_fix(arg[7 + k]);
    FixMeshSurface *fm = f < 0 ? NULL : dynamic_cast<FixMeshSurface *>(modify->fix[f]);
    if (!fm)
      error->all(FLERR, (std::string("fix wall/jiang mesh: '") + arg[7 + k] +
                         "' is not the ID of a fix mesh/surface defined before this fix").c_str());
    if (k > 0 && fm->atomTypeWall() != wtype)
      error->all(FLERR, "fix wall/jiang mesh: all meshes of one fix need the same 'type' (make one fix per type)");
    wtype = fm->atomTypeWall();
    Mesh m;
    m.fix = fm;
    m.built = false;
    meshes.push_back(m);
  }
  if (wtype < 1 || wtype > atom->ntypes)
    error->all(FLERR, "fix wall/jiang mesh: the mesh's 'type T' must be 1 <= T <= ntypes");
}

/* LIGGGHTS' mesh neighbour list (particles of the group near each triangle), as wall/gran. */
void FixWallJiangMesh::post_create() {
  for (size_t k = 0; k < meshes.size(); k++) meshes[k].fix->createWallNeighList(igroup);
}

void FixWallJiangMesh::pre_delete(bool unfixflag) {
  if (!unfixflag) return;
  for (size_t k = 0; k < meshes.size(); k++) meshes[k].fix->deleteWallNeighList();
}

void FixWallJiangMesh::init() {
  pair = dynamic_cast<PairGranJiang *>(force->pair);
  if (!pair) error->all(FLERR, "fix wall/jiang mesh requires pair_style gran/jiang");
  if (pair->state_len() != state_len)
    error->all(FLERR, "fix wall/jiang: pair_style gran/jiang changed its rolling or energy option after the wall was defined");
  if (!atom->radius_flag || !atom->rmass_flag || !atom->omega_flag || !atom->torque_flag)
    error->all(FLERR, "fix wall/jiang requires atom_style granular (sphere)");
  for (size_t k = 0; k < meshes.size(); k++) meshes[k].built = false;
}

/* As FixWallJiang::setup: while a run resumes from a restart file, the history, energy sums
 * and contact count read from it stand (the set-up evaluation sees the full-step velocities,
 * and would set every contact's energy reference from them: the continued run's dissipation
 * would then differ from the uninterrupted one's in its last digits). */
void FixWallJiangMesh::setup(int vflag) {
  if (jdem_restart_resuming(lmp)) return;
  compute_mesh(false);
}

void FixWallJiangMesh::post_force(int vflag) { compute_mesh(true); }

/* The kernel's topology of the triangles this rank holds (owned and ghost), ordered by their
 * ids (the STL's order), so that edge and vertex contacts belong to the same triangle as in the
 * standalone engine.  Rebuilt when the mesh moves (the welding compares coordinates) or the
 * rank's set of triangles changes. */
const char *FixWallJiangMesh::mesh_name(size_t k) const { return meshes[k].fix->id; }

bool FixWallJiangMesh::mesh_moves(size_t k) const { return meshes[k].fix->triMesh()->isMoving(); }

std::vector<double> FixWallJiangMesh::gather_triangles(size_t k) const {
  TriMesh *tm = meshes[k].fix->triMesh();
  std::vector<double> mine;
  for (int t = 0; t < tm->sizeLocal(); t++) {
    double row[10];
    row[0] = tm->id(t);
    for (int c = 0; c < 3; c++) tm->node(t, c, &row[1 + 3 * c]);
    mine.insert(mine.end(), row, row + 10);
  }
  const std::vector<double> all = jdem_gather_rows(world, mine);
  const size_t n = all.size() / 10;
  std::vector<std::pair<double, size_t> > by_id(n);
  for (size_t r = 0; r < n; r++) by_id[r] = std::make_pair(all[10 * r], r);
  std::sort(by_id.begin(), by_id.end());
  std::vector<double> corners(9 * n);
  for (size_t t = 0; t < n; t++) std::copy(&all[10 * by_id[t].second + 1], &all[10 * by_id[t].second + 10], &corners[9 * t]);
  return corners;
}

void FixWallJiangMesh::rebuild_topology(Mesh &m) {
  TriMesh *tm = m.fix->triMesh();
  const int nall = tm->sizeLocal() + tm->sizeGhost();
  if (m.built && !tm->isMoving() && (int)m.tri_of.size() == nall) {
    bool same = true;
    for (int k = 0; k < nall && same; k++) same = m.lig_of[m.tri_of[k]] == k;
    if (same) return;
  }
  std::vector<std::pair<int, int> > by_id((size_t)nall);
  for (int k = 0; k < nall; k++) by_id[k] = std::make_pair(tm->id(k), k);
  std::sort(by_id.begin(), by_id.end());
  const size_t n = (size_t)nall;
  m.lig_of.resize(n);
  m.tri_of.resize(n);
  m.corner.resize(9 * n);
  for (size_t t = 0; t < n; t++) {
    m.lig_of[t] = by_id[t].second;
    m.tri_of[by_id[t].second] = (int32_t)t;
    for (int c = 0; c < 3; c++) tm->node(by_id[t].second, c, &m.corner[9 * t + 3 * c]);
  }
  m.vertex.resize(9 * n + 3);
  m.tri_vertex.resize(3 * n + 3);
  m.tri_edge.resize(3 * n + 3);
  m.edge_vertex.resize(6 * n + 2);
  m.edge_valence.resize(3 * n + 1);
  m.vertex_valence.resize(3 * n + 1);
  m.scratch.resize(3 * n + 1);
  const jd_mesh_storage st = {(double(*)[3])m.vertex.data(), (int32_t(*)[3])m.tri_vertex.data(),
                              (int32_t(*)[3])m.tri_edge.data(), (int32_t(*)[2])m.edge_vertex.data(),
                              m.edge_valence.data(), m.vertex_valence.data(), m.scratch.data()};
  size_t bad = 0;
  const int rc = jd_mesh_build(n, (const double(*)[3][3])m.corner.data(), &st, &m.topo, &bad);
  if (rc == JD_MESH_DEGENERATE) {
    char msg[256];
    std::snprintf(msg, sizeof msg,
                  "fix wall/jiang mesh: triangle id %d of mesh '%s' has zero area or two equal corners",
                  tm->id(m.lig_of[bad]), m.fix->id);
    error->one(FLERR, msg);
  }
  if (rc == JD_MESH_TOO_LARGE) error->one(FLERR, "fix wall/jiang mesh: too many triangles");
  m.built = true;
}

/* (atom, triangle) pairs from LIGGGHTS' mesh neighbour list: owned atoms of the group.  The
 * set-up evaluation (every_pair) pairs every atom with every triangle instead: LIGGGHTS fills
 * a moving mesh's neighbour list only from the first step on. */
void FixWallJiangMesh::gather_candidates(Mesh &m, bool every_pair) {
  TriMesh *tm = m.fix->triMesh();
  FixNeighlistMesh *nl = m.fix->meshNeighlist();
  const int nall = tm->sizeLocal() + tm->sizeGhost();
  const int nlocal = atom->nlocal;
  const int *mask = atom->mask;
  if (every_pair) {
    for (int i = 0; i < nlocal; i++)
      for (int k = 0; k < nall && (mask[i] & groupbit); k++) {
        Candidate cd = {i, m.tri_of[k]};
        cand.push_back(cd);
      }
    return;
  }
  for (int k = 0; k < nall; k++) {
    const std::vector<int> &list = nl->get_contact_list(k);
    for (size_t c = 0; c < list.size(); c++) {
      const int i = list[c];
      if (i >= nlocal || !(mask[i] & groupbit)) continue;
      Candidate cd = {i, m.tri_of[k]};
      cand.push_back(cd);
    }
  }
}

void FixWallJiangMesh::compute_mesh(bool commit) {
#define JD_MESH_LOOP(b) \
  case (b): mesh_loop<(b)>(commit); break;
  JD_DISPATCH(pair->features(), JD_MESH_LOOP)
#undef JD_MESH_LOOP
}

/* Every mesh's candidates, then each atom's contacts (sphere_contacts) in ascending atom
 * index; atoms without candidates lose their history. */
template <unsigned F>
void FixWallJiangMesh::mesh_loop(bool commit) {
  pair->refresh_prefactors();
  overlap_trip = JdOverlapTrip();
  contact_x.clear();
  contact_f.clear();
  const int nlocal = atom->nlocal;
  touched.assign((size_t)nlocal, 0);
  double sums[5] = {0.0, 0.0, 0.0, 0.0, 0.0}; /* e_damp, e_fric, e_el, contacts, work */
  const unsigned laws = jd_law_set_of_loop(F, pair->features()); /* with the run-time laws */
  for (size_t im = 0; im < meshes.size(); im++) {
    rebuild_topology(meshes[im]);
    cand.clear();
    gather_candidates(meshes[im], !commit);
    std::sort(cand.begin(), cand.end());
    for (size_t a = 0; a < cand.size();) {
      size_t b = a;
      while (b < cand.size() && cand[b].i == cand[a].i) b++;
      sphere_contacts<F>((int)im, cand[a].i, a, b, commit, laws, sums);
      a = b;
    }
  }
  if (commit)
    for (int i = 0; i < nlocal; i++)
      if (!touched[i])
        for (int k = 0; k < slen; k++) hist[i][k] = 0.0;
  if (commit) {
    e_damp_cum += sums[0];
    e_fric_cum += sums[1];
    work_cum += sums[4];
  }
  e_elastic_now = sums[2];
  contacts_now = sums[3];
}

/* Atom i's contacts with mesh im (candidates cand[first, last)): the kernel's procedure
 * (jd_mesh_sphere_contacts) picks the contacts and the history slot each continues, and
 * rewrites the slots in the contacts' order (ascending triangle); laws: the loop's law set with
 * the run's run-time laws. */
template <unsigned F>
void FixWallJiangMesh::sphere_contacts(int im, int i, size_t first, size_t last, bool commit,
                                       unsigned laws, double *sums) {
  Mesh &m = meshes[(size_t)im];
  double **x = atom->x, **v = atom->v, **f = atom->f;
  double **omega = atom->omega, **torque = atom->torque;
  const double R = atom->radius[i], mass = atom->rmass[i];
  const size_t n = last - first;
  closest.resize(n);
  is_contact.resize(n);
  tri.resize(n);
  for (size_t k = 0; k < n; k++) tri[k] = cand[first + k].t;
  const int stride = 3 + state_len;
  double *h = hist[i];
  jd_mesh_sphere sc;
  if (jd_mesh_sphere_contacts(&m.topo, n, tri.data(), x[i], R, h, (size_t)stride, closest.data(),
                              is_contact.data(), &sc) == JD_MESH_TOO_MANY)
    error->one(FLERR, "fix wall/jiang mesh: a sphere touches more than 6 faces of one mesh at once");
  if (sc.n == 0) return;
  if (meshes.size() > 1 && touched[i])
    error->one(FLERR, "fix wall/jiang mesh: a sphere touches two meshes of one fix at once; use one fix per mesh");
  touched[i] = 1;
  next.resize((size_t)JD_MESH_SLOTS * stride);
  jd_mesh_history_next(h, (size_t)stride, &sc, next.data());
  jd_contact_geom *g = sc.geom;
  const size_t nc = sc.n;

  TriMesh *tm = m.fix->triMesh();
  MultiVectorContainer<double, 3, 3> *vprop =
      tm->prop().getElementProperty<MultiVectorContainer<double, 3, 3> >("v");
  double ***vnode = vprop ? vprop->begin() : NULL;
  const int roll_at = pair->rolling_at();
  const double kw = pair->wall_prefactors()[i];
  const jd_pair_coeffs co = jd_wall_coeffs(&pair->coeffs(atom->type[i], wtype));
  for (size_t c = 0; c < nc; c++) {
    if (g[c].delta > overlap_limit * R && jd_overlap_excessive(g[c].delta, R, INFINITY, overlap_limit))
      overlap_trip.note(g[c].delta, R, atom->tag[i], 0, id);
    jd_geom_wall_material(F, &g[c], kw, mass, jd_sphere_inertia(mass, R));
    jd_kinematics k;
    jd_copy3(k.va, v[i]);
    jd_copy3(k.wa, omega[i]);
    k.vb[0] = k.vb[1] = k.vb[2] = 0.0;
    if (vnode) {
      const int lt = m.lig_of[sc.feature[c]->tri];
      const double vt[3][3] = {{vnode[lt][0][0], vnode[lt][0][1], vnode[lt][0][2]},
                               {vnode[lt][1][0], vnode[lt][1][1], vnode[lt][1][2]},
                               {vnode[lt][2][0], vnode[lt][2][1], vnode[lt][2][2]}};
      jd_mesh_point_velocity(&m.topo, sc.feature[c], vt, k.vb);
    }
    k.wb[0] = k.wb[1] = k.wb[2] = 0.0;
    JdHistory<F> hs(&next[c * stride + 3], roll_at, commit);
    double f_prev[3] = {0.0, 0.0, 0.0};
    if (F & JD_F_ENERGY) jd_copy3(f_prev, hs.st->f_prev);
    jd_contact_result out;
    const int carries = jd_contact(laws, &co, &g[c], &k, update->dt, hs.st, hs.rs, &out);
    if (F & JD_F_ENERGY) {
      sums[4] += jd_wall_work(f_prev, out.f, k.vb, update->dt);
      jd_contact_harvest(hs.st, 1.0, &sums[0], &sums[1]);
      if (carries) sums[2] += jd_contact_elastic_energy(hs.st);
    }
    hs.finish();
    if (!carries) continue;
    sums[3] += 1.0;
    jd_sub3(f[i], out.f);
    jd_add3(torque[i], out.ta);
  }
  /* also after the set-up evaluation: JdHistory has then changed only the energy reference */
  std::memcpy(h, next.data(), next.size() * sizeof(double));
}
