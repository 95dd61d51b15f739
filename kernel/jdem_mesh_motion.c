/* jdem_mesh_motion.c — the motions of jdem_mesh_motion.h, in fix move/mesh's operation order. */
#include "jdem_mesh_motion.h"

#include <math.h>
#include <string.h>

#include "jdem_kernel.h" /* JD_PI, the M_PI of LIGGGHTS */

static double mag3(const double v[3]) { return sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]); }

/* v times 1/s, as LIGGGHTS divides a vector by a scalar */
static void scale_inv3(double v[3], double s) {
    const double inv = 1. / s;
    for (int k = 0; k < 3; k++) v[k] = inv * v[k];
}

static void cross3(const double a[3], const double b[3], double c[3]) {
    c[0] = a[1] * b[2] - a[2] * b[1];
    c[1] = a[2] * b[0] - a[0] * b[2];
    c[2] = a[0] * b[1] - a[1] * b[0];
}

/* c = a b, the Hamilton product of quaternions (w, x, y, z) */
static void quat_mult(const double a[4], const double b[4], double c[4]) {
    c[0] = a[0] * b[0] - a[1] * b[1] - a[2] * b[2] - a[3] * b[3];
    c[1] = a[0] * b[1] + b[0] * a[1] + a[2] * b[3] - a[3] * b[2];
    c[2] = a[0] * b[2] + b[0] * a[2] + a[3] * b[1] - a[1] * b[3];
    c[3] = a[0] * b[3] + b[0] * a[3] + a[1] * b[2] - a[2] * b[1];
}

/* p turned by the unit quaternion q: q (0, p) q* */
static void quat_rotate(const double q[4], double p[3]) {
    const double pq[4] = {0., p[0], p[1], p[2]}, qc[4] = {q[0], -q[1], -q[2], -q[3]};
    double t[4], r[4];
    quat_mult(q, pq, t);
    quat_mult(t, qc, r);
    p[0] = r[1];
    p[1] = r[2];
    p[2] = r[3];
}

void jd_mesh_motion_still(jd_mesh_motion *m) { memset(m, 0, sizeof *m); }

void jd_mesh_motion_translating(jd_mesh_motion *m, const double v[3]) {
    jd_mesh_motion_still(m);
    m->kind = JD_MESH_TRANSLATING;
    memcpy(m->velocity, v, sizeof m->velocity);
}

int jd_mesh_motion_rotating(jd_mesh_motion *m, const double origin[3], const double axis[3],
                            double period) {
    const double norm = mag3(axis);
    if (!(norm > 0.0) || !(period != 0.0) || !isfinite(period)) return -1;
    jd_mesh_motion_still(m);
    m->kind = JD_MESH_ROTATING;
    memcpy(m->origin, origin, sizeof m->origin);
    const double inv = 1. / norm;
    for (int k = 0; k < 3; k++) m->axis[k] = axis[k] * inv;
    memcpy(m->axis_q, m->axis, sizeof m->axis_q);
    scale_inv3(m->axis_q, mag3(m->axis_q));
    m->omega = 2. * JD_PI / period;
    return 0;
}

static void translate_step(const jd_mesh_motion *m, double dt, size_t n, double (*corner)[3]) {
    const double dx[3] = {dt * m->velocity[0], dt * m->velocity[1], dt * m->velocity[2]};
    for (size_t i = 0; i < n; i++)
        for (int k = 0; k < 3; k++) corner[i][k] = corner[i][k] + dx[k];
}

static void rotate_step(const jd_mesh_motion *m, double dt, size_t n, double (*corner)[3]) {
    const double half = m->omega * dt * 0.5, s = sin(half);
    const double q[4] = {cos(half), m->axis_q[0] * s, m->axis_q[1] * s, m->axis_q[2] * s};
    const double *o = m->origin;
    const int shifted = o[0] * o[0] + o[1] * o[1] + o[2] * o[2] > 0.;
    for (size_t i = 0; i < n; i++) {
        double *p = corner[i];
        if (shifted)
            for (int k = 0; k < 3; k++) p[k] = p[k] - o[k];
        quat_rotate(q, p);
        if (shifted)
            for (int k = 0; k < 3; k++) p[k] = p[k] + o[k];
    }
}

void jd_mesh_motion_step(const jd_mesh_motion *m, double dt, size_t n, double (*corner)[3]) {
    if (m->kind == JD_MESH_TRANSLATING) translate_step(m, dt, n, corner);
    if (m->kind == JD_MESH_ROTATING) rotate_step(m, dt, n, corner);
}

void jd_mesh_motion_velocity(const jd_mesh_motion *m, size_t n, const double (*corner)[3],
                             double (*v)[3]) {
    const double w[3] = {m->omega * m->axis[0], m->omega * m->axis[1], m->omega * m->axis[2]};
    for (size_t i = 0; i < n; i++) {
        double r[3], u[3] = {0., 0., 0.};
        if (m->kind == JD_MESH_TRANSLATING) memcpy(u, m->velocity, sizeof u);
        if (m->kind == JD_MESH_ROTATING) {
            for (int k = 0; k < 3; k++) r[k] = corner[i][k] - m->origin[k];
            cross3(w, r, u);
        }
        /* move/mesh adds its velocity to the zeroed node velocity */
        for (int k = 0; k < 3; k++) v[i][k] = 0. + u[k];
    }
}

/* The triangle's unit normal as LIGGGHTS' TriMesh stores it: (t1 - t0)/|t1 - t0| x
 * (t2 - t1)/|t2 - t1|, normalised. */
static void face_normal(const double t[3][3], double n[3]) {
    double e[2][3];
    for (int i = 0; i < 2; i++) {
        for (int k = 0; k < 3; k++) e[i][k] = t[(i + 1) % 3][k] - t[i][k];
        scale_inv3(e[i], mag3(e[i]));
    }
    cross3(e[0], e[1], n);
    scale_inv3(n, mag3(n));
}

void jd_mesh_spin_velocity(const double origin[3], const double axis[3], double omega,
                           const double t[3][3], double v[3][3]) {
    double n[3], unit[3] = {axis[0], axis[1], axis[2]};
    face_normal(t, n);
    scale_inv3(unit, mag3(unit));
    for (int c = 0; c < 3; c++) {
        const double arm[3] = {t[c][0] - origin[0], t[c][1] - origin[1], t[c][2] - origin[2]};
        double tang[3];
        cross3(arm, unit, tang);
        for (int k = 0; k < 3; k++) tang[k] = -omega * tang[k];
        const double along = tang[0] * n[0] + tang[1] * n[1] + tang[2] * n[2];
        for (int k = 0; k < 3; k++) v[c][k] = tang[k] - along * n[k];
        const double speed = mag3(tang), left = mag3(v[c]);
        if (left > 0.0) {
            scale_inv3(v[c], left);
            for (int k = 0; k < 3; k++) v[c][k] = speed * v[c][k];
        }
    }
}

void jd_mesh_conveyor_velocity(const double u[3], const double t[3][3], double v[3][3]) {
    double n[3];
    face_normal(t, n);
    const double speed = mag3(u), along = u[0] * n[0] + u[1] * n[1] + u[2] * n[2];
    double tang[3];
    for (int k = 0; k < 3; k++) tang[k] = u[k] - along * n[k];
    /* LIGGGHTS rescales any non-zero remainder: a surface velocity along the normal leaves
     * a rounding remainder that it turns into full speed in an arbitrary direction; here such a
     * face is at rest */
    const double tm = mag3(tang);
    if (!(tm > 1e-12 * speed)) {
        memset(v, 0, 9 * sizeof(double));
        return;
    }
    {
        scale_inv3(tang, tm);
        for (int k = 0; k < 3; k++) tang[k] = speed * tang[k];
    }
    for (int c = 0; c < 3; c++) memcpy(v[c], tang, sizeof tang);
}
