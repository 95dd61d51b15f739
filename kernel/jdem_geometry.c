/*
 * jdem_geometry.c — set-up of wall geometry (see jdem_geometry.h).
 */
#include "jdem_geometry.h"

int jd_plane_init(jd_plane *w, const double corners[4][3], double rel_tol) {
    for (int k = 0; k < 4; k++)
        for (int d = 0; d < 3; d++) w->p[k][d] = corners[k][d];
    double e1[3], e2[3], nrm[3];
    for (int d = 0; d < 3; d++) {
        e1[d] = corners[1][d] - corners[0][d];
        e2[d] = corners[2][d] - corners[0][d];
    }
    jd_cross(e1, e2, nrm);
    const double size = fmax(sqrt(jd_dot(e1, e1)), sqrt(jd_dot(e2, e2)));
    const double len = sqrt(jd_dot(nrm, nrm));
    if (!(size > 0.0) || !(len > rel_tol * size * size)) return JD_GEOM_DEGENERATE;
    for (int d = 0; d < 3; d++) w->n[d] = nrm[d] / len;
    const double off[3] = {corners[3][0] - corners[0][0], corners[3][1] - corners[0][1],
                           corners[3][2] - corners[0][2]};
    if (fabs(jd_dot(off, w->n)) > rel_tol * size) return JD_GEOM_NOT_PLANAR;
    return JD_GEOM_OK;
}

void jd_plane_translate(jd_plane *w, const double d[3]) {
    for (int k = 0; k < 4; k++)
        for (int c = 0; c < 3; c++) w->p[k][c] += d[c];
}

void jd_cylinder_translate(jd_cylinder *c, const double d[3]) {
    for (int k = 0; k < 3; k++) {
        c->a0[k] += d[k];
        c->a1[k] += d[k];
    }
}
