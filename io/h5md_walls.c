/*
 * h5md_walls.c — the walls of the H5MD writer (io/h5md.h, jd_h5md_set_walls): their
 * description and motion law in /jdem/walls, and the surface mesh the sidecar draws.
 *
 * The mesh is quadrilaterals only (Xdmf's Quadrilateral topology, one kind of cell per grid):
 * a plane is its own quadrilateral, a cylinder JD_H5MD_CYLINDER_FACETS facets around its axis,
 * a triangle of a mesh wall a quadrilateral whose last two corners are one vertex (ParaView
 * draws it as the triangle).
 * Every quadrilateral is counter-clockwise seen from the wall's active side (its normal points
 * at the particles), so a viewer that culls back faces shows a container's far walls and hides
 * the near ones that would cover the particles.
 * Walls move by rigid translation, so a frame's vertices are the time-0 vertices plus
 * velocity x time, except a mesh that its engine moves otherwise (`moved`), whose vertices are
 * where jd_h5md_move_mesh last put them; the writer stores them per frame only when some wall
 * moves (a run whose walls stand still carries one vertex list, not one per frame).
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "h5md_internal.h"

/* Two unit vectors perpendicular to the unit vector a (and to each other). */
static void perpendicular_pair(const double a[3], double u[3], double w[3]) {
    const double t[3] = {fabs(a[0]) < 0.9 ? 1.0 : 0.0, fabs(a[0]) < 0.9 ? 0.0 : 1.0, 0.0};
    u[0] = a[1] * t[2] - a[2] * t[1];
    u[1] = a[2] * t[0] - a[0] * t[2];
    u[2] = a[0] * t[1] - a[1] * t[0];
    const double lu = sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
    for (int d = 0; d < 3; d++) u[d] /= lu;
    w[0] = a[1] * u[2] - a[2] * u[1];
    w[1] = a[2] * u[0] - a[0] * u[2];
    w[2] = a[0] * u[1] - a[1] * u[0];
}

static size_t wall_vertices(const jd_h5md_wall *w) {
    return w->type == 1 ? 2 * JD_H5MD_CYLINDER_FACETS : w->type == 2 ? 3 * w->n_triangles : 4;
}

static size_t wall_quads(const jd_h5md_wall *w) {
    return w->type == 1 ? JD_H5MD_CYLINDER_FACETS : w->type == 2 ? w->n_triangles : 1;
}

static int wall_moves(const jd_h5md_wall *w) {
    return (w->type == 2 && w->moved) || w->velocity[0] != 0.0 || w->velocity[1] != 0.0 ||
           w->velocity[2] != 0.0;
}

/* Vertices (at time 0) and quadrilaterals (indices from v0) of wall k. */
static void tessellate(const jd_h5md_wall *w, int32_t k, int64_t v0, double *vert, int64_t *quad,
                       int32_t *quad_wall, size_t *nq) {
    if (w->type == 2) { /* the STL's winding: its normal, the right-hand rule, faces the active side */
        if (w->n_triangles) memcpy(vert, w->triangles, w->n_triangles * sizeof *w->triangles);
        for (size_t t = 0; t < w->n_triangles; t++) {
            const int64_t c = v0 + 3 * (int64_t)t, tri[4] = {c, c + 1, c + 2, c + 2};
            memcpy(&quad[4 * t], tri, sizeof tri);
            quad_wall[t] = k;
        }
        *nq = w->n_triangles;
        return;
    }
    if (w->type != 1) {
        memcpy(vert, w->corners, sizeof w->corners);
        for (int c = 0; c < 4; c++) quad[c] = v0 + c;
        quad_wall[0] = k;
        *nq = 1;
        return;
    }
    const int m = JD_H5MD_CYLINDER_FACETS;
    double a[3], u[3], v[3];
    for (int d = 0; d < 3; d++) a[d] = w->axis[1][d] - w->axis[0][d];
    const double la = sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
    for (int d = 0; d < 3; d++) a[d] /= la;
    perpendicular_pair(a, u, v);
    for (int j = 0; j < m; j++) {
        const double phi = 2.0 * 3.14159265358979323846 * j / m, c = cos(phi) * w->radius, s = sin(phi) * w->radius;
        for (int e = 0; e < 2; e++)
            for (int d = 0; d < 3; d++)
                vert[3 * (e * m + j) + d] = w->axis[e][d] + c * u[d] + s * v[d];
        /* counter-clockwise seen from the active side, as a plane's corners: outwards for an
         * obstacle, inwards for a container */
        const int64_t out[4] = {v0 + j, v0 + (j + 1) % m, v0 + m + (j + 1) % m, v0 + m + j};
        const int64_t in[4] = {out[0], out[3], out[2], out[1]};
        memcpy(&quad[4 * j], w->inside ? in : out, sizeof out);
        quad_wall[j] = k;
    }
    *nq = (size_t)m;
}

static int write_2d(hid_t g, const char *name, hid_t ftype, hid_t mtype, hsize_t rows,
                    hsize_t cols, const void *buf, const char *unit) {
    const hsize_t dims[2] = {rows, cols};
    hid_t sp = H5Screate_simple(2, dims, NULL);
    hid_t d = sp >= 0 ? H5Dcreate2(g, name, ftype, sp, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT)
                      : H5I_INVALID_HID;
    int rc = (d >= 0 && (rows == 0 || H5Dwrite(d, mtype, H5S_ALL, H5S_ALL, H5P_DEFAULT, buf) >= 0))
                 ? 0 : -1;
    if (rc == 0 && unit) rc = h5md_attr_str(d, "unit", unit);
    h5md_close_id(&d);
    h5md_close_id(&sp);
    return rc;
}

/* /jdem/walls: the description (name, type, corners, axis, radius, inside, velocity). */
static int write_description(hid_t g, size_t n, const jd_h5md_wall *walls) {
    size_t longest = 1;
    for (size_t k = 0; k < n; k++)
        if (walls[k].name && strlen(walls[k].name) > longest) longest = strlen(walls[k].name);
    char *names = calloc(n ? n : 1, longest + 1);
    int32_t *type = malloc((n ? n : 1) * sizeof *type), *inside = malloc((n ? n : 1) * sizeof *inside);
    double *corners = malloc((n ? n : 1) * 12 * sizeof *corners);
    double *axis = malloc((n ? n : 1) * 6 * sizeof *axis), *radius = malloc((n ? n : 1) * sizeof *radius);
    double *vel = malloc((n ? n : 1) * 3 * sizeof *vel);
    int rc = -1;
    if (!names || !type || !inside || !corners || !axis || !radius || !vel) goto done;
    for (size_t k = 0; k < n; k++) {
        if (walls[k].name) memcpy(names + k * (longest + 1), walls[k].name, strlen(walls[k].name));
        type[k] = walls[k].type;
        inside[k] = walls[k].inside;
        memcpy(corners + 12 * k, walls[k].corners, 12 * sizeof *corners);
        memcpy(axis + 6 * k, walls[k].axis, 6 * sizeof *axis);
        radius[k] = walls[k].radius;
        memcpy(vel + 3 * k, walls[k].velocity, 3 * sizeof *vel);
    }
    hid_t st = h5md_str_type(longest);
    hsize_t dn = (hsize_t)n;
    hid_t sp = st >= 0 ? H5Screate_simple(1, &dn, NULL) : H5I_INVALID_HID;
    hid_t d = sp >= 0 ? H5Dcreate2(g, "name", st, sp, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT)
                      : H5I_INVALID_HID;
    rc = (d >= 0 && (n == 0 || H5Dwrite(d, st, H5S_ALL, H5S_ALL, H5P_DEFAULT, names) >= 0)) ? 0 : -1;
    h5md_close_id(&d);
    h5md_close_id(&sp);
    h5md_close_id(&st);
    if (rc == 0)
        rc = h5md_dset_fixed(g, "type", H5T_STD_I32LE, H5T_NATIVE_INT32, n, type, NULL) |
             h5md_dset_fixed(g, "inside", H5T_STD_I32LE, H5T_NATIVE_INT32, n, inside, NULL) |
             write_2d(g, "corners", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, dn * 4, 3, corners, "m") |
             write_2d(g, "axis", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, dn * 2, 3, axis, "m") |
             h5md_dset_fixed(g, "radius", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, n, radius, "m") |
             write_2d(g, "velocity", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, dn, 3, vel, "m s-1");
done:
    free(names);
    free(type);
    free(inside);
    free(corners);
    free(axis);
    free(radius);
    free(vel);
    return rc ? -1 : 0;
}

int h5md_walls_write(hid_t file, size_t n, const jd_h5md_wall *walls, h5md_wall_mesh *m) {
    memset(m, 0, sizeof *m);
    m->position = H5I_INVALID_HID;
    for (size_t k = 0; k < n; k++) {
        m->nv += wall_vertices(&walls[k]);
        m->nq += wall_quads(&walls[k]);
        m->moving |= wall_moves(&walls[k]);
    }
    m->n_walls = n;
    m->vert0 = malloc((m->nv ? m->nv : 1) * 3 * sizeof *m->vert0);
    m->vel = malloc((m->nv ? m->nv : 1) * 3 * sizeof *m->vel);
    m->now = malloc((m->nv ? m->nv : 1) * 3 * sizeof *m->now);
    m->given = calloc(m->nv ? m->nv : 1, 1);
    m->first_vertex = malloc((n ? n : 1) * sizeof *m->first_vertex);
    m->n_vertices = malloc((n ? n : 1) * sizeof *m->n_vertices);
    int64_t *quad = malloc((m->nq ? m->nq : 1) * 4 * sizeof *quad);
    int32_t *quad_wall = malloc((m->nq ? m->nq : 1) * sizeof *quad_wall);
    double *zero = calloc(m->nv ? m->nv : 1, sizeof *zero);
    int rc = -1;
    if (!m->vert0 || !m->vel || !m->now || !m->given || !m->first_vertex || !m->n_vertices ||
        !quad || !quad_wall || !zero)
        goto done;
    size_t v = 0, q = 0;
    for (size_t k = 0; k < n; k++) {
        size_t nq;
        tessellate(&walls[k], (int32_t)k, (int64_t)v, m->vert0 + 3 * v, quad + 4 * q,
                   quad_wall + q, &nq);
        m->first_vertex[k] = v;
        m->n_vertices[k] = wall_vertices(&walls[k]);
        for (size_t j = v; j < v + wall_vertices(&walls[k]); j++) {
            memcpy(m->vel + 3 * j, walls[k].velocity, 3 * sizeof *m->vel);
            memcpy(m->now + 3 * j, m->vert0 + 3 * j, 3 * sizeof *m->now);
            m->given[j] = walls[k].type == 2 && walls[k].moved;
        }
        v += wall_vertices(&walls[k]);
        q += nq;
    }
    hid_t g = h5md_group_create(file, "jdem/walls");
    hid_t mg = g >= 0 ? h5md_group_create(g, "mesh") : H5I_INVALID_HID;
    if (mg >= 0 && write_description(g, n, walls) == 0 &&
        write_2d(mg, "quads", H5T_STD_I64LE, H5T_NATIVE_INT64, m->nq, 4, quad, NULL) == 0 &&
        h5md_dset_fixed(mg, "wall", H5T_STD_I32LE, H5T_NATIVE_INT32, m->nq, quad_wall, NULL) == 0 &&
        h5md_dset_fixed(mg, "radius", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, m->nv, zero, "m") == 0 &&
        (m->moving || write_2d(mg, "vertices", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, m->nv, 3,
                               m->vert0, "m") == 0))
        rc = 0;
    if (rc == 0 && m->moving) {
        const hsize_t rest[2] = {m->nv, 3}, chunk[3] = {64, m->nv ? m->nv : 1, 3};
        m->position = h5md_dset_extendible(mg, "vertex_position", H5T_IEEE_F64LE, 3, rest, chunk);
        if (m->position < 0 || h5md_attr_str(m->position, "unit", "m") < 0) rc = -1;
    }
    h5md_close_id(&mg);
    h5md_close_id(&g);
    m->present = rc == 0;
done:
    free(quad);
    free(quad_wall);
    free(zero);
    return rc;
}

int h5md_walls_frame(h5md_wall_mesh *m, hsize_t frame, double time) {
    if (!m->present || !m->moving || m->nv == 0) return 0;
    double *x = malloc(m->nv * 3 * sizeof *x);
    if (!x) return -1;
    for (size_t j = 0; j < 3 * m->nv; j++)
        x[j] = m->given[j / 3] ? m->now[j] : m->vert0[j] + m->vel[j] * time;
    const hsize_t rest[2] = {m->nv, 3};
    const int rc = h5md_append_row(m->position, frame, 3, rest, H5T_NATIVE_DOUBLE, x);
    free(x);
    return rc;
}

int h5md_walls_move_mesh(h5md_wall_mesh *m, size_t k, const double (*tri)[3][3], size_t n_tri) {
    if (!m->present || k >= m->n_walls || !m->given[m->first_vertex[k]] ||
        m->n_vertices[k] != 3 * n_tri)
        return -1;
    memcpy(m->now + 3 * m->first_vertex[k], tri, n_tri * sizeof *tri);
    return 0;
}

void h5md_walls_free(h5md_wall_mesh *m) {
    h5md_close_id(&m->position);
    free(m->vert0);
    free(m->vel);
    free(m->now);
    free(m->given);
    free(m->first_vertex);
    free(m->n_vertices);
    m->vert0 = m->vel = m->now = NULL;
    m->given = NULL;
    m->first_vertex = m->n_vertices = NULL;
}
