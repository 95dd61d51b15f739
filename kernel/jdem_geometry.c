/*
 * jdem_geometry.c — set-up of the wall shapes of jdem_geometry.h.
 */
#include "jdem_geometry.h"

int jd_plane_init(jd_plane *w, const double corners[4][3], double tol) {
    for (int c = 0; c < 4; c++)
        for (int k = 0; k < 3; k++) w->p[c][k] = corners[c][k];
    double e[3][3]; /* P2-P1, P3-P1, P4-P1 */
    double size = 0.0;
    for (int c = 0; c < 3; c++) {
        for (int k = 0; k < 3; k++) e[c][k] = corners[c + 1][k] - corners[0][k];
        const double l = sqrt(jd_dot(e[c], e[c]));
        if (l > size) size = l;
    }
    double nn[3];
    jd_cross(e[0], e[1], nn);
    const double len = sqrt(jd_dot(nn, nn));
    if (!(len > 0.0)) return JD_GEOM_DEGENERATE;
    for (int k = 0; k < 3; k++) w->n[k] = nn[k] / len;
    if (fabs(jd_dot(e[2], w->n)) > tol * size) return JD_GEOM_NOT_PLANAR;
    return JD_GEOM_OK;
}
