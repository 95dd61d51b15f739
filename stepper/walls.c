/*
 * walls.c — walls as the engine sees them: set-up from the scene into the kernel's shapes
 * (kernel/jdem_geometry.h) and rigid translation at the wall's velocity.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "sim.h"

int sim_walls_init(jd_sim *s, char *err, size_t errlen) {
    const jd_scene *sc = s->scene;
    s->n_walls = sc->n_walls;
    s->walls = calloc(sc->n_walls ? sc->n_walls : 1, sizeof *s->walls);
    if (!s->walls) {
        snprintf(err, errlen, "out of memory");
        return -1;
    }
    for (size_t k = 0; k < sc->n_walls; k++) {
        const jd_wall *in = &sc->walls[k];
        jd_sim_wall *w = &s->walls[k];
        w->type = in->type;
        w->material = in->material;
        memcpy(w->v, in->velocity, sizeof w->v);
        if (in->type == JD_WALL_PLANE) {
            /* the scene reader has checked planarity; only a degenerate quad can fail here */
            if (jd_plane_init(&w->plane, in->corners, 1e-6) != JD_GEOM_OK) {
                snprintf(err, errlen, "wall '%s': the corners do not span a plane", in->name);
                return -1;
            }
        } else {
            memcpy(w->cyl.a0, in->axis[0], sizeof w->cyl.a0);
            memcpy(w->cyl.a1, in->axis[1], sizeof w->cyl.a1);
            w->cyl.rc = in->radius;
            w->cyl.inside = in->inside;
            const double ab[3] = {in->axis[1][0] - in->axis[0][0], in->axis[1][1] - in->axis[0][1],
                                  in->axis[1][2] - in->axis[0][2]};
            if (!(jd_dot(ab, ab) > 0.0)) {
                snprintf(err, errlen, "wall '%s': the cylinder axis has zero length", in->name);
                return -1;
            }
        }
    }
    return 0;
}

/* x_wall += v dt for every point that defines the wall. */
void sim_walls_move(jd_sim *s) {
    const double dt = s->dt;
    for (size_t k = 0; k < s->n_walls; k++) {
        jd_sim_wall *w = &s->walls[k];
        if (w->v[0] == 0.0 && w->v[1] == 0.0 && w->v[2] == 0.0) continue;
        for (int d = 0; d < 3; d++) {
            const double dx = w->v[d] * dt;
            for (int c = 0; c < 4; c++) w->plane.p[c][d] += dx;
            w->cyl.a0[d] += dx;
            w->cyl.a1[d] += dx;
            w->disp[d] += dx;
        }
    }
}
