/*
 * scene_mesh.c — walls of type mesh: a static triangle mesh read from an STL file with
 * libadmesh (Debian's libadmesh-dev), scaled, and checked by the kernel's topology builder
 * (jd_mesh_build), so that a degenerate triangle is reported at load time by its index.
 */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <admesh/stl.h>

#include "jdem_mesh.h"
#include "scene_internal.h"

/* admesh 0.98 refuses a file shorter than the 84-byte binary header plus four facets. */
#define STL_MIN_BYTES 284

/* The file's size in bytes, or -1 with errno when it cannot be opened for reading. */
static long readable_size(const char *file) {
    FILE *f = fopen(file, "rb");
    if (!f) return -1;
    long size = fseek(f, 0, SEEK_END) == 0 ? ftell(f) : -1;
    fclose(f);
    return size;
}

/* The STL's triangles, times scale, into mw (admesh stores float32 coordinates: each is
 * widened exactly to double before the scaling). */
static int read_stl(loader *L, const yaml_node_t *at, const char *sub, jd_mesh_wall *mw) {
    const long size = readable_size(mw->file);
    if (size < 0)
        return sd_fail(&L->c, at, sub, "cannot read the STL file '%s' (%s); valid: the path of an "
                       "STL file, relative to the scene file's folder", mw->file, strerror(errno));
    if (size < STL_MIN_BYTES)
        return sd_fail(&L->c, at, sub, "the STL file '%s' has %ld bytes, fewer than the %d that "
                       "admesh reads; valid: an STL file of at least %d bytes (at least four "
                       "triangles in binary)", mw->file, size, STL_MIN_BYTES, STL_MIN_BYTES);
    stl_file stl;
    memset(&stl, 0, sizeof stl);
    stl_open(&stl, mw->file);
    if (stl_get_error(&stl) || stl.stats.number_of_facets <= 0) {
        stl_close(&stl);
        return sd_fail(&L->c, at, sub, "admesh cannot read the STL file '%s'; valid: an ASCII or "
                       "binary STL file with at least one triangle", mw->file);
    }
    mw->ntri = (size_t)stl.stats.number_of_facets;
    mw->corner = malloc(mw->ntri * sizeof *mw->corner);
    if (!mw->corner) {
        stl_close(&stl);
        return sd_no_memory(&L->c, at, sub);
    }
    for (size_t t = 0; t < mw->ntri; t++)
        for (int k = 0; k < 3; k++) {
            const stl_vertex *v = &stl.facet_start[t].vertex[k];
            mw->corner[t][k][0] = (double)v->x * mw->scale;
            mw->corner[t][k][1] = (double)v->y * mw->scale;
            mw->corner[t][k][2] = (double)v->z * mw->scale;
        }
    stl_close(&stl);
    return 0;
}

/* The kernel's topology builder on the scaled triangles: the first degenerate one by index. */
static int check_topology(loader *L, const yaml_node_t *at, const char *sub, const jd_mesh_wall *mw) {
    const size_t n = mw->ntri;
    jd_mesh_storage st = {malloc(3 * n * sizeof *st.vertex), malloc(n * sizeof *st.tri_vertex),
                          malloc(n * sizeof *st.tri_edge), malloc(3 * n * sizeof *st.edge_vertex),
                          malloc(3 * n * sizeof *st.edge_valence),
                          malloc(3 * n * sizeof *st.vertex_valence), malloc(3 * n * sizeof *st.scratch)};
    jd_mesh m;
    size_t bad = 0;
    int rc = -2;
    if (st.vertex && st.tri_vertex && st.tri_edge && st.edge_vertex && st.edge_valence &&
        st.vertex_valence && st.scratch)
        rc = jd_mesh_build(n, (const double(*)[3][3])mw->corner, &st, &m, &bad);
    free(st.vertex);
    free(st.tri_vertex);
    free(st.tri_edge);
    free(st.edge_vertex);
    free(st.edge_valence);
    free(st.vertex_valence);
    free(st.scratch);
    if (rc == -2) return sd_no_memory(&L->c, at, sub);
    if (rc == JD_MESH_DEGENERATE)
        return sd_fail(&L->c, at, sub, "triangle %zu (0-based, in the file's order) of the STL "
                       "file '%s' has zero area or two equal corners (after scaling); valid: "
                       "triangles with three distinct corners and a non-zero area", bad, mw->file);
    if (rc == JD_MESH_TOO_LARGE)
        return sd_fail(&L->c, at, sub, "the STL file '%s' has %zu triangles; valid: at most %d",
                       mw->file, n, INT32_MAX / 3);
    return 0;
}

static int nonzero3(const double v[3]) { return v[0] != 0.0 || v[1] != 0.0 || v[2] != 0.0; }

static const char *const ROTATION_KEYS[] = {"origin", "axis", "period", NULL};

/* walls.K.rotation: {origin, axis, period} (fix move/mesh rotate), checked by the kernel. */
static int read_rotation(loader *L, const yaml_node_t *w, const char *path, jd_mesh_wall *mw) {
    const yaml_node_t *r = sd_get(&L->c, w, "rotation");
    char sub[SD_PATH_MAX], key[SD_PATH_MAX];
    sd_join(sub, path, "rotation");
    double origin[3];
    if (sd_keys(&L->c, r, sub, ROTATION_KEYS) || sd_req_vec3(&L->c, r, sub, "origin", origin) ||
        sd_req_vec3(&L->c, r, sub, "axis", mw->rotation_axis) ||
        sd_req_num(&L->c, r, sub, "period", SD_ANY, &mw->rotation_period))
        return -1;
    if (!nonzero3(mw->rotation_axis)) {
        sd_join(key, sub, "axis");
        return sd_fail(&L->c, sd_get(&L->c, r, "axis"), key, "the rotation axis is (0, 0, 0); "
                       "valid: a non-zero direction (any length)");
    }
    if (jd_mesh_motion_rotating(&mw->motion, origin, mw->rotation_axis, mw->rotation_period) != 0) {
        sd_join(key, sub, "period");
        return sd_fail(&L->c, sd_get(&L->c, r, "period"), key, "the period is %g; valid: a "
                       "non-zero finite time per turn [s] (negative: the other way round)",
                       mw->rotation_period);
    }
    return 0;
}

static const char *const SPIN_KEYS[] = {"origin", "axis", "omega", NULL};

/* walls.K.surface_angular_velocity: {origin, axis, omega} (fix mesh/surface surface_ang_vel). */
static int read_spin(loader *L, const yaml_node_t *w, const char *path, jd_mesh_wall *mw) {
    const yaml_node_t *r = sd_get(&L->c, w, "surface_angular_velocity");
    char sub[SD_PATH_MAX], key[SD_PATH_MAX];
    sd_join(sub, path, "surface_angular_velocity");
    if (sd_keys(&L->c, r, sub, SPIN_KEYS) || sd_req_vec3(&L->c, r, sub, "origin", mw->spin_origin) ||
        sd_req_vec3(&L->c, r, sub, "axis", mw->spin_axis) ||
        sd_req_num(&L->c, r, sub, "omega", SD_ANY, &mw->spin_omega))
        return -1;
    if (!nonzero3(mw->spin_axis)) {
        sd_join(key, sub, "axis");
        return sd_fail(&L->c, sd_get(&L->c, r, "axis"), key, "the spin axis is (0, 0, 0); valid: "
                       "a non-zero direction (any length)");
    }
    mw->spinning = 1;
    return 0;
}

/* velocity, rotation, surface_velocity and surface_angular_velocity: at most one motion, and a
 * conveyor or spinning surface only on a mesh that stays (LIGGGHTS' move/mesh replaces the
 * surface's velocity by the motion's), and not both. */
static int read_motion(loader *L, const yaml_node_t *w, const char *path, jd_mesh_wall *mw) {
    double v[3] = {0.0, 0.0, 0.0};
    char sub[SD_PATH_MAX];
    jd_mesh_motion_still(&mw->motion);
    if (sd_opt_vec3(&L->c, w, path, "velocity", v) ||
        sd_opt_vec3(&L->c, w, path, "surface_velocity", mw->surface_velocity))
        return -1;
    if (nonzero3(v)) jd_mesh_motion_translating(&mw->motion, v);
    if (sd_get(&L->c, w, "rotation")) {
        sd_join(sub, path, "rotation");
        if (nonzero3(v))
            return sd_fail(&L->c, sd_get(&L->c, w, "rotation"), sub, "the mesh has a velocity "
                           "and a rotation; valid: one motion per mesh wall (velocity or rotation)");
        if (read_rotation(L, w, path, mw)) return -1;
    }
    if (nonzero3(mw->surface_velocity) && mw->motion.kind != JD_MESH_STILL) {
        sd_join(sub, path, "surface_velocity");
        return sd_fail(&L->c, sd_get(&L->c, w, "surface_velocity"), sub, "a conveyor surface "
                       "on a moving mesh; valid: surface_velocity on a mesh wall without "
                       "velocity or rotation");
    }
    if (!sd_get(&L->c, w, "surface_angular_velocity")) return 0;
    sd_join(sub, path, "surface_angular_velocity");
    if (mw->motion.kind != JD_MESH_STILL || nonzero3(mw->surface_velocity))
        return sd_fail(&L->c, sd_get(&L->c, w, "surface_angular_velocity"), sub, "a spinning "
                       "surface on a moving or conveyor mesh; valid: surface_angular_velocity on a "
                       "mesh wall without velocity, rotation or surface_velocity");
    return read_spin(L, w, path, mw);
}

int scene_read_mesh_wall(loader *L, const yaml_node_t *w, const char *path, jd_mesh_wall *mw) {
    char sub[SD_PATH_MAX];
    sd_join(sub, path, "file");
    const yaml_node_t *file = sd_get(&L->c, w, "file");
    if (!file) return sd_missing(&L->c, w, path, "file", "the path of an STL file");
    if (scene_file_path(L, file, sub, "an STL file", mw->file, sizeof mw->file)) return -1;
    mw->scale = 1.0;
    if (sd_opt_num(&L->c, w, path, "scale", SD_POSITIVE, &mw->scale) ||
        read_stl(L, file, sub, mw))
        return -1;
    return check_topology(L, file, sub, mw) || read_motion(L, w, path, mw);
}
