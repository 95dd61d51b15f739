/*
 * scene_materials.c — the materials section, references to materials by name, and the
 * interactions section (docs/scenes.md).
 *
 * Resolution rule that docs/scenes.md leaves to the implementation: an unlike pair without an
 * interactions entry takes the common value of a coefficient when both materials agree.  When
 * they differ, the pair is an error only if it can meet (one material is used by particles, the
 * other by particles or walls); a pair that never meets gets the smaller value, which is never
 * used but keeps the emitted matrix explicit.
 */
#include <stdlib.h>
#include <string.h>

#include "scene_internal.h"

static const char *const MATERIAL_KEYS[] = {"youngs_modulus",      "poisson_ratio",
                                            "density",             "restitution",
                                            "friction",            "rolling_friction",
                                            "loading_stiffness",   "unloading_stiffness",
                                            "cohesive_stiffness",  NULL};
static const char *const INTERACTION_KEYS[] = {"materials", "restitution", "friction",
                                               "rolling_friction", NULL};

static const sd_range RESTITUTION = {0.0, 1.0, 1, 0};
static const sd_range POISSON = {-1.0, 0.5, 1, 0}; /* 0.5: incompressible (rubber) */

/* ---------------------------------------------------------------------------------------- */
/* References by name                                                                        */

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
    if (sd_name(&L->c, n, path, name, sizeof name)) return -1;
    for (size_t i = 0; i < L->s->n_materials; i++)
        if (strcmp(L->s->materials[i].name, name) == 0) return (int)i;
    char valid[512];
    material_names(L->s, valid, sizeof valid);
    return sd_fail(&L->c, n, path, "unknown material '%s'; valid: %s", name, valid);
}

int scene_material_ref(loader *L, const yaml_node_t *n, const char *path) {
    return material_ref(L, n, path);
}

int scene_req_material(loader *L, const yaml_node_t *map, const char *path, int *out) {
    const yaml_node_t *n = sd_get(&L->c, map, "material");
    char sub[SD_PATH_MAX], valid[512];
    if (!n) {
        material_names(L->s, valid, sizeof valid);
        return sd_missing(&L->c, map, path, "material", valid);
    }
    sd_join(sub, path, "material");
    return (*out = material_ref(L, n, sub)) < 0 ? -1 : 0;
}

/* ---------------------------------------------------------------------------------------- */
/* Materials                                                                                 */

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
            snprintf(valid, sizeof valid, "%s (%s)", k == 1 ? "a number in (-1, 0.5]"
                                                            : "a number > 0", together);
            return sd_missing(&L->c, m, path, keys[k], valid);
        }
    return sd_req_num(&L->c, m, path, "youngs_modulus", SD_POSITIVE, &mat->youngs_modulus) ||
                   sd_req_num(&L->c, m, path, "poisson_ratio", POISSON, &mat->poisson_ratio) ||
                   sd_req_num(&L->c, m, path, "density", SD_POSITIVE, &mat->density)
               ? -1
               : 0;
}

/* MEPA's stiffnesses (model.normal_law mepa, read before the materials): loading and unloading
 * together, unloading above loading, cohesive optional (default 0). */
static int read_mepa(loader *L, const yaml_node_t *m, const char *path, jd_material *mat) {
    static const char *const keys[] = {"loading_stiffness", "unloading_stiffness",
                                       "cohesive_stiffness"};
    const yaml_node_t *first = NULL;
    for (int k = 0; k < 3 && !first; k++) first = sd_get(&L->c, m, keys[k]);
    mat->has_mepa = first != NULL;
    if (!first) return 0;
    char sub[SD_PATH_MAX];
    if (L->s->normal_law != JD_NORMAL_MEPA) {
        for (int k = 0; k < 3; k++)
            if (sd_get(&L->c, m, keys[k]) == first) sd_join(sub, path, keys[k]);
        return sd_fail(&L->c, first, sub, "MEPA's stiffness without MEPA's law; valid: "
                       "model.normal_law: mepa, or no loading/unloading/cohesive_stiffness");
    }
    if (!sd_get(&L->c, m, "loading_stiffness") || !sd_get(&L->c, m, "unloading_stiffness"))
        return sd_missing(&L->c, m, path, sd_get(&L->c, m, "loading_stiffness")
                                              ? "unloading_stiffness" : "loading_stiffness",
                          "a number > 0 [N/m^n] (loading_stiffness and unloading_stiffness go "
                          "together, unloading above loading)");
    if (sd_req_num(&L->c, m, path, "loading_stiffness", SD_POSITIVE, &mat->loading_stiffness) ||
        sd_req_num(&L->c, m, path, "unloading_stiffness", SD_POSITIVE,
                   &mat->unloading_stiffness) ||
        sd_opt_num(&L->c, m, path, "cohesive_stiffness", SD_NONNEGATIVE,
                   &mat->cohesive_stiffness))
        return -1;
    if (!jd_mepa_material_valid(mat->loading_stiffness, mat->unloading_stiffness,
                                mat->cohesive_stiffness)) { /* k1 > 0, kadh >= 0 held above */
        sd_join(sub, path, "unloading_stiffness");
        return sd_fail(&L->c, sd_get(&L->c, m, "unloading_stiffness"), sub,
                       "%g is not above loading_stiffness %g; valid: k2 > k1 (MEPA's virgin "
                       "branch ends where the two meet; k1 = k2 divides by zero)",
                       mat->unloading_stiffness, mat->loading_stiffness);
    }
    return 0;
}

static int read_material(loader *L, const yaml_node_pair_t *p, jd_material *mat) {
    const yaml_node_t *key = sd_node(&L->c, p->key);
    const char *name = sd_scalar(key);
    const yaml_node_t *m = sd_node(&L->c, p->value);
    if (sd_check_name(&L->c, key, "materials", name, key->data.scalar.length, JD_NAME_MAX))
        return -1;
    char path[SD_PATH_MAX];
    sd_join(path, "materials", name);
    snprintf(mat->name, sizeof mat->name, "%s", name);
    mat->restitution = 1.0;
    if (sd_keys(&L->c, m, path, MATERIAL_KEYS) || read_elastic(L, m, path, mat) ||
        read_mepa(L, m, path, mat))
        return -1;
    return sd_opt_num(&L->c, m, path, "restitution", RESTITUTION, &mat->restitution) ||
                   sd_opt_num(&L->c, m, path, "friction", SD_NONNEGATIVE, &mat->friction) ||
                   sd_opt_num(&L->c, m, path, "rolling_friction", SD_NONNEGATIVE,
                              &mat->rolling_friction)
               ? -1
               : 0;
}

int scene_read_materials(loader *L) {
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
        return sd_no_memory(&L->c, m, "materials");
    s->n_materials = n;
    for (size_t i = 0; i < n; i++)
        if (read_material(L, &m->data.mapping.pairs.start[i], &s->materials[i])) return -1;
    return 0;
}

/* ---------------------------------------------------------------------------------------- */
/* Interactions                                                                              */

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

/* With MEPA's law every material that meets another needs its stiffnesses. */
static int check_mepa(loader *L) {
    const jd_scene *s = L->s;
    for (size_t a = 0; s->normal_law == JD_NORMAL_MEPA && a < s->n_materials; a++) {
        if (s->materials[a].has_mepa || !(L->by_particle[a] || L->by_wall[a])) continue;
        char path[SD_PATH_MAX];
        sd_join(path, "materials", s->materials[a].name);
        const yaml_node_t *m = sd_get(&L->c, sd_get(&L->c, L->root, "materials"),
                                      s->materials[a].name);
        return sd_missing(&L->c, m, path, "loading_stiffness",
                          "a number > 0 [N/m^n] for every material with model.normal_law: mepa "
                          "(with unloading_stiffness, and optionally cohesive_stiffness)");
    }
    return 0;
}

int scene_read_interactions(loader *L) {
    jd_scene *s = L->s;
    size_t n = s->n_materials;
    unsigned char *given = calloc(n * n, N_COEF);
    const yaml_node_t **first = calloc(n * n, sizeof *first);
    const yaml_node_t *list = sd_get(&L->c, L->root, "interactions");
    int rc = (!given || !first) ? sd_no_memory(&L->c, list, "interactions") : 0;
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
    return rc || check_mepa(L);
}
