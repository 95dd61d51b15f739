/* jdem_wall_near.h — can a sphere touch a wall after the sphere and the wall have moved by at
 * most `margin` relative to each other?  fix wall/jiang keeps the particles for which this holds
 * at a neighbour rebuild as its candidates, and evaluates only those until the next rebuild.
 *
 * The tests are the contact tests of kernel/jdem_geometry.h (jd_geom_plane, jd_geom_cylinder)
 * with every distance widened by the margin, so they are true for every sphere that touches the
 * wall now or can touch it after a relative motion of up to `margin` [m].  The standalone
 * engine's wall candidate list (wall_candidate() in stepper/neighbour.c) uses the same tests;
 * they belong in kernel/jdem_geometry.h so that both engines share one copy (a kernel change
 * left to the kernel's owner). */
#ifndef JDEM_WALL_NEAR_H
#define JDEM_WALL_NEAR_H

#include <cmath>

#include "jdem_geometry.h"

/* Plane: signed distance in (-margin, R + margin) and the centre's projection within margin of
 * the quadrilateral (the signed distance to each edge line is > -margin). */
static inline bool jd_plane_near(const jd_plane *w, const double x[3], double R, double margin) {
  const double rel[3] = {x[0] - w->p[0][0], x[1] - w->p[0][1], x[2] - w->p[0][2]};
  const double sd = jd_dot(w->n, rel);
  if (!(sd > -margin && sd < R + margin)) return false;
  for (int k = 0; k < 4; k++) {
    const double *p = w->p[k], *q = w->p[(k + 1) & 3];
    const double e[3] = {q[0] - p[0], q[1] - p[1], q[2] - p[2]};
    const double c[3] = {x[0] - p[0], x[1] - p[1], x[2] - p[2]};
    double cr[3];
    jd_cross(e, c, cr);
    if (jd_dot(cr, w->n) < -margin * std::sqrt(jd_dot(e, e))) return false;
  }
  return true;
}

/* Cylinder: the axial coordinate within margin of the segment, and the distance from the axis
 * within R + margin of the surface on the contact side. */
static inline bool jd_cylinder_near(const jd_cylinder *c, const double x[3], double R,
                                    double margin) {
  const double ab[3] = {c->a1[0] - c->a0[0], c->a1[1] - c->a0[1], c->a1[2] - c->a0[2]};
  const double len = std::sqrt(jd_dot(ab, ab));
  const double rel[3] = {x[0] - c->a0[0], x[1] - c->a0[1], x[2] - c->a0[2]};
  const double t = jd_dot(rel, ab) / len;
  if (!(t > -margin && t < len + margin)) return false;
  const double d = std::sqrt(std::fmax(jd_dot(rel, rel) - t * t, 0.0)); /* from the axis */
  return c->inside ? d > c->rc - R - margin : d < c->rc + R + margin;
}

#endif
