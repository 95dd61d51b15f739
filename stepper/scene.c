/*
 * scene.c — scene files (docs/scenes.md) -> jd_scene: load with libyaml, apply the case's sweep
 * overrides to the document tree, then validate and resolve every section in one pass.  This
 * file drives the load and reads the small sections; the others have files of their own (see
 * scene_internal.h).
 *
 * Resolution rules that docs/scenes.md leaves to the implementation:
 *   - Interactions: see scene_materials.c.
 *   - The lattice generator is described at generate_lattice() (scene_generate.c).
 *   - A resolved file carries the case name in a top-level `case:` key (see scene_emit.c), so
 *     that `jdem resolve` output loads back as the same case.
 */
#include <libgen.h>
#include <stdlib.h>
#include <string.h>

#include "jdem_domain.h"
#include "jdem_guard.h"
#include "scene_internal.h"
#include "sim.h"

static const char *const TOP_KEYS[] = {"jdem_scene", "name", "case", "description", "time",
                                       "output", "gravity", "model", "materials", "interactions",
                                       "particles", "generate", "walls", "watchdog", "sweep",
                                       "bond_types", "bonds", "bond_rules", "particles_from",
                                       "inlets", "domain", "neighbour", NULL};
static const char *const DOMAIN_KEYS[] = {"lo", "hi", NULL};
static const char *const TIME_KEYS[] = {"dt", "steps", "end_time", "max_impact_speed",
                                         "coordination_number", NULL};
static const char *const OUTPUT_KEYS[] = {"every", "observables_every", "compare_tolerance",
                                          "energy", NULL};
static const char *const MODEL_KEYS[] = {"wall_rule",  "damping",       "tangential_limit",
                                         "mu_r",       "tangential_stiffness", "normal_law",
                                         "mepa_exponent", "mepa_plastic_depth", NULL};
static const char *const NEIGHBOUR_KEYS[] = {"skin_steps", NULL};
static const char *const WATCHDOG_KEYS[] = {"enabled", "max_overlap_fraction", "max_energy_jump",
                                            NULL};

/* Enum spellings, indexed by the kernel's enum values. */
static const char *const WALL_RULES[] = {"hertz", "jiang2021", NULL};
static const char *const DAMPING_MAPS[] = {"jiang2021", "exact_restitution", NULL};
static const char *const XI_LIMITS[] = {"coulomb", "unconstrained", NULL};
static const char *const TANGENTIAL_RULES[] = {"jiang2021", "mindlin", NULL};
static const char *const NORMAL_LAWS[] = {"hertz", "mepa", NULL};
static const char *const BOOLEANS[] = {"false", "true", NULL};
_Static_assert(JD_WALL_HERTZ == 0 && JD_WALL_JIANG2021 == 1, "WALL_RULES order");
_Static_assert(JD_DAMP_JIANG2021 == 0 && JD_DAMP_EXACT == 1, "DAMPING_MAPS order");
_Static_assert(JD_XI_COULOMB == 0 && JD_XI_UNCONSTRAINED == 1, "XI_LIMITS order");
_Static_assert(JD_KT_JIANG2021 == 0 && JD_KT_MINDLIN == 1, "TANGENTIAL_RULES order");
_Static_assert(JD_NORMAL_HERTZ == 0 && JD_NORMAL_MEPA == 1, "NORMAL_LAWS order");

/* ---------------------------------------------------------------------------------------- */
/* Small helpers                                                                             */

int scene_opt_int(loader *L, const yaml_node_t *map, const char *path, const char *key,
                  int64_t lo, int64_t *out) {
    const yaml_node_t *n = sd_get(&L->c, map, key);
    char sub[SD_PATH_MAX];
    sd_join(sub, path, key);
    return n ? sd_int(&L->c, n, sub, lo, out) : 0;
}

int scene_file_path(loader *L, const yaml_node_t *node, const char *path, const char *what,
                    char *out, size_t size) {
    const char *file = sd_scalar(node);
    if (!file || !*file)
        return sd_fail(&L->c, node, path, "expected a file name, got %s; valid: the path of %s",
                       sd_kind(node), what);
    char dir[sizeof L->s->path];
    snprintf(dir, sizeof dir, "%s", L->s->path);
    int n = file[0] == '/' ? snprintf(out, size, "%s", file)
                           : snprintf(out, size, "%s/%s", dirname(dir), file);
    if (n < (int)size) return 0;
    return sd_fail(&L->c, node, path, "the path is too long; valid: at most %zu characters", size - 1);
}

/* An optional section: absent is fine, present must be a mapping with known keys. */
static const yaml_node_t *section(loader *L, const char *key, const char *const *keys, int *rc) {
    const yaml_node_t *n = sd_get(&L->c, L->root, key);
    *rc = n ? sd_keys(&L->c, n, key, keys) : 0;
    return n;
}

/* ---------------------------------------------------------------------------------------- */
/* Header, time, output, gravity, model                                                      */

/* The default name: the file name without directory and extension, checked as a name. */
static int file_stem(sd_ctx *c, const yaml_node_t *root, char *out, size_t size) {
    const char *base = strrchr(c->file, '/');
    base = base ? base + 1 : c->file;
    const char *dot = strrchr(base, '.');
    const size_t len = dot && dot != base ? (size_t)(dot - base) : strlen(base);
    if (sd_check_name(c, root, "name", base, len, size)) {
        const size_t used = strlen(c->err);
        snprintf(c->err + used, c->errlen - used, " (the default name is the file name: give "
                 "name:)");
        return -1;
    }
    memcpy(out, base, len);
    out[len] = '\0';
    return 0;
}

/* name (default: the file stem) and, for a file without sweep, the case name (default: name). */
static int read_names(sd_ctx *c, const yaml_node_t *root, char name[JD_NAME_MAX],
                      char case_name[2 * JD_NAME_MAX]) {
    const yaml_node_t *n = sd_get(c, root, "name");
    if (n ? sd_name(c, n, "name", name, JD_NAME_MAX) : file_stem(c, root, name, JD_NAME_MAX))
        return -1;
    const yaml_node_t *cn = sd_get(c, root, "case");
    if (cn && sd_get(c, root, "sweep"))
        return sd_fail(c, cn, "case", "a scene with a sweep names its cases by the sweep; valid: "
                       "case only without sweep");
    if (cn) return sd_name(c, cn, "case", case_name, 2 * JD_NAME_MAX);
    snprintf(case_name, 2 * JD_NAME_MAX, "%s", name);
    return 0;
}

static int read_header(loader *L) {
    jd_scene *s = L->s;
    const yaml_node_t *v = sd_get(&L->c, L->root, "jdem_scene");
    if (!v) return sd_missing(&L->c, L->root, NULL, "jdem_scene", "1");
    int64_t version;
    if (sd_int(&L->c, v, "jdem_scene", 1, &version)) return -1;
    if (version != 1)
        return sd_fail(&L->c, v, "jdem_scene", "unsupported format version %lld; valid: 1",
                       (long long)version);
    const yaml_node_t *d = sd_get(&L->c, L->root, "description");
    if (!d) return 0;
    if (d->type != YAML_SCALAR_NODE)
        return sd_fail(&L->c, d, "description", "expected text, got %s; valid: a string",
                       sd_kind(d));
    if (d->data.scalar.length >= sizeof s->description)
        return sd_fail(&L->c, d, "description", "too long; valid: at most %zu characters",
                       sizeof s->description - 1);
    memcpy(s->description, d->data.scalar.value, d->data.scalar.length + 1);
    return 0;
}

/* steps = ceil(end_time/dt - 1e-9): the 1e-9 absorbs the rounding of end_time/dt when end_time
 * is meant as a whole number of steps. */
static int read_steps(loader *L, const yaml_node_t *t) {
    const yaml_node_t *st = sd_get(&L->c, t, "steps"), *et = sd_get(&L->c, t, "end_time");
    if (st && et)
        return sd_fail(&L->c, et, "time.end_time", "given together with time.steps; valid: "
                       "either steps or end_time");
    if (st) return sd_int(&L->c, st, "time.steps", 1, &L->s->steps);
    if (!et)
        return sd_missing(&L->c, t, "time", "steps", "an integer >= 1, or end_time: a number > 0");
    double end_time;
    if (sd_num(&L->c, et, "time.end_time", SD_POSITIVE, &end_time)) return -1;
    double steps = ceil(end_time / L->s->dt - 1e-9);
    if (steps < 1.0)
        return sd_fail(&L->c, et, "time.end_time", "shorter than one time step (end_time/dt = "
                       "%g); valid: end_time >= dt", end_time / L->s->dt);
    if (!(steps < 9.0e18))
        return sd_fail(&L->c, et, "time.end_time", "end_time/dt gives %g steps; valid: at most "
                       "9e18 steps", steps);
    L->s->steps = (int64_t)steps;
    return 0;
}

/* time.dt: a number > 0, or `auto` (also when absent), resolved by auto_dt() once the particles
 * and walls are known.  sd_num's messages all end in "valid: a number > 0": ", or auto" is
 * appended to it. */
static int read_dt(loader *L, const yaml_node_t *t) {
    const yaml_node_t *n = sd_get(&L->c, t, "dt");
    L->s->dt_auto = !n || (n->type == YAML_SCALAR_NODE &&
                           n->data.scalar.style == YAML_PLAIN_SCALAR_STYLE &&
                           strcmp((const char *)n->data.scalar.value, "auto") == 0);
    if (L->s->dt_auto || sd_num(&L->c, n, "time.dt", SD_POSITIVE, &L->s->dt) == 0) return 0;
    size_t len = strlen(L->c.err);
    snprintf(L->c.err + len, L->c.errlen - len, ", or auto");
    return -1;
}

/* An auto dt: JD_DT_AUTO_FACTOR x the guard's largest safe dt (guard.c) for the resolved
 * particles, walls, bonds and max_impact_speed; then the steps of an end_time. */
static int auto_dt(loader *L) {
    jd_guard_input in;
    jd_guard_species *species;
    jd_guard_result g;
    if (sim_guard(L->s, &in, &species, &g) != 0)
        return sd_no_memory(&L->c, L->time, "time.dt");
    free(species);
    if (!(g.safe_dt > 0.0 && isfinite(g.safe_dt)))
        return sd_fail(&L->c, L->time, "time.dt", "auto: the time-step guard finds no bound (%g s); "
                       "valid: a number > 0", g.safe_dt);
    L->s->dt = JD_DT_AUTO_FACTOR * g.safe_dt;
    return read_steps(L, L->time) || scene_bond_rule_steps(L) || scene_wall_steps(L);
}

static int read_time(loader *L) {
    const yaml_node_t *t = sd_get(&L->c, L->root, "time");
    if (!t) return sd_missing(&L->c, L->root, NULL, "time", "a mapping with steps or end_time");
    if (sd_keys(&L->c, t, "time", TIME_KEYS) || read_dt(L, t)) return -1;
    L->time = t;
    if (!L->s->dt_auto && read_steps(L, t)) return -1;
    L->max_impact_given = sd_get(&L->c, t, "max_impact_speed") != NULL;
    if (sd_opt_num(&L->c, t, "time", "max_impact_speed", SD_NONNEGATIVE, &L->s->max_impact_speed))
        return -1;
    L->s->coordination_number = JD_GUARD_DEFAULT_COORDINATION;
    return sd_opt_num(&L->c, t, "time", "coordination_number", SD_AT_LEAST_ONE,
                      &L->s->coordination_number);
}

static int read_output(loader *L) {
    int rc;
    const yaml_node_t *o = section(L, "output", OUTPUT_KEYS, &rc);
    L->s->output_every = 1;
    if (rc || scene_opt_int(L, o, "output", "every", 1, &L->s->output_every)) return -1;
    L->s->observables_every = L->s->output_every;
    if (scene_opt_int(L, o, "output", "observables_every", 1, &L->s->observables_every)) return -1;
    L->s->compare_tolerance = 1e-10; /* the two engines run the same kernel in the same order */
    if (sd_opt_num(&L->c, o, "output", "compare_tolerance", SD_POSITIVE, &L->s->compare_tolerance))
        return -1;
    L->s->energy = 1;
    return sd_opt_enum(&L->c, o, "output", "energy", BOOLEANS, &L->s->energy);
}

static int read_model(loader *L) {
    int rc;
    jd_scene *s = L->s;
    const yaml_node_t *m = section(L, "model", MODEL_KEYS, &rc);
    s->wall_rule = JD_WALL_HERTZ;
    s->damping_map = JD_DAMP_JIANG2021;
    s->xi_limit = JD_XI_COULOMB;
    s->mu_r = 1.0;
    s->tangential_rule = JD_KT_JIANG2021;
    s->normal_law = JD_NORMAL_HERTZ;
    s->mepa_exponent = JD_MEPA_DEFAULT_EXPONENT;
    s->mepa_plastic_depth = JD_MEPA_DEFAULT_DEPTH;
    if (rc || sd_opt_enum(&L->c, m, "model", "wall_rule", WALL_RULES, &s->wall_rule) ||
        sd_opt_enum(&L->c, m, "model", "normal_law", NORMAL_LAWS, &s->normal_law) ||
        sd_opt_num(&L->c, m, "model", "mepa_exponent", SD_POSITIVE, &s->mepa_exponent) ||
        sd_opt_num(&L->c, m, "model", "mepa_plastic_depth", SD_POSITIVE,
                   &s->mepa_plastic_depth) ||
        sd_opt_enum(&L->c, m, "model", "damping", DAMPING_MAPS, &s->damping_map) ||
        sd_opt_enum(&L->c, m, "model", "tangential_limit", XI_LIMITS, &s->xi_limit) ||
        sd_opt_enum(&L->c, m, "model", "tangential_stiffness", TANGENTIAL_RULES,
                    &s->tangential_rule))
        return -1;
    static const char *const mepa_keys[] = {"mepa_exponent", "mepa_plastic_depth"};
    for (int k = 0; k < 2 && s->normal_law != JD_NORMAL_MEPA; k++)
        if (sd_get(&L->c, m, mepa_keys[k])) {
            char sub[SD_PATH_MAX];
            sd_join(sub, "model", mepa_keys[k]);
            return sd_fail(&L->c, sd_get(&L->c, m, mepa_keys[k]), sub, "MEPA's option without "
                           "MEPA's law; valid: model.normal_law: mepa, or no %s", mepa_keys[k]);
        }
    return sd_opt_num(&L->c, m, "model", "mu_r", UNIT, &s->mu_r);
}

/* Defaults.  Overlap: half the smaller radius, where Hertz (delta << R) has long stopped
 * meaning anything and only a contact the time step missed gets; not lower, because soft scenes
 * reach 10-20 % legitimately (reference_runs/pour: E = 5 MPa, over 10 %).  Energy: a 5 % jump of
 * the energy in play between two samples is far beyond the integration error of a guarded
 * time step. */
static int read_watchdog(loader *L) {
    int rc;
    jd_watchdog_limits *w = &L->s->watchdog;
    const yaml_node_t *m = section(L, "watchdog", WATCHDOG_KEYS, &rc);
    *w = (jd_watchdog_limits){.enabled = 1, .max_overlap_fraction = 0.5, .max_energy_jump = 0.05};
    return rc || sd_opt_enum(&L->c, m, "watchdog", "enabled", BOOLEANS, &w->enabled) ||
           sd_opt_num(&L->c, m, "watchdog", "max_overlap_fraction", SD_POSITIVE,
                      &w->max_overlap_fraction) ||
           sd_opt_num(&L->c, m, "watchdog", "max_energy_jump", SD_POSITIVE, &w->max_energy_jump);
}

/* Default 20 steps: a falling stream's lists are rebuilt about every 20 steps instead of every
 * few, and the pairs of its fast particles grow by a few per cent (docs/performance.md). */
static int read_neighbour(loader *L) {
    int rc;
    const yaml_node_t *m = section(L, "neighbour", NEIGHBOUR_KEYS, &rc);
    L->s->skin_steps = 20;
    return rc || scene_opt_int(L, m, "neighbour", "skin_steps", 0, &L->s->skin_steps);
}

/* ---------------------------------------------------------------------------------------- */
/* Default max_impact_speed                                                                  */

typedef struct vel {
    double v[3], r; /* velocity and its distance from the mean velocity */
} vel;

static int by_velocity(const void *a, const void *b) {
    const vel *x = a, *y = b;
    for (int d = 0; d < 3; d++)
        if (x->v[d] != y->v[d]) return x->v[d] < y->v[d] ? -1 : 1;
    return 0;
}

static int by_r_desc(const void *a, const void *b) {
    const vel *x = a, *y = b;
    return x->r > y->r ? -1 : x->r < y->r;
}

/* Largest |v_i - v_j| over all pairs: distinct velocities only, visited by decreasing distance
 * from the mean, stopping once r_i + r_j (a bound, by the triangle inequality) cannot win. */
static double max_relative_speed(const jd_scene *s, vel *u) {
    size_t n = s->n_particles, m = 0;
    for (size_t i = 0; i < n; i++) memcpy(u[i].v, &s->velocity[3 * i], sizeof u[i].v);
    qsort(u, n, sizeof *u, by_velocity);
    for (size_t i = 0; i < n; i++)
        if (m == 0 || by_velocity(&u[i], &u[m - 1]) != 0) u[m++] = u[i];
    double mean[3] = {0.0, 0.0, 0.0}, best = 0.0;
    for (size_t i = 0; i < m; i++)
        for (int d = 0; d < 3; d++) mean[d] += u[i].v[d] / (double)m;
    for (size_t i = 0; i < m; i++) {
        double d[3];
        sub3(u[i].v, mean, d);
        u[i].r = norm3(d);
    }
    qsort(u, m, sizeof *u, by_r_desc);
    for (size_t i = 0; i < m && 2.0 * u[i].r > best; i++)
        for (size_t j = i + 1; j < m && u[i].r + u[j].r > best; j++) {
            double d[3];
            sub3(u[i].v, u[j].v, d);
            best = fmax(best, norm3(d));
        }
    return best;
}

/* Height of the initial bounding box (centres +- radius) along gravity, with the inlets'
 * sections at their origins (they enter at that height) and, with inlets, the walls' corners
 * and axis ends (the floor the stream falls onto). */
static double fall_height(const jd_scene *s, const double ghat[3]) {
    double lo = INFINITY, hi = -INFINITY;
    for (size_t i = 0; i < s->n_particles; i++) {
        double h = jd_dot(&s->position[3 * i], ghat);
        lo = fmin(lo, h - s->radius[i]);
        hi = fmax(hi, h + s->radius[i]);
    }
    for (size_t k = 0; k < s->n_inlets; k++)
        for (size_t p = 0; p < s->inlets[k].n; p++) {
            double x[3];
            for (int d = 0; d < 3; d++) x[d] = s->inlets[k].origin[d] + s->inlets[k].rel[3 * p + d];
            lo = fmin(lo, jd_dot(x, ghat) - s->inlets[k].radius[p]);
            hi = fmax(hi, jd_dot(x, ghat) + s->inlets[k].radius[p]);
        }
    for (size_t w = 0; s->n_inlets && w < s->n_walls; w++) {
        const jd_wall *wl = &s->walls[w];
        const int np = wl->type == JD_WALL_PLANE ? 4 : 2;
        for (int c = 0; c < np; c++) {
            const double h = jd_dot(wl->type == JD_WALL_PLANE ? wl->corners[c] : wl->axis[c], ghat);
            lo = fmin(lo, h);
            hi = fmax(hi, h);
        }
    }
    return hi - lo;
}

/* The largest belt speed relative to a wall, or to a resting particle. */
static double inlet_speed(const jd_scene *s) {
    double v = 0.0;
    for (size_t k = 0; k < s->n_inlets; k++) {
        v = fmax(v, norm3(s->inlets[k].velocity));
        for (size_t w = 0; w < s->n_walls; w++) {
            double d[3];
            sub3(s->inlets[k].velocity, s->walls[w].velocity, d);
            v = fmax(v, norm3(d));
        }
    }
    return v;
}

static int default_impact_speed(loader *L) {
    jd_scene *s = L->s;
    vel *u = malloc((s->n_particles ? s->n_particles : 1) * sizeof *u);
    if (!u) return sd_no_memory(&L->c, L->root, NULL);
    double v = max_relative_speed(s, u);
    free(u);
    for (size_t i = 0; i < s->n_particles; i++)
        for (size_t w = 0; w < s->n_walls; w++) {
            double d[3];
            sub3(&s->velocity[3 * i], s->walls[w].velocity, d);
            v = fmax(v, norm3(d));
        }
    if (s->n_particles == 1 && s->n_walls == 0) v = norm3(s->velocity);
    v = fmax(v, inlet_speed(s));
    double g = norm3(s->gravity);
    if (g > 0.0) {
        const double ghat[3] = {s->gravity[0] / g, s->gravity[1] / g, s->gravity[2] / g};
        v += sqrt(2.0 * g * fall_height(s, ghat));
    }
    s->max_impact_speed = v;
    return 0;
}

/* The optional domain: lo and hi, with lo < hi along every axis. */
static int read_domain(loader *L) {
    int rc;
    const yaml_node_t *d = section(L, "domain", DOMAIN_KEYS, &rc);
    if (!d || rc) return rc;
    jd_scene *s = L->s;
    if (sd_req_vec3(&L->c, d, "domain", "lo", s->domain_lo) ||
        sd_req_vec3(&L->c, d, "domain", "hi", s->domain_hi))
        return -1;
    for (int k = 0; k < 3; k++)
        if (!(s->domain_lo[k] < s->domain_hi[k]))
            return sd_fail(&L->c, sd_get(&L->c, d, "hi"), "domain.hi", "%c is %g, not above "
                           "domain.lo's %g; valid: hi > lo along every axis", "xyz"[k],
                           s->domain_hi[k], s->domain_lo[k]);
    s->has_domain = 1;
    return 0;
}

/* Every scene particle starts inside the domain (a particle outside it would be deleted at the
 * first neighbour build, which is never what the scene meant). */
static int check_domain(loader *L) {
    const jd_scene *s = L->s;
    for (size_t i = 0; s->has_domain && i < s->n_particles; i++)
        if (!jd_inside_domain(s->domain_lo, s->domain_hi, &s->position[3 * i]))
            return sd_fail(&L->c, sd_get(&L->c, L->root, "domain"), "domain", "particle id %lld "
                           "at (%g, %g, %g) m lies outside [lo, hi); valid: a domain that holds "
                           "every particle's centre", (long long)s->id[i], s->position[3 * i],
                           s->position[3 * i + 1], s->position[3 * i + 2]);
    return 0;
}

/* ---------------------------------------------------------------------------------------- */
/* Loading                                                                                   */

static int read_scene(loader *L) {
    jd_scene *s = L->s;
    /* Sections in the order of docs/scenes.md, so the first error is usually the first in the
     * file; interactions come last because their defaults depend on which materials meet. */
    if (sd_keys(&L->c, L->root, NULL, TOP_KEYS) || read_header(L) || read_time(L) ||
        read_output(L) || sd_opt_vec3(&L->c, L->root, NULL, "gravity", s->gravity) ||
        read_domain(L) ||
        read_model(L) || read_watchdog(L) || read_neighbour(L) || scene_read_materials(L) ||
        scene_read_bond_types(L) || scene_read_particles(L) || scene_read_generators(L) ||
        scene_read_deposits(L) ||
        scene_read_inlets(L) || scene_read_walls(L) || scene_read_bonds(L))
        return -1;
    if (s->n_inlets && s->n_bond_rules)
        return sd_fail(&L->c, sd_get(&L->c, L->root, "bond_rules"), "bond_rules", "bond rules "
                       "together with inlets; valid: one of the two (an inlet's bonded blocks "
                       "are section.blocks)");
    if (s->n_particles == 0 && s->n_inlets == 0) {
        const yaml_node_t *p = sd_get(&L->c, L->root, "particles");
        return sd_fail(&L->c, p ? p : L->root, "particles", "no particles; valid: at least one "
                       "particle in particles or generate");
    }
    if (scene_read_interactions(L) || scene_sort_particles(L) || scene_check_overlaps(L) ||
        scene_check_wall_overlaps(L) || scene_check_plane_winding(L) || check_domain(L) ||
        scene_resolve_bonds(L))
        return -1;
    if (!L->max_impact_given && default_impact_speed(L)) return -1;
    return (L->s->dt_auto && auto_dt(L)) || scene_check_inlets(L);
}

/* Index of case_name among the cases (NULL: the only one), or -1 after reporting. */
static int pick_case(sd_ctx *c, char **names, int n, const char *case_name) {
    const yaml_node_t *root = yaml_document_get_root_node(c->doc);
    const yaml_node_t *sweep = sd_get(c, root, "sweep");
    for (int i = 0; case_name && i < n; i++)
        if (strcmp(names[i], case_name) == 0) return i;
    if (!case_name && n == 1) return 0;
    char valid[1024] = "";
    size_t used = 0;
    for (int i = 0; i < n && used < sizeof valid; i++) {
        int k = snprintf(valid + used, sizeof valid - used, "%s%s", i ? ", " : "", names[i]);
        used += k > 0 ? (size_t)k : 0;
    }
    if (!case_name)
        return sd_fail(c, sweep, "sweep", "the scene has %d cases, choose one; valid: %s", n,
                       valid);
    return sd_fail(c, sweep ? sweep : root, sweep ? "sweep" : NULL,
                   "no case " SD_QUOTE "; valid: %s", case_name, valid);
}

/* Load the document and list its cases; the document is kept (caller deletes it). */
static int open_cases(sd_ctx *c, const char *path, yaml_document_t *doc, char *name,
                      char *case_name, char ***names, int *n) {
    if (sd_load(c, path, doc)) return -1;
    if (read_names(c, yaml_document_get_root_node(doc), name, case_name) ||
        sd_cases(c, case_name, names, n)) {
        yaml_document_delete(doc);
        return -1;
    }
    return 0;
}

int scene_list_cases(const char *path, char ***names, char *err, size_t errlen) {
    sd_ctx c = {.err = err, .errlen = errlen};
    yaml_document_t doc;
    char name[JD_NAME_MAX], case_name[2 * JD_NAME_MAX];
    int n;
    if (open_cases(&c, path, &doc, name, case_name, names, &n))
        return c.no_memory ? SCENE_NO_MEMORY : SCENE_BAD_INPUT;
    yaml_document_delete(&doc);
    return n;
}

void scene_free_names(char **names, int n) { sd_free_names(names, n); }

int scene_load(const char *path, const char *case_name, jd_scene *scene, char *err,
               size_t errlen) {
    memset(scene, 0, sizeof *scene);
    loader L = {.c = {.err = err, .errlen = errlen}, .s = scene};
    yaml_document_t doc;
    char **names = NULL;
    int n = 0;
    if (strlen(path) >= sizeof scene->path) {
        snprintf(err, errlen, "%s: path too long", path);
        return -1;
    }
    snprintf(scene->path, sizeof scene->path, "%s", path);
    if (open_cases(&L.c, path, &doc, scene->name, scene->case_name, &names, &n))
        return L.c.no_memory ? SCENE_NO_MEMORY : SCENE_BAD_INPUT;
    int k = pick_case(&L.c, names, n, case_name);
    int rc = k < 0 ? -1 : sd_apply_case(&L.c, k);
    if (rc == 0) {
        snprintf(scene->case_name, sizeof scene->case_name, "%s", names[k]);
        /* Overrides may change name: read it again (the case name is already final). */
        char unused[2 * JD_NAME_MAX];
        L.root = yaml_document_get_root_node(&doc);
        rc = read_names(&L.c, L.root, scene->name, unused) || read_scene(&L);
    }
    free(L.pnode);
    free(L.psrc);
    free(L.by_particle);
    free(L.by_wall);
    free(L.bnode);
    free(L.inode);
    sd_free_names(names, n);
    yaml_document_delete(&doc);
    if (rc) scene_free(scene);
    return !rc ? 0 : L.c.no_memory ? SCENE_NO_MEMORY : SCENE_BAD_INPUT;
}

void scene_free(jd_scene *scene) {
    if (!scene) return;
    free(scene->materials);
    free(scene->interactions);
    free(scene->id);
    free(scene->material);
    free(scene->radius);
    free(scene->position);
    free(scene->velocity);
    free(scene->angular_velocity);
    free(scene->fixed);
    free(scene->settled);
    free(scene->force);
    free(scene->walls);
    for (size_t k = 0; k < scene->n_mesh_walls; k++) free(scene->mesh_walls[k].corner);
    free(scene->mesh_walls);
    free(scene->bond_types);
    free(scene->bond_ids);
    free(scene->bond_type);
    for (size_t r = 0; r < scene->n_bond_rules; r++) free(scene->bond_rules[r].materials);
    free(scene->bond_rules);
    for (size_t k = 0; k < scene->n_inlets; k++) {
        free(scene->inlets[k].rel);
        free(scene->inlets[k].radius);
        free(scene->inlets[k].material);
        free(scene->inlets[k].bond_pair);
        free(scene->inlets[k].bond_type);
        free(scene->inlets[k].group_first);
        free(scene->inlets[k].group_member);
        free(scene->inlets[k].group_of);
    }
    free(scene->inlets);
    memset(scene, 0, sizeof *scene);
}
