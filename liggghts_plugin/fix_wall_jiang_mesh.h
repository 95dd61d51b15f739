/* fix_wall_jiang_mesh.h — `fix wall/jiang mesh`: STL mesh walls through jdem's C kernel.
 *
 *   fix mesh/surface file F.stl type T [move/mesh, surface_vel ...]   (LIGGGHTS' own)
 *   fix ID group wall/jiang mesh n_meshes N meshes ID1 ... IDN
 *
 * as stock `fix wall/gran ... mesh n_meshes N meshes ID1 ...`.  LIGGGHTS reads the STL and
 * moves the mesh (fix move/mesh); its node velocities (move/mesh, or surface_vel for a conveyor
 * belt) give the wall's velocity at each contact point (jd_mesh_point_velocity).  The wall's
 * material is the mesh's `type T`, with the same coefficients as the other walls of
 * pair_style gran/jiang.  Which triangles a sphere touches, without double counting, is the
 * kernel's rule (kernel/jdem_mesh.h); the law is jd_contact(), as for plane walls.
 *
 * Candidates: the particles LIGGGHTS' own mesh neighbour list (fix neighlist/mesh, created as
 * for wall/gran) holds near each triangle.  The kernel's topology (vertex and edge tables) is
 * rebuilt from the triangles this rank holds, ordered by their ids, whenever the mesh moves or
 * the rank's set of triangles changes.  The set-up evaluation (before the first step) tests
 * every triangle.
 *
 * History: per atom and per mesh fix JD_MESH_SLOTS slots, each the contact's last normal and
 * its state in gran/jiang's layout; a contact keeps its slot across triangles by its normal
 * (jd_mesh_match_history), migrating with the atom (FixWallJiang's per-atom array). */
#ifndef JDEM_FIX_WALL_JIANG_MESH_H
#define JDEM_FIX_WALL_JIANG_MESH_H

#include <vector>

#include "fix_wall_jiang.h"
#include "jdem_mesh.h"

namespace LAMMPS_NS {

class FixWallJiangMesh : public FixWallJiang {
 public:
  FixWallJiangMesh(class LAMMPS *, int, char **);
  void post_create();
  void pre_delete(bool unfixflag);
  void init();
  void setup(int);
  void post_force(int);

  /* For dump h5md/jdem: the meshes of the fix; mesh k's name (its fix mesh/surface ID), whether
   * LIGGGHTS moves it (fix move/mesh), and its triangles' corners [ntri][3][3] in id order, the
   * STL's [m] (collective: every rank's own triangles, on rank 0; empty elsewhere). */
  size_t n_meshes() const { return meshes.size(); }
  const char *mesh_name(size_t k) const;
  bool mesh_moves(size_t k) const;
  std::vector<double> gather_triangles(size_t k) const;

 private:
  /* One mesh of the fix: LIGGGHTS' fix, and the kernel's view of the triangles this rank holds. */
  struct Mesh {
    class FixMeshSurface *fix;
    std::vector<int> lig_of;            /* kernel triangle t -> LIGGGHTS' local index   */
    std::vector<int32_t> tri_of;        /* LIGGGHTS' local index -> kernel triangle t   */
    std::vector<double> corner;         /* [ntri][3][3] corner coordinates           [m] */
    std::vector<double> vertex;         /* jd_mesh_storage arrays                        */
    std::vector<int32_t> tri_vertex, tri_edge, edge_vertex, edge_valence, vertex_valence;
    std::vector<int64_t> scratch;
    jd_mesh topo;
    bool built;
  };
  /* A sphere's candidate triangle: local atom index and kernel triangle. */
  struct Candidate {
    int i;
    int32_t t;
    bool operator<(const Candidate &o) const { return i != o.i ? i < o.i : t < o.t; }
  };

  void rebuild_topology(Mesh &m);
  void gather_candidates(Mesh &m, bool every_pair);
  template <unsigned F> JD_SPECIALISED void mesh_loop(bool commit);
  template <unsigned F> void sphere_contacts(int im, int i, size_t first, size_t last, bool commit,
                                             unsigned laws, double *sums);
  void compute_mesh(bool commit);

  std::vector<Mesh> meshes;
  std::vector<Candidate> cand;
  std::vector<int32_t> tri;             /* per candidate of the sphere in hand: its triangle, */
  std::vector<jd_mesh_closest> closest; /* its feature, */
  std::vector<unsigned char> is_contact; /* whether it is a contact                        */
  std::vector<double> next;              /* the sphere's history slots being rewritten     */
  std::vector<unsigned char> touched; /* per local atom: had contacts on this mesh */
  int state_len;                      /* doubles of a contact's state (gran/jiang's) */
};

}  // namespace LAMMPS_NS

#endif
