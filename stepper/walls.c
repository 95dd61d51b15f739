/*
 * walls.c — walls as the engine sees them: set-up from the scene into the kernel's shapes
 * (kernel/jdem_geometry.h) and rigid translation at the wall's velocity.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "h5md.h"
#include "jdem_servo.h"
#include "sim.h"

int sim_walls_init(jd_walls *walls, const jd_run_constants *run, char *err, size_t errlen) {
    const jd_scene *sc = run->scene;
    walls->n = sc->n_walls;
    walls->wall = calloc(sc->n_walls ? sc->n_walls : 1, sizeof *walls->wall);
    if (!walls->wall) {
        snprintf(err, errlen, "out of memory");
        return -1;
    }
    for (size_t k = 0; k < sc->n_walls; k++) {
        const jd_wall *in = &sc->walls[k];
        jd_sim_wall *w = &walls->wall[k];
        w->type = in->type;
        w->material = in->material;
        w->until_step = in->until_step;
        memcpy(w->v, in->velocity, sizeof w->v);
        if (in->has_servo) {
            w->servo = 1;
            w->spec = in->servo;
            w->spec.hold_steps = jd_servo_hold_steps(in->servo_hold, run->dt);
            w->area = jd_servo_area(in->corners);
            walls->forces = 1;
        }
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
            w->spin = in->angular_velocity;
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

void sim_walls_free(jd_walls *walls) {
    free(walls->wall);
    free(walls->f);
    free(walls->x);
}

int sim_walls_reserve(jd_walls *walls, size_t n, char *err, size_t errlen) {
    if (!walls->forces || n <= walls->cap) return 0;
    free(walls->f);
    free(walls->x);
    walls->f = calloc(3 * n, sizeof *walls->f);
    walls->x = calloc(3 * n, sizeof *walls->x);
    walls->cap = walls->f && walls->x ? n : 0;
    if (walls->cap) return 0;
    snprintf(err, errlen, "out of memory for the wall forces of %zu wall contacts", n);
    return -1;
}

/* The sample box of the stress tensor: the plane walls where they are now. */
static void sample_box(const jd_walls *walls, double centre[3], double *volume) {
    double p[12 * walls->n], nrm[3 * walls->n];
    size_t n = 0;
    for (size_t k = 0; k < walls->n; k++)
        if (walls->wall[k].type == JD_WALL_PLANE) {
            memcpy(p + 12 * n, walls->wall[k].plane.p, sizeof(double[12]));
            memcpy(nrm + 3 * n, walls->wall[k].plane.n, sizeof(double[3]));
            n++;
        }
    jd_servo_box(n, p, nrm, centre, volume);
}

void sim_walls_sum(jd_walls *walls, const jd_contact_list *L) {
    for (size_t k = 0; k < walls->n; k++) memset(walls->wall[k].force, 0, sizeof walls->wall[k].force);
    for (size_t c = 0; c < L->n; c++)
        for (int d = 0; d < 3; d++) walls->wall[L->j[c]].force[d] += walls->f[3 * c + d];
    double centre[3], volume;
    sample_box(walls, centre, &volume);
    jd_stress_tensor(L->n, walls->x, walls->f, centre, volume, walls->stress_tensor);
    memset(walls->f, 0, 3 * L->n * sizeof *walls->f);
    memset(walls->x, 0, 3 * L->n * sizeof *walls->x);
    for (size_t k = 0; k < walls->n; k++) {
        jd_sim_wall *w = &walls->wall[k];
        if (!w->servo) continue;
        w->stress = jd_servo_stress(w->force, w->plane.n, w->area);
        w->speed = jd_servo_speed(&w->spec, &w->state, w->stress);
        for (int d = 0; d < 3; d++) w->v[d] = w->speed * w->plane.n[d];
    }
}

static int write_scalar(jd_h5md *h, int64_t step, double dt, const char *group, const char *item,
                        double value, char *err, size_t errlen) {
    char name[2 * JD_NAME_MAX + 32];
    snprintf(name, sizeof name, "%s/%s", group, item);
    return jd_h5md_write_observable(h, name, step, (double)step * dt, value, err, errlen);
}

int sim_walls_write_observables(const jd_walls *walls, const jd_run_constants *run, int64_t step,
                                jd_h5md *h, char *err, size_t errlen) {
    const double dt = run->dt;
    for (size_t k = 0; k < walls->n; k++) {
        const jd_sim_wall *w = &walls->wall[k];
        const char *name = run->scene->walls[k].name;
        char group[JD_NAME_MAX + 32];
        snprintf(group, sizeof group, "%s/%s", jd_obs_wall_force, name);
        for (int d = 0; d < 3; d++)
            if (write_scalar(h, step, dt, group, jd_obs_axes[d], w->force[d], err, errlen)) return -1;
        if (w->servo &&
            (write_scalar(h, step, dt, jd_obs_servo_stress, name, w->stress, err, errlen) ||
             write_scalar(h, step, dt, jd_obs_servo_position, name, w->position, err, errlen)))
            return -1;
    }
    for (int k = 0; k < 9; k++)
        if (write_scalar(h, step, dt, jd_obs_stress_tensor, jd_obs_tensor_components[k],
                         walls->stress_tensor[k], err, errlen))
            return -1;
    return 0;
}

void sim_walls_retire(jd_walls *walls, int64_t step) {
    for (size_t k = 0; k < walls->n; k++) walls->wall[k].gone = jd_wall_gone(step, walls->wall[k].until_step);
}

/* x_wall += v dt for every point that defines the wall. */
void sim_walls_move(jd_walls *walls, double dt) {
    for (size_t k = 0; k < walls->n; k++) {
        jd_sim_wall *w = &walls->wall[k];
        if (w->v[0] == 0.0 && w->v[1] == 0.0 && w->v[2] == 0.0) continue;
        for (int d = 0; d < 3; d++) {
            const double dx = w->v[d] * dt;
            for (int c = 0; c < 4; c++) w->plane.p[c][d] += dx;
            w->cyl.a0[d] += dx;
            w->cyl.a1[d] += dx;
            w->disp[d] += dx;
        }
        if (w->servo) w->position += w->speed * dt;
    }
}
