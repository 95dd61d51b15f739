/*
 * scene_inlets.c — the inlets section (docs/mixing.md 2.1): each entry's section (generated or
 * explicit particles, positions relative to the section origin), belt, plane, period and stop
 * rule, read into jd_scene.inlets; and the kernel's check of the stream (kernel/jdem_inlet.h),
 * run once dt is final because the crossing steps depend on it.
 *
 * The section's particles are built by the scene's own generators: they are appended to the
 * scene's particle arrays, copied out into the inlet and the arrays cut back, so a section
 * lattice is exactly the lattice the generate section would make.  Section particles carry no
 * velocity: every inserted particle moves at the belt velocity.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "jdem_inlet.h"
#include "scene_internal.h"

static const char *const INLET_KEYS[] = {"name", "section", "origin", "velocity", "plane",
                                         "period", "offset", "first_id", "stop",
                                         "max_insert_overlap", NULL};
static const char *const SECTION_KEYS[] = {"blocks", "generate", "particles", "from_deposit",
                                            "bonds", NULL};
static const char *const SECTION_PARTICLE_KEYS[] = {"material", "radius", "position", "settled",
                                                    NULL};
static const char *const BOOLEANS[] = {"false", "true", NULL};
static const char *const PLANE_KEYS[] = {"point", "normal", NULL};
static const char *const STOP_KEYS[] = {"sections", "time", "deposit_height", NULL};
static const char *const HEIGHT_KEYS[] = {"height", "below_speed", "every", NULL};

static int section_particle(loader *L, const yaml_node_t *p, const char *path) {
    jd_scene *s = L->s;
    int mat;
    if (sd_keys(&L->c, p, path, SECTION_PARTICLE_KEYS)) return -1;
    long i = scene_add_particle(L, p, -1);
    if (i < 0 || scene_req_material(L, p, path, &mat) ||
        sd_req_num(&L->c, p, path, "radius", SD_POSITIVE, &s->radius[i]) ||
        sd_req_vec3(&L->c, p, path, "position", &s->position[3 * i]))
        return -1;
    if (!s->materials[mat].has_elastic) {
        char sub[SD_PATH_MAX];
        sd_join(sub, path, "material");
        return sd_fail(&L->c, sd_get(&L->c, p, "material"), sub, "material '%s' has no "
                       "youngs_modulus, poisson_ratio and density; valid: a material with "
                       "elastic properties", s->materials[mat].name);
    }
    L->by_particle[mat] = 1;
    s->material[i] = mat;
    int settled = 0;
    if (sd_opt_enum(&L->c, p, path, "settled", BOOLEANS, &settled)) return -1;
    s->settled[i] = (unsigned char)settled;
    return 0;
}

/* Move the scene's particles [from, n_particles) into the inlet and cut the arrays back. */
static int take_section(loader *L, size_t from, jd_inlet *in, const yaml_node_t *at,
                        const char *path) {
    jd_scene *s = L->s;
    const size_t n = s->n_particles - from;
    if (n == 0)
        return sd_fail(&L->c, at, path, "no particles; valid: at least one particle in "
                       "section.blocks, section.generate, section.particles or "
                       "section.from_deposit");
    in->n = n;
    in->rel = malloc(3 * n * sizeof *in->rel);
    in->radius = malloc(n * sizeof *in->radius);
    in->material = malloc(n * sizeof *in->material);
    if (!in->rel || !in->radius || !in->material) return sd_no_memory(&L->c, at, path);
    memcpy(in->rel, &s->position[3 * from], 3 * n * sizeof *in->rel);
    memcpy(in->radius, &s->radius[from], n * sizeof *in->radius);
    memcpy(in->material, &s->material[from], n * sizeof *in->material);
    for (size_t p = from; p < s->n_particles; p++) in->settled |= s->settled[p];
    s->n_particles = from;
    return 0;
}

/* The section's particles in the order blocks, generate, particles, from_deposit (blocks first:
 * a bonded section with its unbonded spheres in generate gives every sphere the id it has in
 * the same section unbonded, with the lattice first in generate), then its bonds. */
static int read_section(loader *L, const yaml_node_t *m, const char *path, jd_inlet *in,
                        section_blocks **blocks) {
    char sub[SD_PATH_MAX], item[SD_PATH_MAX];
    sd_join(sub, path, "section");
    const yaml_node_t *sec = sd_get(&L->c, m, "section");
    if (!sec)
        return sd_missing(&L->c, m, path, "section", "a mapping with blocks, generate, particles "
                          "and/or from_deposit");
    if (sd_keys(&L->c, sec, sub, SECTION_KEYS)) return -1;
    const size_t from = L->s->n_particles;
    if (scene_read_section_blocks(L, sec, sub, blocks)) return -1;
    const yaml_node_t *gen = sd_get(&L->c, sec, "generate"), *parts = sd_get(&L->c, sec, "particles"),
                      *deposits = sd_get(&L->c, sec, "from_deposit");
    int64_t unused_id = 1; /* ids are the stream's */
    sd_join(item, sub, "generate");
    if (gen && scene_generate_list(L, gen, item, 1, &unused_id)) return -1;
    sd_join(item, sub, "particles");
    if (parts && sd_sequence(&L->c, parts, item, "a list of {material, radius, position}"))
        return -1;
    for (size_t k = 0; parts && k < sd_len(parts); k++) {
        char pp[SD_PATH_MAX];
        sd_join_index(pp, item, k);
        if (section_particle(L, sd_item(&L->c, parts, k), pp)) return -1;
    }
    sd_join(item, sub, "from_deposit");
    if (deposits && scene_read_deposit_list(L, deposits, item, 1)) return -1;
    return take_section(L, from, in, sec, sub) || scene_read_section_bonds(L, sec, sub, in, *blocks);
}

static int read_plane(loader *L, const yaml_node_t *m, const char *path, jd_inlet *in) {
    char sub[SD_PATH_MAX];
    sd_join(sub, path, "plane");
    const yaml_node_t *p = sd_get(&L->c, m, "plane");
    if (!p) return sd_missing(&L->c, m, path, "plane", "a mapping with point and normal");
    return sd_keys(&L->c, p, sub, PLANE_KEYS) ||
           sd_req_vec3(&L->c, p, sub, "point", in->plane_point) ||
           sd_req_vec3(&L->c, p, sub, "normal", in->plane_normal);
}

static int read_height(loader *L, const yaml_node_t *h, const char *path, jd_inlet *in) {
    in->stop = JD_INLET_STOP_HEIGHT;
    in->below_speed = 0.1;
    in->every = 1000;
    return sd_keys(&L->c, h, path, HEIGHT_KEYS) ||
           sd_req_num(&L->c, h, path, "height", SD_POSITIVE, &in->height) ||
           sd_opt_num(&L->c, h, path, "below_speed", SD_POSITIVE, &in->below_speed) ||
           scene_opt_int(L, h, path, "every", 1, &in->every);
}

/* Exactly one of sections, time, deposit_height. */
static int read_stop(loader *L, const yaml_node_t *m, const char *path, jd_inlet *in) {
    char sub[SD_PATH_MAX], item[SD_PATH_MAX];
    static const char never[] = "the stream never stops; valid: a number of sections, a deposit "
                                "height or a time";
    sd_join(sub, path, "stop");
    const yaml_node_t *st = sd_get(&L->c, m, "stop");
    if (!st) return sd_fail(&L->c, m, sub, never);
    if (sd_keys(&L->c, st, sub, STOP_KEYS)) return -1;
    const yaml_node_t *ns = sd_get(&L->c, st, "sections"), *nt = sd_get(&L->c, st, "time"),
                      *nh = sd_get(&L->c, st, "deposit_height");
    const int given = (ns != NULL) + (nt != NULL) + (nh != NULL);
    if (given == 0) return sd_fail(&L->c, st, sub, never);
    if (given > 1)
        return sd_fail(&L->c, st, sub, "more than one stop rule; valid: exactly one of sections, "
                       "time, deposit_height");
    if (ns) {
        in->stop = JD_INLET_STOP_SECTIONS;
        sd_join(item, sub, "sections");
        return sd_int(&L->c, ns, item, 1, &in->sections);
    }
    if (nt) {
        in->stop = JD_INLET_STOP_TIME;
        sd_join(item, sub, "time");
        return sd_num(&L->c, nt, item, SD_POSITIVE, &in->stop_time);
    }
    sd_join(item, sub, "deposit_height");
    return read_height(L, nh, item, in);
}

/* first_id: an integer >= 1, or auto (also when absent): resolved by resolve_first_ids. */
static int read_first_id(loader *L, const yaml_node_t *m, const char *path, jd_inlet *in) {
    const yaml_node_t *n = sd_get(&L->c, m, "first_id");
    const char *text = n ? sd_scalar(n) : NULL;
    in->first_id = 0;
    if (!n || (text && strcmp(text, "auto") == 0)) return 0;
    char sub[SD_PATH_MAX];
    sd_join(sub, path, "first_id");
    if (sd_int(&L->c, n, sub, 1, &in->first_id) == 0) return 0;
    const size_t len = strlen(L->c.err);
    snprintf(L->c.err + len, L->c.errlen - len, ", or auto");
    return -1;
}

/* max_insert_overlap: a fraction >= 0 of the smaller radius, or .inf (every particle is
 * inserted, whatever occupies its place). */
/* max_insert_overlap: a fraction >= 0 of the smaller radius, or .inf (every particle is
 * inserted, whatever occupies its place). */
static int read_max_insert_overlap(loader *L, const yaml_node_t *m, const char *path, jd_inlet *in) {
    in->max_insert_overlap = JD_INLET_MAX_INSERT_OVERLAP;
    return sd_opt_num_or_inf(&L->c, m, path, "max_insert_overlap", SD_NONNEGATIVE,
                             "an overlap fraction", "a number >= 0 (a fraction of the smaller radius), or .inf (never "
                             "skip a particle)", &in->max_insert_overlap);
}

static int read_inlet(loader *L, const yaml_node_t *m, const char *path, jd_inlet *in) {
    char sub[SD_PATH_MAX];
    if (sd_keys(&L->c, m, path, INLET_KEYS)) return -1;
    const yaml_node_t *name = sd_get(&L->c, m, "name");
    sd_join(sub, path, "name");
    if (!name) return sd_missing(&L->c, m, path, "name", "a unique name");
    if (sd_name(&L->c, name, sub, in->name, sizeof in->name)) return -1;
    for (const jd_inlet *other = L->s->inlets; other < in; other++)
        if (strcmp(other->name, in->name) == 0)
            return sd_fail(&L->c, name, sub, "duplicate inlet name '%s'; valid: unique names",
                           in->name);
    section_blocks *blocks = NULL;
    const int rc = read_section(L, m, path, in, &blocks) ||
                   sd_req_vec3(&L->c, m, path, "origin", in->origin) ||
                   sd_req_vec3(&L->c, m, path, "velocity", in->velocity) ||
                   read_plane(L, m, path, in) ||
                   sd_req_num(&L->c, m, path, "period", SD_POSITIVE, &in->period) ||
                   sd_opt_num(&L->c, m, path, "offset", SD_NONNEGATIVE, &in->offset) ||
                   read_max_insert_overlap(L, m, path, in) ||
                   read_first_id(L, m, path, in) || read_stop(L, m, path, in) ||
                   scene_check_section_blocks(L, path, in, blocks);
    scene_free_section_blocks(blocks);
    return rc;
}

int scene_read_inlets(loader *L) {
    jd_scene *s = L->s;
    const yaml_node_t *list = sd_get(&L->c, L->root, "inlets");
    if (!list) return 0;
    if (sd_sequence(&L->c, list, "inlets", "a list of {name, section, origin, velocity, plane, "
                    "period, stop, ...}"))
        return -1;
    const size_t n = sd_len(list);
    s->inlets = calloc(n ? n : 1, sizeof *s->inlets);
    L->inode = calloc(n ? n : 1, sizeof *L->inode);
    if (!s->inlets || !L->inode) return sd_no_memory(&L->c, list, "inlets");
    for (size_t k = 0; k < n; k++) {
        char path[SD_PATH_MAX];
        sd_join_index(path, "inlets", k);
        L->inode[k] = sd_item(&L->c, list, k);
        s->n_inlets = k + 1; /* counted before it is read: the scene frees what a failed read took */
        if (read_inlet(L, L->inode[k], path, &s->inlets[k])) return -1;
    }
    return 0;
}

void scene_inlet_spec(const jd_scene *sc, size_t k, jd_inlet_spec *out) {
    const jd_inlet *in = &sc->inlets[k];
    *out = (jd_inlet_spec){.n = in->n, .rel = in->rel, .radius = in->radius,
                           .species = in->material, .period = in->period, .offset = in->offset,
                           .dt = sc->dt, .first_id = in->first_id,
                           .max_sections = in->stop == JD_INLET_STOP_SECTIONS ? in->sections : 0,
                           .stop_step = JD_INLET_NO_STOP,
                           .max_insert_overlap = in->max_insert_overlap,
                           .overlap_tol = in->settled ? sc->watchdog.max_overlap_fraction
                                                      : JD_INLET_OVERLAP_TOL,
                           .n_groups = in->n_groups, .group_first = in->group_first,
                           .group_member = in->group_member, .group_of = in->group_of};
    memcpy(out->origin, in->origin, sizeof out->origin);
    memcpy(out->velocity, in->velocity, sizeof out->velocity);
    memcpy(out->plane_point, in->plane_point, sizeof out->plane_point);
    memcpy(out->plane_normal, in->plane_normal, sizeof out->plane_normal);
    if (in->stop == JD_INLET_STOP_TIME) out->stop_step = jd_inlet_stop_step_of_time(in->stop_time, sc->dt);
}

/* The key of inlet K a kernel check failure is about. */
static const char *failed_key(jd_inlet_status st) {
    switch (st) {
    case JD_INLET_NO_NORMAL: return "plane";
    case JD_INLET_NEVER_CROSSES: return "velocity";
    case JD_INLET_ALREADY_INSIDE: return "origin";
    case JD_INLET_PERIOD_OVERLAP: return "period";
    case JD_INLET_NO_STOP_RULE: return "stop";
    default: return "section";
    }
}

/* first_id auto: after the largest id of the scene's particles and of the inlets before it.
 * An explicit first_id must not reuse an id of the particles or of another inlet. */
static int resolve_first_ids(loader *L) {
    jd_scene *s = L->s;
    int64_t next = 1;
    for (size_t i = 0; i < s->n_particles; i++) next = s->id[i] >= next ? s->id[i] + 1 : next;
    for (size_t k = 0; k < s->n_inlets; k++) {
        jd_inlet *in = &s->inlets[k];
        char path[SD_PATH_MAX];
        snprintf(path, sizeof path, "inlets.%zu.first_id", k);
        const yaml_node_t *at = sd_get(&L->c, L->inode[k], "first_id");
        if (!in->first_id && next < 0)
            return sd_fail(&L->c, at ? at : L->inode[k], path, "auto after an inlet whose "
                           "number of sections is open; valid: an explicit first_id");
        if (!in->first_id) in->first_id = next;
        if (in->first_id < next)
            return sd_fail(&L->c, at, path, "%lld reuses an id of the particles or of an earlier "
                           "inlet; valid: an id >= %lld", (long long)in->first_id, (long long)next);
        next = in->stop == JD_INLET_STOP_SECTIONS
                   ? in->first_id + in->sections * (int64_t)in->n
                   : -1;
    }
    return 0;
}

int scene_check_inlets(loader *L) {
    jd_scene *s = L->s;
    if (resolve_first_ids(L)) return -1;
    for (size_t k = 0; k < s->n_inlets; k++) {
        jd_inlet_spec spec;
        char msg[512], path[SD_PATH_MAX];
        scene_inlet_spec(s, k, &spec);
        const jd_inlet_status st =
            jd_inlet_check(&spec, s->inlets[k].stop == JD_INLET_STOP_HEIGHT, msg, sizeof msg);
        if (st == JD_INLET_OK) continue;
        const char *key = failed_key(st);
        const yaml_node_t *at = sd_get(&L->c, L->inode[k], key);
        snprintf(path, sizeof path, "inlets.%zu.%s", k, key);
        return sd_fail(&L->c, at ? at : L->inode[k], path, "%s", msg);
    }
    return 0;
}
