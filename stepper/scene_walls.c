/*
 * scene_walls.c — the walls section: planar quadrilaterals and cylinders, with their geometry
 * checks (a plane wound away from the particles is refused), and STL meshes (scene_mesh.c).
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "jdem_geometry.h"
#include "scene_internal.h"

/* Relative tolerance of docs/scenes.md: wall geometry, fraction of the wall's size. */
#define GEOM_TOL 1e-9

static const char *const PLANE_KEYS[] = {"name",    "type",    "corners", "material", "velocity",
                                         "present", "servo",   "until",   "until_step", NULL};
static const char *const SERVO_KEYS[] = {"target", "gain", "tolerance", "max_speed", "hold", NULL};
static const char *const CYLINDER_KEYS[] = {"name",     "type",     "axis",    "radius",
                                            "side",     "material", "velocity", "present",
                                            "angular_velocity", "until", "until_step", NULL};
static const char *const MESH_KEYS[] = {"name",     "type",     "file",     "material",
                                        "scale",    "velocity", "rotation", "surface_velocity",
                                        "surface_angular_velocity", NULL};
static const char *const BOOLEANS[] = {"false", "true", NULL};

/* Enum spellings, indexed by the kernel's enum values. */
static const char *const WALL_TYPES[] = {"plane", "cylinder", "mesh", NULL};
static const char *const CYLINDER_SIDES[] = {"outside", "inside", NULL};
_Static_assert(JD_WALL_PLANE == 0 && JD_WALL_CYLINDER == 1 && JD_WALL_MESH == 2, "WALL_TYPES order");

/* Size of a point set: its largest pairwise distance. */
static double extent(const double (*p)[3], int n) {
    double size = 0.0;
    for (int a = 0; a < n; a++)
        for (int b = a + 1; b < n; b++) {
            double d[3];
            sub3(p[b], p[a], d);
            size = fmax(size, norm3(d));
        }
    return size;
}

/* Planar quadrilateral: P1..P3 not collinear, P4 in their plane, convex and counter-clockwise
 * about the normal (P2-P1) x (P3-P1), all within GEOM_TOL of the wall's size. */
static int check_plane(loader *L, const yaml_node_t *w, const char *path, jd_wall *wall) {
    double (*p)[3] = wall->corners, e1[3], e2[3], n[3], d4[3];
    char sub[SD_PATH_MAX];
    sd_join(sub, path, "corners");
    const yaml_node_t *at = sd_get(&L->c, w, "corners");
    double size = extent((const double (*)[3])p, 4);
    sub3(p[1], p[0], e1);
    sub3(p[2], p[0], e2);
    jd_cross(e1, e2, n);
    double area = norm3(n);
    if (!(area > GEOM_TOL * size * size))
        return sd_fail(&L->c, at, sub, "the first three corners are collinear; valid: corners "
                       "of a quadrilateral with a non-zero area");
    for (int d = 0; d < 3; d++) wall->normal[d] = n[d] / area;
    sub3(p[3], p[0], d4);
    double off = jd_dot(d4, wall->normal);
    if (fabs(off) > GEOM_TOL * size)
        return sd_fail(&L->c, at, sub, "the fourth corner is %.3g m off the plane of the first "
                       "three; valid: coplanar corners (within %g of the wall's size)", off,
                       GEOM_TOL);
    for (int k = 0; k < 4; k++) {
        double a[3], b[3], t[3];
        sub3(p[(k + 1) % 4], p[k], a);
        sub3(p[(k + 2) % 4], p[(k + 1) % 4], b);
        jd_cross(a, b, t);
        if (!(jd_dot(t, wall->normal) > GEOM_TOL * size * size))
            return sd_fail(&L->c, at, sub, "the corners do not form a convex quadrilateral in "
                           "counter-clockwise order; valid: corners in order around the edge");
    }
    return 0;
}

static int read_cylinder(loader *L, const yaml_node_t *w, const char *path, jd_wall *wall) {
    const yaml_node_t *axis = sd_get(&L->c, w, "axis");
    char sub[SD_PATH_MAX];
    sd_join(sub, path, "axis");
    if (!axis) return sd_missing(&L->c, w, path, "axis", "[[x, y, z], [x, y, z]]");
    if (sd_points(&L->c, axis, sub, 2, &wall->axis[0][0]) ||
        sd_req_num(&L->c, w, path, "radius", SD_POSITIVE, &wall->radius) ||
        sd_opt_enum(&L->c, w, path, "side", CYLINDER_SIDES, &wall->inside) ||
        sd_opt_num(&L->c, w, path, "angular_velocity", SD_ANY, &wall->angular_velocity))
        return -1;
    double d[3];
    sub3(wall->axis[1], wall->axis[0], d);
    const double length = norm3(d);
    if (!(length > GEOM_TOL * fmax(norm3(wall->axis[0]), norm3(wall->axis[1]))))
        return sd_fail(&L->c, axis, sub, "the axis has zero length; valid: two distinct end "
                       "points");
    /* the axis' direction carries the round-off of its end points to the distance R away */
    sd_join(sub, path, "radius");
    if (!(length > GEOM_TOL * wall->radius))
        return sd_fail(&L->c, sd_get(&L->c, w, "radius"), sub, "the radius %g m is more than "
                       "%g times the axis length %g m; valid: a radius of at most %g m for this "
                       "axis (or a longer axis)",
                       wall->radius, 1.0 / GEOM_TOL, length, length / GEOM_TOL);
    return 0;
}

/* The Ch. 4 campaign's values (docs/mixing.md section 1) as the defaults of the optional keys. */
#define SERVO_GAIN 1e-4      /* [m/(s Pa)] */
#define SERVO_TOLERANCE 10.0 /* [Pa] */
#define SERVO_MAX_SPEED 0.02 /* [m/s] */
#define SERVO_HOLD 0.05      /* [s] */

/* max_speed: a number (the kernel checks its sign), or .inf (no cap). */
static int read_max_speed(loader *L, const yaml_node_t *m, const char *path, double *out) {
    if (sd_is_inf(sd_get(&L->c, m, "max_speed"))) {
        *out = INFINITY;
        return 0;
    }
    *out = SERVO_MAX_SPEED;
    return sd_opt_num(&L->c, m, path, "max_speed", SD_ANY, out);
}

/* The kernel's check (jd_servo_check) names the first bad value; its key, in the kernel's order. */
static const char *servo_key(jd_servo_status st) {
    static const char *const keys[] = {"", "target", "gain", "tolerance", "max_speed", "hold"};
    return keys[st];
}

/* walls.K.servo: the values, then the kernel's check (hold_steps is dt's business: 1 here). */
static int read_servo(loader *L, const yaml_node_t *w, const char *path, jd_wall *wall) {
    const yaml_node_t *m = sd_get(&L->c, w, "servo");
    if (!m) return 0;
    char sub[SD_PATH_MAX];
    sd_join(sub, path, "servo");
    if (sd_mapping(&L->c, m, sub, "{target, gain, tolerance, max_speed, hold}") ||
        sd_keys(&L->c, m, sub, SERVO_KEYS))
        return -1;
    if (sd_get(&L->c, w, "velocity")) {
        char vpath[SD_PATH_MAX];
        sd_join(vpath, path, "velocity");
        return sd_fail(&L->c, sd_get(&L->c, w, "velocity"), vpath, "a servo wall moves by its "
                       "servo law; valid: no velocity on a wall with a servo");
    }
    jd_servo_spec *sp = &wall->servo;
    sp->gain = SERVO_GAIN;
    sp->tolerance = SERVO_TOLERANCE;
    sp->hold_steps = 1;
    wall->servo_hold = SERVO_HOLD;
    if (sd_req_num(&L->c, m, sub, "target", SD_ANY, &sp->target) ||
        sd_opt_num(&L->c, m, sub, "gain", SD_ANY, &sp->gain) ||
        sd_opt_num(&L->c, m, sub, "tolerance", SD_ANY, &sp->tolerance) ||
        read_max_speed(L, m, sub, &sp->max_speed) ||
        sd_opt_num(&L->c, m, sub, "hold", SD_POSITIVE, &wall->servo_hold))
        return -1;
    char msg[256], key[SD_PATH_MAX];
    const jd_servo_status st = jd_servo_check(sp, msg, sizeof msg);
    if (st == JD_SERVO_OK) {
        wall->has_servo = 1;
        return 0;
    }
    sd_join(key, sub, servo_key(st));
    return sd_fail(&L->c, sd_get(&L->c, m, servo_key(st)), key, "%s", msg);
}

/* A name used by an earlier wall of either kind: "duplicate" message, else 0. */
static int unique_name(loader *L, const yaml_node_t *name, const char *sub, const char *s,
                       size_t index) {
    for (size_t k = 0; k < index; k++)
        if (strcmp(L->s->walls[k].name, s) == 0)
            return sd_fail(&L->c, name, sub, "duplicate wall name '%s' (also walls.%zu); valid: "
                           "unique names", s, k);
    for (size_t k = 0; k < L->s->n_mesh_walls; k++)
        if (strcmp(L->s->mesh_walls[k].name, s) == 0)
            return sd_fail(&L->c, name, sub, "duplicate wall name '%s' (also the mesh wall of that "
                           "name); valid: unique names", s);
    return 0;
}

/* A wall of type mesh at PATH, appended to mesh_walls (name already read into wall); counted
 * before it is read, so that scene_free frees its triangles also when a check fails. */
static int read_mesh(loader *L, const yaml_node_t *w, const char *path, const jd_wall *wall) {
    jd_mesh_wall *mw = &L->s->mesh_walls[L->s->n_mesh_walls++];
    memcpy(mw->name, wall->name, sizeof mw->name);
    if (scene_req_material(L, w, path, &mw->material) || scene_read_mesh_wall(L, w, path, mw))
        return -1;
    L->by_wall[mw->material] = 1;
    return 0;
}

/* until [s] (a step once dt is known: here, or in scene_wall_steps for an auto dt), or
 * until_step, the resolved form: the wall is gone from that step's forces on.  Not on a servo
 * wall (its test holds it in place to the end). */
static int read_until(loader *L, const yaml_node_t *w, const char *path, jd_wall *wall) {
    wall->until = NAN;
    wall->until_step = JD_WALL_ALWAYS;
    const yaml_node_t *t = sd_get(&L->c, w, "until"), *st = sd_get(&L->c, w, "until_step");
    if (!t && !st) return 0;
    char sub[SD_PATH_MAX];
    sd_join(sub, path, t ? "until" : "until_step");
    if (t && st) return sd_fail(&L->c, st, path, "until and until_step given together; valid: one of them");
    if (wall->has_servo)
        return sd_fail(&L->c, t ? t : st, sub, "a servo wall cannot vanish; valid: until on a wall "
                       "without servo");
    if (st) return sd_int(&L->c, st, sub, 1, &wall->until_step);
    if (sd_num(&L->c, t, sub, SD_POSITIVE, &wall->until)) return -1;
    return L->s->dt_auto ? 0 : scene_time_to_step(L, t, sub, wall->until, &wall->until_step);
}

int scene_wall_steps(loader *L) {
    for (size_t k = 0; k < L->s->n_walls; k++)
        if (!isnan(L->s->walls[k].until) &&
            scene_time_to_step(L, sd_get(&L->c, L->root, "walls"), "walls", L->s->walls[k].until,
                               &L->s->walls[k].until_step))
            return -1;
    return 0;
}

/* Reads the wall at PATH into walls[index]; *present = 0 for a wall that the case leaves out
 * (present: false, so that one swept scene can hold the obstacles of every model): it is checked
 * like the others but takes no slot and marks no material as in use.  A mesh wall goes to
 * mesh_walls instead (*present = 0: no slot in walls). */
static int read_wall(loader *L, const yaml_node_t *w, const char *path, size_t index,
                     int *present) {
    jd_wall *wall = &L->s->walls[index];
    char sub[SD_PATH_MAX];
    if (sd_mapping(&L->c, w, path, "{name, type, material, ...}")) return -1;
    const yaml_node_t *type = sd_get(&L->c, w, "type"), *name = sd_get(&L->c, w, "name");
    sd_join(sub, path, "type");
    if (!type) return sd_missing(&L->c, w, path, "type", "plane, cylinder, mesh");
    if (sd_enum(&L->c, type, sub, WALL_TYPES, &wall->type)) return -1;
    const int plane = wall->type == JD_WALL_PLANE, mesh = wall->type == JD_WALL_MESH;
    sd_join(sub, path, "servo");
    if (!plane && sd_get(&L->c, w, "servo"))
        return sd_fail(&L->c, sd_get(&L->c, w, "servo"), sub, "a servo moves a plane wall along "
                       "its normal; valid: servo on a wall of type plane");
    if (sd_keys(&L->c, w, path, plane ? PLANE_KEYS : mesh ? MESH_KEYS : CYLINDER_KEYS)) return -1;
    *present = 1;
    if (sd_opt_enum(&L->c, w, path, "present", BOOLEANS, present)) return -1;
    sd_join(sub, path, "name");
    if (!name) return sd_missing(&L->c, w, path, "name", "a unique name");
    if (sd_name(&L->c, name, sub, wall->name, sizeof wall->name) ||
        unique_name(L, name, sub, wall->name, index))
        return -1;
    if (mesh) {
        *present = 0;
        return read_mesh(L, w, path, wall);
    }
    if (scene_req_material(L, w, path, &wall->material) ||
        sd_opt_vec3(&L->c, w, path, "velocity", wall->velocity))
        return -1;
    if (*present) L->by_wall[wall->material] = 1;
    if (!plane) return read_cylinder(L, w, path, wall) || read_until(L, w, path, wall);
    sd_join(sub, path, "corners");
    const yaml_node_t *corners = sd_get(&L->c, w, "corners");
    if (!corners) return sd_missing(&L->c, w, path, "corners", "four points [[x, y, z], ...]");
    if (sd_points(&L->c, corners, sub, 4, &wall->corners[0][0])) return -1;
    return check_plane(L, w, path, wall) || read_servo(L, w, path, wall) ||
           read_until(L, w, path, wall);
}

int scene_read_walls(loader *L) {
    const yaml_node_t *list = sd_get(&L->c, L->root, "walls");
    if (!list) return 0;
    if (sd_sequence(&L->c, list, "walls", "a list of {name, type, material, ...}")) return -1;
    L->s->walls = calloc(sd_len(list) ? sd_len(list) : 1, sizeof *L->s->walls);
    L->s->mesh_walls = calloc(sd_len(list) ? sd_len(list) : 1, sizeof *L->s->mesh_walls);
    if (!L->s->walls || !L->s->mesh_walls) return sd_no_memory(&L->c, list, "walls");
    for (size_t i = 0; i < sd_len(list); i++) {
        char path[SD_PATH_MAX];
        int present;
        sd_join_index(path, "walls", i);
        if (read_wall(L, sd_item(&L->c, list, i), path, L->s->n_walls, &present)) return -1;
        if (present) L->s->n_walls++;
        else memset(&L->s->walls[L->s->n_walls], 0, sizeof L->s->walls[0]);
    }
    return 0;
}

/* The mapping of the wall named name in the walls list and its path walls.K. */
static const yaml_node_t *wall_node(loader *L, const char *name, char path[SD_PATH_MAX]) {
    const yaml_node_t *list = sd_get(&L->c, L->root, "walls");
    for (size_t i = 0; list && i < sd_len(list); i++) {
        const yaml_node_t *w = sd_item(&L->c, list, i);
        const char *s = sd_scalar(sd_get(&L->c, w, "name"));
        if (s && strcmp(s, name) == 0) {
            sd_join_index(path, "walls", i);
            return w;
        }
    }
    snprintf(path, SD_PATH_MAX, "walls");
    return list;
}

/* A plane acts on its active side only, so one wound away from the particles lets every one of
 * them through: of the particles over each plane at the start, count those in front and behind
 * and apply the kernel's rule (jd_plane_wound_away), as fix wall/jiang does at its set-up. */
int scene_check_plane_winding(loader *L) {
    const jd_scene *s = L->s;
    for (size_t k = 0; k < s->n_walls; k++) {
        const jd_wall *w = &s->walls[k];
        jd_plane p;
        if (w->type != JD_WALL_PLANE || jd_plane_init(&p, w->corners, 1e-6) != JD_GEOM_OK)
            continue;
        double side[2] = {0.0, 0.0}; /* in front, behind */
        for (size_t i = 0; i < s->n_particles; i++) {
            const int at = jd_plane_side(&p, &s->position[3 * i]);
            if (at != 0) side[at > 0 ? 0 : 1] += 1.0;
        }
        if (!jd_plane_wound_away(side[0], side[1])) continue;
        char path[SD_PATH_MAX], sub[SD_PATH_MAX];
        const yaml_node_t *node = wall_node(L, w->name, path);
        sd_join(sub, path, "corners");
        return sd_fail(&L->c, sd_get(&L->c, node, "corners") ? sd_get(&L->c, node, "corners") : node,
                       sub, "plane '%s' faces away from the particles: its normal (%.3g, %.3g, "
                       "%.3g) = (P2-P1) x (P3-P1), and all %.0f particles over it are behind it, "
                       "so they would pass through it; valid: the corners counter-clockwise as "
                       "seen from the particles (reverse their order, which turns the normal to "
                       "(%.3g, %.3g, %.3g))", w->name, p.n[0], p.n[1], p.n[2], side[1], 0.0 - p.n[0],
                       0.0 - p.n[1], 0.0 - p.n[2]);
    }
    return 0;
}
