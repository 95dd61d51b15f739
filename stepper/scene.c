/*
 * scene.c — scene files (docs/scenes.md) -> jd_scene: load with libyaml, apply the case's sweep
 * overrides to the document tree, then validate and resolve every section in one pass.
 *
 * Resolution rules that docs/scenes.md leaves to the implementation:
 *   - Interactions: an unlike pair without an entry takes the common value of a coefficient when
 *     both materials agree.  When they differ, the pair is an error only if it can meet (one
 *     material is used by particles, the other by particles or walls); a pair that never meets
 *     gets the smaller value, which is never used but keeps the emitted matrix explicit.
 *   - The lattice generator is described at generate_lattice().
 *   - A resolved file carries the case name in a top-level `case:` key (see scene_emit.c), so
 *     that `jdem resolve` output loads back as the same case.
 */
#include "scene.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "jdem_kernel.h"
#include "scene_doc.h"

/* Relative tolerances of docs/scenes.md. */
#define OVERLAP_TOL 1e-6  /* initial overlap, fraction of the smaller radius */
#define GEOM_TOL 1e-9     /* wall geometry, fraction of the wall's size */
#define MAX_PARTICLES 100000000

static const char *const TOP_KEYS[] = {"jdem_scene", "name", "case", "description", "time",
                                       "output", "gravity", "model", "materials", "interactions",
                                       "particles", "generate", "walls", "sweep", NULL};
static const char *const TIME_KEYS[] = {"dt", "steps", "end_time", "max_impact_speed", NULL};
static const char *const OUTPUT_KEYS[] = {"every", "observables_every", NULL};
static const char *const MODEL_KEYS[] = {"wall_rule", "damping", "tangential_limit", "mu_r", NULL};
static const char *const MATERIAL_KEYS[] = {"youngs_modulus", "poisson_ratio", "density",
                                            "restitution", "friction", "rolling_friction", NULL};
static const char *const INTERACTION_KEYS[] = {"materials", "restitution", "friction",
                                               "rolling_friction", NULL};
static const char *const PARTICLE_KEYS[] = {"id", "material", "radius", "position", "velocity",
                                            "angular_velocity", NULL};
static const char *const GENERATOR_KEYS[] = {"lattice", NULL};
static const char *const LATTICE_KEYS[] = {"material", "radius", "radii", "origin", "spacing",
                                           "counts", "jitter", "velocity", "seed", NULL};
static const char *const RADII_KEYS[] = {"values", "fractions", NULL};
static const char *const PLANE_KEYS[] = {"name", "type", "corners", "material", "velocity", NULL};
static const char *const CYLINDER_KEYS[] = {"name", "type", "axis", "radius", "side", "material",
                                            "velocity", NULL};

/* Enum spellings, indexed by the kernel's enum values. */
static const char *const WALL_RULES[] = {"hertz", "jiang2021", NULL};
static const char *const DAMPING_MAPS[] = {"jiang2021", "exact_restitution", NULL};
static const char *const XI_LIMITS[] = {"coulomb", "unconstrained", NULL};
static const char *const WALL_TYPES[] = {"plane", "cylinder", NULL};
static const char *const CYLINDER_SIDES[] = {"outside", "inside", NULL};
_Static_assert(JD_WALL_HERTZ == 0 && JD_WALL_JIANG2021 == 1, "WALL_RULES order");
_Static_assert(JD_DAMP_JIANG2021 == 0 && JD_DAMP_EXACT == 1, "DAMPING_MAPS order");
_Static_assert(JD_XI_COULOMB == 0 && JD_XI_UNCONSTRAINED == 1, "XI_LIMITS order");
_Static_assert(JD_WALL_PLANE == 0 && JD_WALL_CYLINDER == 1, "WALL_TYPES order");

static const sd_range RESTITUTION = {0.0, 1.0, 1, 0};
static const sd_range POISSON = {-1.0, 0.5, 1, 1};
static const sd_range UNIT = {0.0, 1.0, 0, 0};

/* Loader state: the scene being filled plus, per particle, where it came from (for messages). */
typedef struct loader {
    sd_ctx c;
    jd_scene *s;
    const yaml_node_t *root;
    size_t cap;                 /* allocated particles */
    const yaml_node_t **pnode;  /* the particle's mapping, or its generator's */
    int32_t *psrc;              /* >= 0: index in particles; < 0: -(generator index + 1) */
    unsigned char *by_particle; /* per material: used by a particle */
    unsigned char *by_wall;     /* per material: used by a wall */
    int max_impact_given;
} loader;

/* ---------------------------------------------------------------------------------------- */
/* Small helpers                                                                             */

static double norm3(const double v[3]) { return sqrt(jd_dot(v, v)); }

static void sub3(const double a[3], const double b[3], double out[3]) {
    for (int d = 0; d < 3; d++) out[d] = a[d] - b[d];
}

static void material_names(const jd_scene *s, char *out, size_t size) {
    size_t used = 0;
    out[0] = '\0';
    for (size_t i = 0; i < s->n_materials && used < size; i++) {
        int k = snprintf(out + used, size - used, "%s%s", i ? ", " : "", s->materials[i].name);
        if (k < 0) break;
        used += (size_t)k;
    }
}

/* Material index named by scalar node n, or -1 after reporting. */
static int material_ref(loader *L, const yaml_node_t *n, const char *path) {
    char name[JD_NAME_MAX];
    if (sd_str(&L->c, n, path, name, sizeof name)) return -1;
    for (size_t i = 0; i < L->s->n_materials; i++)
        if (strcmp(L->s->materials[i].name, name) == 0) return (int)i;
    char valid[512];
    material_names(L->s, valid, sizeof valid);
    return sd_fail(&L->c, n, path, "unknown material '%s'; valid: %s", name, valid);
}

static int req_material(loader *L, const yaml_node_t *map, const char *path, int *out) {
    const yaml_node_t *n = sd_get(&L->c, map, "material");
    char sub[SD_PATH_MAX], valid[512];
    if (!n) {
        material_names(L->s, valid, sizeof valid);
        return sd_missing(&L->c, map, path, "material", valid);
    }
    sd_join(sub, path, "material");
    return (*out = material_ref(L, n, sub)) < 0 ? -1 : 0;
}

static int opt_int(loader *L, const yaml_node_t *map, const char *path, const char *key,
                   int64_t lo, int64_t *out) {
    const yaml_node_t *n = sd_get(&L->c, map, key);
    char sub[SD_PATH_MAX];
    sd_join(sub, path, key);
    return n ? sd_int(&L->c, n, sub, lo, out) : 0;
}

/* An optional section: absent is fine, present must be a mapping with known keys. */
static const yaml_node_t *section(loader *L, const char *key, const char *const *keys, int *rc) {
    const yaml_node_t *n = sd_get(&L->c, L->root, key);
    *rc = n ? sd_keys(&L->c, n, key, keys) : 0;
    return n;
}

/* ---------------------------------------------------------------------------------------- */
/* Header, time, output, gravity, model                                                      */

static void file_stem(const char *path, char *out, size_t size) {
    const char *base = strrchr(path, '/');
    base = base ? base + 1 : path;
    const char *dot = strrchr(base, '.');
    size_t len = dot && dot != base ? (size_t)(dot - base) : strlen(base);
    if (len >= size) len = size - 1;
    memcpy(out, base, len);
    out[len] = '\0';
}

/* name (default: the file stem) and, for a file without sweep, the case name (default: name). */
static int read_names(sd_ctx *c, const yaml_node_t *root, char name[JD_NAME_MAX],
                      char case_name[2 * JD_NAME_MAX]) {
    const yaml_node_t *n = sd_get(c, root, "name");
    if (n) {
        if (sd_str(c, n, "name", name, JD_NAME_MAX)) return -1;
    } else {
        file_stem(c->file, name, JD_NAME_MAX);
    }
    const yaml_node_t *cn = sd_get(c, root, "case");
    if (cn && sd_get(c, root, "sweep"))
        return sd_fail(c, cn, "case", "a scene with a sweep names its cases by the sweep; valid: "
                       "case only without sweep");
    if (cn) return sd_str(c, cn, "case", case_name, 2 * JD_NAME_MAX);
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

static int read_time(loader *L) {
    const yaml_node_t *t = sd_get(&L->c, L->root, "time");
    if (!t) return sd_missing(&L->c, L->root, NULL, "time", "a mapping with dt and steps");
    if (sd_keys(&L->c, t, "time", TIME_KEYS)) return -1;
    if (sd_req_num(&L->c, t, "time", "dt", SD_POSITIVE, &L->s->dt)) return -1;
    if (read_steps(L, t)) return -1;
    L->max_impact_given = sd_get(&L->c, t, "max_impact_speed") != NULL;
    return sd_opt_num(&L->c, t, "time", "max_impact_speed", SD_NONNEGATIVE,
                      &L->s->max_impact_speed);
}

static int read_output(loader *L) {
    int rc;
    const yaml_node_t *o = section(L, "output", OUTPUT_KEYS, &rc);
    L->s->output_every = 1;
    if (rc || opt_int(L, o, "output", "every", 1, &L->s->output_every)) return -1;
    L->s->observables_every = L->s->output_every;
    return opt_int(L, o, "output", "observables_every", 1, &L->s->observables_every);
}

static int read_model(loader *L) {
    int rc;
    jd_scene *s = L->s;
    const yaml_node_t *m = section(L, "model", MODEL_KEYS, &rc);
    s->wall_rule = JD_WALL_HERTZ;
    s->damping_map = JD_DAMP_JIANG2021;
    s->xi_limit = JD_XI_COULOMB;
    s->mu_r = 1.0;
    if (rc || sd_opt_enum(&L->c, m, "model", "wall_rule", WALL_RULES, &s->wall_rule) ||
        sd_opt_enum(&L->c, m, "model", "damping", DAMPING_MAPS, &s->damping_map) ||
        sd_opt_enum(&L->c, m, "model", "tangential_limit", XI_LIMITS, &s->xi_limit))
        return -1;
    return sd_opt_num(&L->c, m, "model", "mu_r", UNIT, &s->mu_r);
}

/* ---------------------------------------------------------------------------------------- */
/* Materials and interactions                                                                */

/* youngs_modulus, poisson_ratio and density: all three, or none (a wall-only material). */
static int read_elastic(loader *L, const yaml_node_t *m, const char *path, jd_material *mat) {
    static const char *const keys[] = {"youngs_modulus", "poisson_ratio", "density"};
    int given = 0;
    for (int k = 0; k < 3; k++) given += sd_get(&L->c, m, keys[k]) != NULL;
    mat->has_elastic = given > 0;
    if (!given) return 0;
    const char *together = "youngs_modulus, poisson_ratio and density go together";
    for (int k = 0; k < 3; k++)
        if (!sd_get(&L->c, m, keys[k])) {
            char valid[128];
            snprintf(valid, sizeof valid, "%s (%s)", k == 1 ? "a number in (-1, 0.5)"
                                                            : "a number > 0", together);
            return sd_missing(&L->c, m, path, keys[k], valid);
        }
    return sd_req_num(&L->c, m, path, "youngs_modulus", SD_POSITIVE, &mat->youngs_modulus) ||
                   sd_req_num(&L->c, m, path, "poisson_ratio", POISSON, &mat->poisson_ratio) ||
                   sd_req_num(&L->c, m, path, "density", SD_POSITIVE, &mat->density)
               ? -1
               : 0;
}

static int read_material(loader *L, const yaml_node_pair_t *p, jd_material *mat) {
    const char *name = sd_scalar(sd_node(&L->c, p->key));
    const yaml_node_t *m = sd_node(&L->c, p->value);
    char path[SD_PATH_MAX];
    sd_join(path, "materials", name);
    if (strlen(name) >= JD_NAME_MAX)
        return sd_fail(&L->c, sd_node(&L->c, p->key), path, "name too long; valid: at most %d "
                       "characters", JD_NAME_MAX - 1);
    snprintf(mat->name, sizeof mat->name, "%s", name);
    mat->restitution = 1.0;
    if (sd_keys(&L->c, m, path, MATERIAL_KEYS) || read_elastic(L, m, path, mat)) return -1;
    return sd_opt_num(&L->c, m, path, "restitution", RESTITUTION, &mat->restitution) ||
                   sd_opt_num(&L->c, m, path, "friction", SD_NONNEGATIVE, &mat->friction) ||
                   sd_opt_num(&L->c, m, path, "rolling_friction", SD_NONNEGATIVE,
                              &mat->rolling_friction)
               ? -1
               : 0;
}

static int read_materials(loader *L) {
    jd_scene *s = L->s;
    const yaml_node_t *m = sd_get(&L->c, L->root, "materials");
    const char *valid = "a mapping NAME: {youngs_modulus, poisson_ratio, density, ...}";
    if (!m) return sd_missing(&L->c, L->root, NULL, "materials", valid);
    if (sd_keys(&L->c, m, "materials", NULL)) return -1;
    size_t n = (size_t)(m->data.mapping.pairs.top - m->data.mapping.pairs.start);
    if (n == 0) return sd_fail(&L->c, m, "materials", "empty; valid: at least one material");
    s->materials = calloc(n, sizeof *s->materials);
    s->interactions = calloc(n * n, sizeof *s->interactions);
    L->by_particle = calloc(n, 1);
    L->by_wall = calloc(n, 1);
    if (!s->materials || !s->interactions || !L->by_particle || !L->by_wall)
        return sd_fail(&L->c, m, "materials", "out of memory");
    s->n_materials = n;
    for (size_t i = 0; i < n; i++)
        if (read_material(L, &m->data.mapping.pairs.start[i], &s->materials[i])) return -1;
    return 0;
}

enum { N_COEF = 3 };
static const char *const COEF_KEYS[N_COEF] = {"restitution", "friction", "rolling_friction"};

static double *coef(jd_interaction *x, int k) {
    return k == 0 ? &x->restitution : k == 1 ? &x->friction : &x->rolling_friction;
}
static double mat_coef(const jd_material *m, int k) {
    return k == 0 ? m->restitution : k == 1 ? m->friction : m->rolling_friction;
}

/* One interactions entry: its pair (a <= b) and which coefficients it gives. */
static int read_interaction(loader *L, const yaml_node_t *e, const char *path, int *a, int *b,
                            jd_interaction *val, int given[N_COEF]) {
    if (sd_keys(&L->c, e, path, INTERACTION_KEYS)) return -1;
    const yaml_node_t *pair = sd_get(&L->c, e, "materials");
    char sub[SD_PATH_MAX], item[SD_PATH_MAX];
    sd_join(sub, path, "materials");
    if (!pair) return sd_missing(&L->c, e, path, "materials", "[MATERIAL, MATERIAL]");
    if (pair->type != YAML_SEQUENCE_NODE || sd_len(pair) != 2)
        return sd_fail(&L->c, pair, sub, "expected two material names, got %s; valid: "
                       "[MATERIAL, MATERIAL]", sd_kind(pair));
    int ab[2];
    for (size_t i = 0; i < 2; i++) {
        sd_join_index(item, sub, i);
        if ((ab[i] = material_ref(L, sd_item(&L->c, pair, i), item)) < 0) return -1;
    }
    *a = ab[0] < ab[1] ? ab[0] : ab[1];
    *b = ab[0] < ab[1] ? ab[1] : ab[0];
    const sd_range ranges[N_COEF] = {RESTITUTION, SD_NONNEGATIVE, SD_NONNEGATIVE};
    for (int k = 0; k < N_COEF; k++) {
        given[k] = sd_get(&L->c, e, COEF_KEYS[k]) != NULL;
        if (sd_opt_num(&L->c, e, path, COEF_KEYS[k], ranges[k], coef(val, k))) return -1;
    }
    return 0;
}

/* A pair can meet when one side is a particle material and the other a particle or wall one. */
static int pair_meets(const loader *L, size_t a, size_t b) {
    return (L->by_particle[a] && (L->by_particle[b] || L->by_wall[b])) ||
           (L->by_particle[b] && L->by_wall[a]);
}

/* Fill the coefficient k of pair (a, b) that no entry gives. */
static int default_coef(loader *L, size_t a, size_t b, int k, double *out) {
    const jd_material *ma = &L->s->materials[a], *mb = &L->s->materials[b];
    double va = mat_coef(ma, k), vb = mat_coef(mb, k);
    if (va == vb || !pair_meets(L, a, b)) {
        *out = va < vb ? va : vb;
        return 0;
    }
    const yaml_node_t *at = sd_get(&L->c, L->root, "interactions");
    if (!at) at = sd_get(&L->c, L->root, "materials");
    return sd_fail(&L->c, at, "interactions", "materials '%s' and '%s' differ in %s (%g vs %g) "
                   "and no entry gives it; valid: an entry {materials: [%s, %s], %s: ...}",
                   ma->name, mb->name, COEF_KEYS[k], va, vb, ma->name, mb->name, COEF_KEYS[k]);
}

static int read_interactions(loader *L) {
    jd_scene *s = L->s;
    size_t n = s->n_materials;
    unsigned char *given = calloc(n * n, N_COEF);
    const yaml_node_t **first = calloc(n * n, sizeof *first);
    const yaml_node_t *list = sd_get(&L->c, L->root, "interactions");
    int rc = (!given || !first) ? sd_fail(&L->c, list, "interactions", "out of memory") : 0;
    if (!rc && list)
        rc = sd_sequence(&L->c, list, "interactions", "a list of {materials: [A, B], "
                         "restitution, friction, rolling_friction}");
    for (size_t i = 0; !rc && list && i < sd_len(list); i++) {
        char path[SD_PATH_MAX];
        sd_join_index(path, "interactions", i);
        const yaml_node_t *e = sd_item(&L->c, list, i);
        int a = 0, b = 0, g[N_COEF];
        jd_interaction val = {0};
        if ((rc = read_interaction(L, e, path, &a, &b, &val, g))) break;
        size_t ab = (size_t)a * n + (size_t)b;
        if (first[ab]) {
            rc = sd_fail(&L->c, e, path, "a second entry for '%s' and '%s' (first at line %zu); "
                         "valid: one entry per pair", s->materials[a].name, s->materials[b].name,
                         first[ab]->start_mark.line + 1);
            break;
        }
        first[ab] = e;
        for (int k = 0; k < N_COEF; k++)
            if (g[k]) {
                given[ab * N_COEF + (size_t)k] = 1;
                *coef(&s->interactions[ab], k) = *coef(&val, k);
            }
    }
    for (size_t a = 0; !rc && a < n; a++)
        for (size_t b = a; !rc && b < n; b++) {
            jd_interaction *x = &s->interactions[a * n + b];
            for (int k = 0; !rc && k < N_COEF; k++) {
                if (given[(a * n + b) * N_COEF + (size_t)k]) continue;
                if (a == b)
                    *coef(x, k) = mat_coef(&s->materials[a], k);
                else
                    rc = default_coef(L, a, b, k, coef(x, k));
            }
            s->interactions[b * n + a] = *x;
        }
    free(given);
    free(first);
    return rc;
}

/* ---------------------------------------------------------------------------------------- */
/* Particles                                                                                 */

static int grow_particles(loader *L, size_t need) {
    jd_scene *s = L->s;
    if (need <= L->cap) return 0;
    size_t cap = L->cap ? L->cap : 64;
    while (cap < need) cap *= 2;
#define GROW(p, k)                                                    \
    do {                                                              \
        void *q = realloc((p), cap * (k) * sizeof *(p));              \
        if (!q) return sd_fail(&L->c, L->root, NULL, "out of memory"); \
        (p) = q;                                                      \
    } while (0)
    GROW(s->id, 1);
    GROW(s->material, 1);
    GROW(s->radius, 1);
    GROW(s->position, 3);
    GROW(s->velocity, 3);
    GROW(s->angular_velocity, 3);
    GROW(L->pnode, 1);
    GROW(L->psrc, 1);
#undef GROW
    L->cap = cap;
    return 0;
}

/* Append a particle with zero velocities; returns its index or -1. */
static long add_particle(loader *L, const yaml_node_t *node, int32_t src) {
    jd_scene *s = L->s;
    if (s->n_particles >= MAX_PARTICLES)
        return sd_fail(&L->c, node, "particles", "more than %d particles; valid: fewer",
                       MAX_PARTICLES);
    if (grow_particles(L, s->n_particles + 1)) return -1;
    size_t i = s->n_particles++;
    memset(&s->velocity[3 * i], 0, 3 * sizeof(double));
    memset(&s->angular_velocity[3 * i], 0, 3 * sizeof(double));
    L->pnode[i] = node;
    L->psrc[i] = src;
    return (long)i;
}

static int particle_material(loader *L, const yaml_node_t *map, const char *path, int *mat) {
    if (req_material(L, map, path, mat)) return -1;
    if (L->s->materials[*mat].has_elastic) {
        L->by_particle[*mat] = 1;
        return 0;
    }
    char sub[SD_PATH_MAX];
    sd_join(sub, path, "material");
    return sd_fail(&L->c, sd_get(&L->c, map, "material"), sub, "material '%s' has no "
                   "youngs_modulus, poisson_ratio and density; valid: a material with elastic "
                   "properties", L->s->materials[*mat].name);
}

static int read_particle(loader *L, const yaml_node_t *p, size_t index) {
    jd_scene *s = L->s;
    char path[SD_PATH_MAX];
    sd_join_index(path, "particles", index);
    if (sd_keys(&L->c, p, path, PARTICLE_KEYS)) return -1;
    long i = add_particle(L, p, (int32_t)index);
    if (i < 0) return -1;
    int mat;
    s->id[i] = (int64_t)index + 1;
    if (opt_int(L, p, path, "id", 1, &s->id[i]) || particle_material(L, p, path, &mat) ||
        sd_req_num(&L->c, p, path, "radius", SD_POSITIVE, &s->radius[i]) ||
        sd_req_vec3(&L->c, p, path, "position", &s->position[3 * i]) ||
        sd_opt_vec3(&L->c, p, path, "velocity", &s->velocity[3 * i]) ||
        sd_opt_vec3(&L->c, p, path, "angular_velocity", &s->angular_velocity[3 * i]))
        return -1;
    s->material[i] = mat;
    return 0;
}

static int read_particles(loader *L) {
    const yaml_node_t *list = sd_get(&L->c, L->root, "particles");
    if (!list) return 0;
    if (sd_sequence(&L->c, list, "particles", "a list of {id, material, radius, position, ...}"))
        return -1;
    for (size_t i = 0; i < sd_len(list); i++)
        if (read_particle(L, sd_item(&L->c, list, i), i)) return -1;
    return 0;
}

/* ---------------------------------------------------------------------------------------- */
/* Lattice generator                                                                         */

/* splitmix64 (Steele, Lea & Flood 2014; public domain reference by S. Vigna): a tiny,
 * well-mixed generator, so a seed gives the same lattice on every platform. */
static uint64_t splitmix64(uint64_t *state) {
    uint64_t z = (*state += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}

/* Uniform in [0, 1) with 53 random bits. */
static double uniform01(uint64_t *state) {
    return (double)(splitmix64(state) >> 11) * 0x1.0p-53;
}

typedef struct lattice {
    int material;
    size_t n_radii;
    double radii[64], fractions[64];
    double origin[3], spacing, jitter, velocity[3];
    int64_t counts[3], seed;
} lattice;

static int read_radii(loader *L, const yaml_node_t *lat, const char *path, lattice *g) {
    const yaml_node_t *r = sd_get(&L->c, lat, "radius"), *rs = sd_get(&L->c, lat, "radii");
    char sub[SD_PATH_MAX], item[SD_PATH_MAX];
    sd_join(sub, path, "radii");
    if (r && rs)
        return sd_fail(&L->c, rs, sub, "given together with radius; valid: either radius or "
                       "radii");
    if (!rs) {
        g->n_radii = 1;
        g->fractions[0] = 1.0;
        if (r) return sd_req_num(&L->c, lat, path, "radius", SD_POSITIVE, &g->radii[0]);
        return sd_missing(&L->c, lat, path, "radius", "a number > 0, or radii: {values: [...], "
                          "fractions: [...]}");
    }
    if (sd_keys(&L->c, rs, sub, RADII_KEYS)) return -1;
    const yaml_node_t *v = sd_get(&L->c, rs, "values"), *f = sd_get(&L->c, rs, "fractions");
    if (!v) return sd_missing(&L->c, rs, sub, "values", "a list of radii > 0");
    if (!f) return sd_missing(&L->c, rs, sub, "fractions", "a list of numbers >= 0");
    sd_join(item, sub, "values");
    if (sd_sequence(&L->c, v, item, "a list of radii > 0")) return -1;
    g->n_radii = sd_len(v);
    if (g->n_radii == 0 || g->n_radii > 64)
        return sd_fail(&L->c, v, item, "%zu values; valid: 1 to 64 radii", g->n_radii);
    sd_join(item, sub, "fractions");
    if (sd_vec(&L->c, f, item, g->n_radii, g->fractions)) return -1;
    double sum = 0.0;
    for (size_t k = 0; k < g->n_radii; k++) {
        char at[SD_PATH_MAX];
        sd_join_index(at, item, k);
        if (sd_num(&L->c, sd_item(&L->c, f, k), at, SD_NONNEGATIVE, &g->fractions[k])) return -1;
        sum += g->fractions[k];
        sd_join(at, sub, "values");
        sd_join_index(at, at, k);
        if (sd_num(&L->c, sd_item(&L->c, v, k), at, SD_POSITIVE, &g->radii[k])) return -1;
    }
    if (!(sum > 0.0))
        return sd_fail(&L->c, f, item, "the fractions sum to 0; valid: fractions with a "
                       "positive sum (they are normalised)");
    for (size_t k = 0; k < g->n_radii; k++) g->fractions[k] /= sum;
    return 0;
}

static int read_counts(loader *L, const yaml_node_t *lat, const char *path, lattice *g) {
    const yaml_node_t *n = sd_get(&L->c, lat, "counts");
    char sub[SD_PATH_MAX], item[SD_PATH_MAX];
    sd_join(sub, path, "counts");
    if (!n) return sd_missing(&L->c, lat, path, "counts", "[nx, ny, nz], integers >= 1");
    if (n->type != YAML_SEQUENCE_NODE || sd_len(n) != 3)
        return sd_fail(&L->c, n, sub, "expected three integers, got %s; valid: [nx, ny, nz]",
                       sd_kind(n));
    double total = 1.0;
    for (size_t d = 0; d < 3; d++) {
        sd_join_index(item, sub, d);
        if (sd_int(&L->c, sd_item(&L->c, n, d), item, 1, &g->counts[d])) return -1;
        total *= (double)g->counts[d];
    }
    if (total > MAX_PARTICLES)
        return sd_fail(&L->c, n, sub, "%.0f sites; valid: at most %d", total, MAX_PARTICLES);
    return 0;
}

static int read_lattice(loader *L, const yaml_node_t *lat, const char *path, lattice *g) {
    char sub[SD_PATH_MAX];
    g->seed = 1;
    if (sd_keys(&L->c, lat, path, LATTICE_KEYS) || req_material(L, lat, path, &g->material) ||
        read_radii(L, lat, path, g) || sd_req_vec3(&L->c, lat, path, "origin", g->origin) ||
        sd_req_num(&L->c, lat, path, "spacing", SD_POSITIVE, &g->spacing) ||
        read_counts(L, lat, path, g) ||
        sd_opt_num(&L->c, lat, path, "jitter", UNIT, &g->jitter) ||
        sd_opt_vec3(&L->c, lat, path, "velocity", g->velocity) ||
        opt_int(L, lat, path, "seed", 0, &g->seed))
        return -1;
    if (!L->s->materials[g->material].has_elastic) {
        sd_join(sub, path, "material");
        return sd_fail(&L->c, sd_get(&L->c, lat, "material"), sub, "material '%s' has no "
                       "youngs_modulus, poisson_ratio and density; valid: a material with "
                       "elastic properties", L->s->materials[g->material].name);
    }
    L->by_particle[g->material] = 1;
    double rmax = 0.0;
    for (size_t k = 0; k < g->n_radii; k++) rmax = g->radii[k] > rmax ? g->radii[k] : rmax;
    if (g->spacing < 2.0 * rmax) {
        sd_join(sub, path, "spacing");
        return sd_fail(&L->c, sd_get(&L->c, lat, "spacing"), sub, "%.17g is smaller than the "
                       "largest diameter %.17g; valid: spacing >= 2 * radius", g->spacing,
                       2.0 * rmax);
    }
    return 0;
}

/* Radius index of each site: exactly round(fraction * n) sites per radius (largest remainder),
 * in a seeded Fisher–Yates shuffle, so small lattices get the intended mixture. */
static void assign_radii(const lattice *g, size_t n, uint64_t *rng, unsigned char *which) {
    size_t count[64], assigned = 0;
    double rem[64];
    for (size_t k = 0; k < g->n_radii; k++) {
        double want = g->fractions[k] * (double)n;
        count[k] = (size_t)floor(want);
        rem[k] = want - floor(want);
        assigned += count[k];
    }
    while (assigned < n) { /* hand the leftover sites to the largest remainders */
        size_t best = 0;
        for (size_t k = 1; k < g->n_radii; k++) best = rem[k] > rem[best] ? k : best;
        count[best]++;
        rem[best] = -1.0;
        assigned++;
    }
    size_t at = 0;
    for (size_t k = 0; k < g->n_radii; k++)
        for (size_t j = 0; j < count[k] && at < n; j++) which[at++] = (unsigned char)k;
    for (size_t i = n; i-- > 1;) {
        size_t j = (size_t)(splitmix64(rng) % (i + 1));
        unsigned char t = which[i];
        which[i] = which[j];
        which[j] = t;
    }
}

/* The lattice generator.  Sites are origin + spacing * (i, j, k), with i (x) varying fastest,
 * then j (y), then k (z); ids follow that order.  With a seed, the generator first shuffles the
 * radii (assign_radii), then draws three offsets per site, in site order, each uniform in
 * [-jitter * gap / 2, +jitter * gap / 2] with gap = spacing - 2 * (largest radius): with
 * jitter <= 1 neighbours cannot overlap. */
static int generate_lattice(loader *L, const yaml_node_t *lat, int32_t gen, lattice *g,
                            int64_t *next_id) {
    jd_scene *s = L->s;
    size_t n = (size_t)(g->counts[0] * g->counts[1] * g->counts[2]);
    unsigned char *which = calloc(n, 1);
    if (!which) return sd_fail(&L->c, lat, NULL, "out of memory");
    uint64_t rng = (uint64_t)g->seed;
    assign_radii(g, n, &rng, which);
    double rmax = 0.0;
    for (size_t k = 0; k < g->n_radii; k++) rmax = g->radii[k] > rmax ? g->radii[k] : rmax;
    const double amp = g->jitter * (g->spacing - 2.0 * rmax) / 2.0;
    int rc = 0;
    for (size_t site = 0; site < n && rc == 0; site++) {
        const size_t ijk[3] = {site % (size_t)g->counts[0],
                               site / (size_t)g->counts[0] % (size_t)g->counts[1],
                               site / (size_t)(g->counts[0] * g->counts[1])};
        long i = add_particle(L, lat, -(gen + 1));
        if (i < 0) {
            rc = -1;
            break;
        }
        s->id[i] = (*next_id)++;
        s->material[i] = g->material;
        s->radius[i] = g->radii[which[site]];
        for (int d = 0; d < 3; d++) {
            double jit = amp > 0.0 ? (2.0 * uniform01(&rng) - 1.0) * amp : 0.0;
            s->position[3 * i + d] = g->origin[d] + (double)ijk[d] * g->spacing + jit;
            s->velocity[3 * i + d] = g->velocity[d];
        }
    }
    free(which);
    return rc;
}

static int read_generators(loader *L) {
    const yaml_node_t *list = sd_get(&L->c, L->root, "generate");
    if (!list) return 0;
    if (sd_sequence(&L->c, list, "generate", "a list of {lattice: {...}}")) return -1;
    int64_t next_id = 1;
    for (size_t i = 0; i < L->s->n_particles; i++)
        next_id = L->s->id[i] >= next_id ? L->s->id[i] + 1 : next_id;
    for (size_t k = 0; k < sd_len(list); k++) {
        char path[SD_PATH_MAX], sub[SD_PATH_MAX];
        sd_join_index(path, "generate", k);
        const yaml_node_t *e = sd_item(&L->c, list, k);
        if (sd_keys(&L->c, e, path, GENERATOR_KEYS)) return -1;
        const yaml_node_t *lat = sd_get(&L->c, e, "lattice");
        if (!lat) return sd_missing(&L->c, e, path, "lattice", "a lattice generator");
        sd_join(sub, path, "lattice");
        lattice g = {0};
        if (read_lattice(L, lat, sub, &g) || generate_lattice(L, lat, (int32_t)k, &g, &next_id))
            return -1;
    }
    return 0;
}

/* ---------------------------------------------------------------------------------------- */
/* Ordering, duplicate ids and initial overlaps                                              */

typedef struct id_index {
    int64_t id;
    size_t index;
} id_index;

static int by_id(const void *a, const void *b) {
    const id_index *x = a, *y = b;
    if (x->id != y->id) return x->id < y->id ? -1 : 1;
    return x->index < y->index ? -1 : x->index > y->index;
}

static void particle_path(const loader *L, size_t i, char out[SD_PATH_MAX]) {
    if (L->psrc[i] >= 0)
        sd_join_index(out, "particles", (size_t)L->psrc[i]);
    else
        snprintf(out, SD_PATH_MAX, "generate.%d.lattice", -L->psrc[i] - 1);
}

/* Reorder every per-particle array by perm (new i <- old perm[i]). */
static int permute(loader *L, const id_index *perm) {
    jd_scene *s = L->s;
    size_t n = s->n_particles;
    void *tmp = malloc(n * 3 * sizeof(double));
    if (!tmp) return sd_fail(&L->c, L->root, NULL, "out of memory");
#define PERMUTE(arr, k)                                                              \
    do {                                                                             \
        for (size_t i = 0; i < n; i++)                                               \
            memcpy((char *)tmp + i * (k) * sizeof *(arr), &(arr)[perm[i].index * (k)], \
                   (k) * sizeof *(arr));                                             \
        memcpy((arr), tmp, n * (k) * sizeof *(arr));                                 \
    } while (0)
    PERMUTE(s->id, 1);
    PERMUTE(s->material, 1);
    PERMUTE(s->radius, 1);
    PERMUTE(s->position, 3);
    PERMUTE(s->velocity, 3);
    PERMUTE(s->angular_velocity, 3);
    PERMUTE(L->pnode, 1);
    PERMUTE(L->psrc, 1);
#undef PERMUTE
    free(tmp);
    return 0;
}

static int sort_particles(loader *L) {
    size_t n = L->s->n_particles;
    id_index *perm = malloc(n * sizeof *perm);
    if (!perm) return sd_fail(&L->c, L->root, NULL, "out of memory");
    for (size_t i = 0; i < n; i++) perm[i] = (id_index){L->s->id[i], i};
    qsort(perm, n, sizeof *perm, by_id);
    int rc = 0;
    for (size_t i = 1; i < n && rc == 0; i++)
        if (perm[i].id == perm[i - 1].id) {
            char path[SD_PATH_MAX], other[SD_PATH_MAX];
            particle_path(L, perm[i].index, path);
            particle_path(L, perm[i - 1].index, other);
            const yaml_node_t *at = sd_get(&L->c, L->pnode[perm[i].index], "id");
            sd_join(path, path, "id");
            rc = sd_fail(&L->c, at ? at : L->pnode[perm[i].index], path, "duplicate id %lld "
                         "(also %s, line %zu); valid: unique ids > 0", (long long)perm[i].id,
                         other, L->pnode[perm[i - 1].index]->start_mark.line + 1);
        }
    if (rc == 0) rc = permute(L, perm);
    free(perm);
    return rc;
}

/* Cell grid for the overlap check: cells of at least the largest diameter, so touching
 * particles are in the same or adjacent cells; entries sorted by (cell, particle). */
typedef struct cell_entry {
    uint64_t cell;
    size_t index;
} cell_entry;

typedef struct grid {
    double lo[3], h;
    uint64_t dims[3];
    cell_entry *e;
} grid;

static int by_cell(const void *a, const void *b) {
    const cell_entry *x = a, *y = b;
    if (x->cell != y->cell) return x->cell < y->cell ? -1 : 1;
    return x->index < y->index ? -1 : x->index > y->index;
}

static void cell_of(const grid *g, const double x[3], uint64_t c[3]) {
    for (int d = 0; d < 3; d++) {
        double k = floor((x[d] - g->lo[d]) / g->h);
        c[d] = k < 0 ? 0 : (uint64_t)k >= g->dims[d] ? g->dims[d] - 1 : (uint64_t)k;
    }
}

static uint64_t cell_key(const grid *g, const uint64_t c[3]) {
    return (c[2] * g->dims[1] + c[1]) * g->dims[0] + c[0];
}

static int build_grid(const jd_scene *s, grid *g) {
    double hi[3], rmax = 0.0;
    for (int d = 0; d < 3; d++) g->lo[d] = hi[d] = s->position[d];
    for (size_t i = 0; i < s->n_particles; i++) {
        rmax = s->radius[i] > rmax ? s->radius[i] : rmax;
        for (int d = 0; d < 3; d++) {
            g->lo[d] = fmin(g->lo[d], s->position[3 * i + d]);
            hi[d] = fmax(hi[d], s->position[3 * i + d]);
        }
    }
    /* Cap the grid at 2^20 cells per axis so that keys fit in 64 bits. */
    g->h = 2.0 * rmax;
    for (int d = 0; d < 3; d++) g->h = fmax(g->h, (hi[d] - g->lo[d]) / 1048576.0);
    for (int d = 0; d < 3; d++) g->dims[d] = (uint64_t)((hi[d] - g->lo[d]) / g->h) + 1;
    g->e = malloc(s->n_particles * sizeof *g->e);
    if (!g->e) return -1;
    for (size_t i = 0; i < s->n_particles; i++) {
        uint64_t c[3];
        cell_of(g, &s->position[3 * i], c);
        g->e[i] = (cell_entry){cell_key(g, c), i};
    }
    qsort(g->e, s->n_particles, sizeof *g->e, by_cell);
    return 0;
}

static size_t first_in_cell(const grid *g, size_t n, uint64_t key) {
    size_t lo = 0, hi = n;
    while (lo < hi) {
        size_t mid = lo + (hi - lo) / 2;
        if (g->e[mid].cell < key) lo = mid + 1; else hi = mid;
    }
    return lo;
}

static double overlap(const jd_scene *s, size_t i, size_t j) {
    double d[3];
    sub3(&s->position[3 * j], &s->position[3 * i], d);
    return s->radius[i] + s->radius[j] - norm3(d);
}

/* The smallest j > i (in id order) overlapping particle i beyond the tolerance, or 0. */
static size_t overlapping(const jd_scene *s, const grid *g, size_t i, double *by) {
    uint64_t c[3];
    cell_of(g, &s->position[3 * i], c);
    size_t found = 0;
    for (int dz = -1; dz <= 1; dz++)
        for (int dy = -1; dy <= 1; dy++)
            for (int dx = -1; dx <= 1; dx++) {
                const int off[3] = {dx, dy, dz};
                uint64_t nb[3];
                int inside = 1;
                for (int d = 0; d < 3; d++) {
                    nb[d] = c[d] + (uint64_t)(int64_t)off[d];
                    inside &= !(off[d] < 0 && c[d] == 0) && !(off[d] > 0 && nb[d] >= g->dims[d]);
                }
                if (!inside) continue;
                uint64_t key = cell_key(g, nb);
                for (size_t k = first_in_cell(g, s->n_particles, key);
                     k < s->n_particles && g->e[k].cell == key; k++) {
                    size_t j = g->e[k].index;
                    double rmin = fmin(s->radius[i], s->radius[j]);
                    double ov = j > i ? overlap(s, i, j) : 0.0;
                    if (j > i && ov > OVERLAP_TOL * rmin && (!found || j < found)) {
                        found = j;
                        *by = ov;
                    }
                }
            }
    return found;
}

static int check_overlaps(loader *L) {
    const jd_scene *s = L->s;
    grid g;
    if (s->n_particles < 2) return 0;
    if (build_grid(s, &g)) return sd_fail(&L->c, L->root, NULL, "out of memory");
    int rc = 0;
    for (size_t i = 0; i < s->n_particles && rc == 0; i++) {
        double by = 0.0;
        size_t j = overlapping(s, &g, i, &by);
        if (!j) continue;
        char path[SD_PATH_MAX];
        particle_path(L, j, path);
        rc = sd_fail(&L->c, L->pnode[j], path, "particles %lld and %lld overlap by %.3g m at the "
                     "start; valid: an overlap of at most %g of the smaller radius",
                     (long long)s->id[i], (long long)s->id[j], by, OVERLAP_TOL);
    }
    free(g.e);
    return rc;
}

/* ---------------------------------------------------------------------------------------- */
/* Walls                                                                                     */

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
        sd_opt_enum(&L->c, w, path, "side", CYLINDER_SIDES, &wall->inside))
        return -1;
    double d[3];
    sub3(wall->axis[1], wall->axis[0], d);
    double scale = fmax(wall->radius, fmax(norm3(wall->axis[0]), norm3(wall->axis[1])));
    if (!(norm3(d) > GEOM_TOL * scale))
        return sd_fail(&L->c, axis, sub, "the axis has zero length; valid: two distinct end "
                       "points");
    return 0;
}

static int read_wall(loader *L, const yaml_node_t *w, const char *path, size_t index) {
    jd_wall *wall = &L->s->walls[index];
    char sub[SD_PATH_MAX];
    if (sd_mapping(&L->c, w, path, "{name, type, material, ...}")) return -1;
    const yaml_node_t *type = sd_get(&L->c, w, "type"), *name = sd_get(&L->c, w, "name");
    sd_join(sub, path, "type");
    if (!type) return sd_missing(&L->c, w, path, "type", "plane, cylinder");
    if (sd_enum(&L->c, type, sub, WALL_TYPES, &wall->type)) return -1;
    const int plane = wall->type == JD_WALL_PLANE;
    if (sd_keys(&L->c, w, path, plane ? PLANE_KEYS : CYLINDER_KEYS)) return -1;
    sd_join(sub, path, "name");
    if (!name) return sd_missing(&L->c, w, path, "name", "a unique name");
    if (sd_str(&L->c, name, sub, wall->name, sizeof wall->name)) return -1;
    for (size_t k = 0; k < index; k++)
        if (strcmp(L->s->walls[k].name, wall->name) == 0)
            return sd_fail(&L->c, name, sub, "duplicate wall name '%s' (also walls.%zu); valid: "
                           "unique names", wall->name, k);
    if (req_material(L, w, path, &wall->material) ||
        sd_opt_vec3(&L->c, w, path, "velocity", wall->velocity))
        return -1;
    L->by_wall[wall->material] = 1;
    if (!plane) return read_cylinder(L, w, path, wall);
    sd_join(sub, path, "corners");
    const yaml_node_t *corners = sd_get(&L->c, w, "corners");
    if (!corners) return sd_missing(&L->c, w, path, "corners", "four points [[x, y, z], ...]");
    if (sd_points(&L->c, corners, sub, 4, &wall->corners[0][0])) return -1;
    return check_plane(L, w, path, wall);
}

static int read_walls(loader *L) {
    const yaml_node_t *list = sd_get(&L->c, L->root, "walls");
    if (!list) return 0;
    if (sd_sequence(&L->c, list, "walls", "a list of {name, type, material, ...}")) return -1;
    L->s->walls = calloc(sd_len(list) ? sd_len(list) : 1, sizeof *L->s->walls);
    if (!L->s->walls) return sd_fail(&L->c, list, "walls", "out of memory");
    L->s->n_walls = sd_len(list);
    for (size_t i = 0; i < sd_len(list); i++) {
        char path[SD_PATH_MAX];
        sd_join_index(path, "walls", i);
        if (read_wall(L, sd_item(&L->c, list, i), path, i)) return -1;
    }
    return 0;
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

/* Height of the initial bounding box (centres +- radius) along gravity. */
static double fall_height(const jd_scene *s, const double ghat[3]) {
    double lo = INFINITY, hi = -INFINITY;
    for (size_t i = 0; i < s->n_particles; i++) {
        double h = jd_dot(&s->position[3 * i], ghat);
        lo = fmin(lo, h - s->radius[i]);
        hi = fmax(hi, h + s->radius[i]);
    }
    return hi - lo;
}

static int default_impact_speed(loader *L) {
    jd_scene *s = L->s;
    vel *u = malloc(s->n_particles * sizeof *u);
    if (!u) return sd_fail(&L->c, L->root, NULL, "out of memory");
    double v = max_relative_speed(s, u);
    free(u);
    for (size_t i = 0; i < s->n_particles; i++)
        for (size_t w = 0; w < s->n_walls; w++) {
            double d[3];
            sub3(&s->velocity[3 * i], s->walls[w].velocity, d);
            v = fmax(v, norm3(d));
        }
    if (s->n_particles == 1 && s->n_walls == 0) v = norm3(s->velocity);
    double g = norm3(s->gravity);
    if (g > 0.0) {
        const double ghat[3] = {s->gravity[0] / g, s->gravity[1] / g, s->gravity[2] / g};
        v += sqrt(2.0 * g * fall_height(s, ghat));
    }
    s->max_impact_speed = v;
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
        read_model(L) || read_materials(L) || read_particles(L) || read_generators(L) ||
        read_walls(L))
        return -1;
    if (s->n_particles == 0) {
        const yaml_node_t *p = sd_get(&L->c, L->root, "particles");
        return sd_fail(&L->c, p ? p : L->root, "particles", "no particles; valid: at least one "
                       "particle in particles or generate");
    }
    if (read_interactions(L) || sort_particles(L) || check_overlaps(L)) return -1;
    return L->max_impact_given ? 0 : default_impact_speed(L);
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
    return sd_fail(c, sweep ? sweep : root, sweep ? "sweep" : NULL, "no case '%s'; valid: %s",
                   case_name, valid);
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
    if (open_cases(&c, path, &doc, name, case_name, names, &n)) return -1;
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
    if (open_cases(&L.c, path, &doc, scene->name, scene->case_name, &names, &n)) return -1;
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
    sd_free_names(names, n);
    yaml_document_delete(&doc);
    if (rc) scene_free(scene);
    return rc ? -1 : 0;
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
    free(scene->walls);
    memset(scene, 0, sizeof *scene);
}
