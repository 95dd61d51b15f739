/*
 * scene_bonds.c — the bond sections of a scene (docs/scenes.md "Bonds"): bond_types, explicit
 * bonds, bond_rules, and their resolution once the particles are sorted by id (every id exists,
 * rules at step 0 become explicit bonds, no pair is bonded twice, bonds sorted by ids).
 */
#include <stdlib.h>
#include <string.h>

#include "scene_internal.h"

static const char *const TYPE_KEYS[] = {"normal_stiffness", "shear_stiffness", "tensile_strength",
                                        "shear_strength", "radius_multiplier", "damping",
                                        "bending", NULL};
static const char *const BOND_KEYS[] = {"ids", "type", NULL};
static const char *const RULE_KEYS[] = {"type", "time", "step", "materials", "id_range",
                                        "max_gap", NULL};
/* Indexed by jd_bond_bending. */
static const char *const BENDINGS[] = {"potyondy_cundall", "jiang2021_literal", NULL};
_Static_assert(JD_BOND_BEND_I == 0 && JD_BOND_BEND_J_LITERAL == 1, "BENDINGS order");

#define DEFAULT_MAX_GAP 1e-9

/* ---------------------------------------------------------------------------------------- */
/* bond_types                                                                                */

/* A strength: a number > 0, or .inf (that failure mode is off). */
static int read_strength(loader *L, const yaml_node_t *m, const char *path, const char *key,
                         double *out) {
    if (!sd_get(&L->c, m, key)) return sd_missing(&L->c, m, path, key, "a number > 0 [Pa], or .inf");
    return sd_opt_num_or_inf(&L->c, m, path, key, SD_POSITIVE, "a strength",
                             "a number > 0 [Pa], or .inf", out);
}

static int read_type(loader *L, const yaml_node_pair_t *p, jd_bond_type *t) {
    const yaml_node_t *key = sd_node(&L->c, p->key);
    const char *name = sd_scalar(key);
    const yaml_node_t *m = sd_node(&L->c, p->value);
    if (sd_check_name(&L->c, key, "bond_types", name, key->data.scalar.length, JD_NAME_MAX))
        return -1;
    char path[SD_PATH_MAX];
    sd_join(path, "bond_types", name);
    snprintf(t->name, sizeof t->name, "%s", name);
    t->p = (jd_bond_params){.lambda = 1.0, .gamma = 0.0, .bending = JD_BOND_BEND_I};
    return sd_keys(&L->c, m, path, TYPE_KEYS) ||
                   sd_req_num(&L->c, m, path, "normal_stiffness", SD_NONNEGATIVE, &t->p.kn) ||
                   sd_req_num(&L->c, m, path, "shear_stiffness", SD_NONNEGATIVE, &t->p.kt) ||
                   read_strength(L, m, path, "tensile_strength", &t->p.sigma_c) ||
                   read_strength(L, m, path, "shear_strength", &t->p.tau_c) ||
                   sd_opt_num(&L->c, m, path, "radius_multiplier", SD_POSITIVE, &t->p.lambda) ||
                   sd_opt_num(&L->c, m, path, "damping", SD_NONNEGATIVE, &t->p.gamma) ||
                   sd_opt_enum(&L->c, m, path, "bending", BENDINGS, &t->p.bending)
               ? -1
               : 0;
}

int scene_read_bond_types(loader *L) {
    jd_scene *s = L->s;
    const yaml_node_t *m = sd_get(&L->c, L->root, "bond_types");
    if (!m) return 0;
    if (sd_keys(&L->c, m, "bond_types", NULL)) return -1;
    size_t n = (size_t)(m->data.mapping.pairs.top - m->data.mapping.pairs.start);
    s->bond_types = calloc(n ? n : 1, sizeof *s->bond_types);
    if (!s->bond_types) return sd_no_memory(&L->c, m, "bond_types");
    s->n_bond_types = n;
    for (size_t i = 0; i < n; i++)
        if (read_type(L, &m->data.mapping.pairs.start[i], &s->bond_types[i])) return -1;
    return 0;
}

int scene_req_bond_type(loader *L, const yaml_node_t *map, const char *path, const char *key,
                        int *out) {
    const yaml_node_t *n = sd_get(&L->c, map, key);
    char sub[SD_PATH_MAX], name[JD_NAME_MAX], valid[512] = "";
    size_t used = 0;
    for (size_t i = 0; i < L->s->n_bond_types && used < sizeof valid; i++) {
        int k = snprintf(valid + used, sizeof valid - used, "%s%s", i ? ", " : "",
                         L->s->bond_types[i].name);
        used += k > 0 ? (size_t)k : 0;
    }
    if (!L->s->n_bond_types) snprintf(valid, sizeof valid, "a name defined under bond_types");
    if (!n) return sd_missing(&L->c, map, path, key, valid);
    sd_join(sub, path, key);
    if (sd_name(&L->c, n, sub, name, sizeof name)) return -1;
    for (size_t i = 0; i < L->s->n_bond_types; i++)
        if (strcmp(L->s->bond_types[i].name, name) == 0) {
            *out = (int)i;
            return 0;
        }
    return sd_fail(&L->c, n, sub, "unknown bond type '%s'; valid: %s", name, valid);
}

/* ---------------------------------------------------------------------------------------- */
/* Bonds and rules                                                                           */

int scene_add_bond(loader *L, const yaml_node_t *node, int64_t a, int64_t b, int type) {
    jd_scene *s = L->s;
    if (s->n_bonds == L->bond_cap) {
        size_t cap = L->bond_cap ? 2 * L->bond_cap : 64;
        int64_t *ids = realloc(s->bond_ids, 2 * cap * sizeof *ids);
        if (ids) s->bond_ids = ids;
        int32_t *ty = realloc(s->bond_type, cap * sizeof *ty);
        if (ty) s->bond_type = ty;
        const yaml_node_t **bn = realloc(L->bnode, cap * sizeof *bn);
        if (bn) L->bnode = bn;
        if (!ids || !ty || !bn) return sd_no_memory(&L->c, node, "bonds");
        L->bond_cap = cap;
    }
    const size_t k = s->n_bonds++;
    s->bond_ids[2 * k] = a < b ? a : b;
    s->bond_ids[2 * k + 1] = a < b ? b : a;
    s->bond_type[k] = type;
    L->bnode[k] = node;
    return 0;
}

static int read_bond(loader *L, const yaml_node_t *b, const char *path) {
    char sub[SD_PATH_MAX], item[SD_PATH_MAX];
    int type;
    if (sd_keys(&L->c, b, path, BOND_KEYS) || scene_req_bond_type(L, b, path, "type", &type))
        return -1;
    const yaml_node_t *ids = sd_get(&L->c, b, "ids");
    sd_join(sub, path, "ids");
    if (!ids) return sd_missing(&L->c, b, path, "ids", "[id, id]: two particle ids");
    if (ids->type != YAML_SEQUENCE_NODE || sd_len(ids) != 2)
        return sd_fail(&L->c, ids, sub, "expected two ids, got %s; valid: [id, id]",
                       sd_kind(ids));
    int64_t id[2];
    for (size_t d = 0; d < 2; d++) {
        sd_join_index(item, sub, d);
        if (sd_int(&L->c, sd_item(&L->c, ids, d), item, 1, &id[d])) return -1;
    }
    if (id[0] == id[1])
        return sd_fail(&L->c, ids, sub, "a particle bonded to itself (%lld); valid: two "
                       "different ids", (long long)id[0]);
    return scene_add_bond(L, b, id[0], id[1], type);
}

/* A rule's time [s] -> step ceil(time/dt - 1e-9) (as end_time). */
int scene_time_to_step(loader *L, const yaml_node_t *at, const char *path, double time,
                       int64_t *step) {
    const double steps = ceil(time / L->s->dt - 1e-9);
    if (!(steps < 9.0e18))
        return sd_fail(&L->c, at, path, "time/dt gives %g steps (dt = %g s); valid: at most 9e18",
                       steps, L->s->dt);
    *step = steps > 0.0 ? (int64_t)steps : 0;
    return 0;
}

/* The rule's group: materials (default all) and id_range (default: the whole id range, set
 * after the sort in scene_resolve_bonds when absent: marked by id_range[0] > id_range[1]). */
static int read_rule(loader *L, const yaml_node_t *r, const char *path, jd_bond_rule *rule) {
    jd_scene *s = L->s;
    char sub[SD_PATH_MAX], item[SD_PATH_MAX];
    rule->max_gap = DEFAULT_MAX_GAP;
    rule->time = NAN;
    rule->id_range[0] = 1;
    rule->id_range[1] = 0;
    rule->materials = calloc(s->n_materials, 1);
    if (!rule->materials) return sd_no_memory(&L->c, r, path);
    if (sd_keys(&L->c, r, path, RULE_KEYS) || scene_req_bond_type(L, r, path, "type", &rule->type) ||
        sd_opt_num(&L->c, r, path, "max_gap", SD_NONNEGATIVE, &rule->max_gap))
        return -1;
    /* time [s] -> step ceil(time/dt - 1e-9) (as end_time); the resolved form gives step */
    const yaml_node_t *t = sd_get(&L->c, r, "time"), *st = sd_get(&L->c, r, "step");
    if (t && st)
        return sd_fail(&L->c, st, path, "time and step given together; valid: one of them");
    if (!t && !st) return sd_missing(&L->c, r, path, "time", "a time >= 0 [s] (or step >= 0)");
    if (st) {
        sd_join(sub, path, "step");
        if (sd_int(&L->c, st, sub, 0, &rule->step)) return -1;
    } else {
        sd_join(sub, path, "time");
        if (sd_num(&L->c, t, sub, SD_NONNEGATIVE, &rule->time)) return -1;
        /* an auto dt is known only once the whole scene is (scene_bond_rule_steps); a later
         * rule stays a later rule meanwhile */
        if (s->dt_auto) rule->step = rule->time > 0.0;
        else if (scene_time_to_step(L, t, sub, rule->time, &rule->step)) return -1;
    }
    const yaml_node_t *m = sd_get(&L->c, r, "materials");
    if (!m) {
        memset(rule->materials, 1, s->n_materials);
    } else {
        sd_join(sub, path, "materials");
        if (sd_sequence(&L->c, m, sub, "a list of material names")) return -1;
        if (sd_len(m) == 0)
            return sd_fail(&L->c, m, sub, "empty; valid: at least one material (or omit it)");
        for (size_t k = 0; k < sd_len(m); k++) {
            sd_join_index(item, sub, k);
            int mat = scene_material_ref(L, sd_item(&L->c, m, k), item);
            if (mat < 0) return -1;
            rule->materials[mat] = 1;
        }
    }
    const yaml_node_t *ir = sd_get(&L->c, r, "id_range");
    if (ir) {
        sd_join(sub, path, "id_range");
        if (ir->type != YAML_SEQUENCE_NODE || sd_len(ir) != 2)
            return sd_fail(&L->c, ir, sub, "expected two ids, got %s; valid: [first, last]",
                           sd_kind(ir));
        for (size_t d = 0; d < 2; d++) {
            sd_join_index(item, sub, d);
            if (sd_int(&L->c, sd_item(&L->c, ir, d), item, 1, &rule->id_range[d])) return -1;
        }
        if (rule->id_range[0] > rule->id_range[1])
            return sd_fail(&L->c, ir, sub, "first %lld > last %lld; valid: first <= last",
                           (long long)rule->id_range[0], (long long)rule->id_range[1]);
    }
    return 0;
}

int scene_read_bonds(loader *L) {
    jd_scene *s = L->s;
    const yaml_node_t *list = sd_get(&L->c, L->root, "bonds");
    char path[SD_PATH_MAX];
    if (list) {
        if (sd_sequence(&L->c, list, "bonds", "a list of {ids: [id, id], type: NAME}")) return -1;
        for (size_t k = 0; k < sd_len(list); k++) {
            sd_join_index(path, "bonds", k);
            if (read_bond(L, sd_item(&L->c, list, k), path)) return -1;
        }
    }
    const yaml_node_t *rules = sd_get(&L->c, L->root, "bond_rules");
    if (!rules) return 0;
    if (sd_sequence(&L->c, rules, "bond_rules", "a list of {type, time, materials, id_range, "
                    "max_gap}"))
        return -1;
    const size_t n = sd_len(rules);
    s->bond_rules = calloc(n ? n : 1, sizeof *s->bond_rules);
    if (!s->bond_rules) return sd_no_memory(&L->c, rules, "bond_rules");
    for (size_t k = 0; k < n; k++) {
        sd_join_index(path, "bond_rules", k);
        s->n_bond_rules = k + 1; /* so that scene_free frees its material flags */
        if (read_rule(L, sd_item(&L->c, rules, k), path, &s->bond_rules[k])) return -1;
    }
    return 0;
}

/* ---------------------------------------------------------------------------------------- */
/* Resolution after the sort by id                                                           */

static long index_of_id(const jd_scene *s, int64_t id) {
    size_t lo = 0, hi = s->n_particles;
    while (lo < hi) {
        size_t mid = lo + (hi - lo) / 2;
        if (s->id[mid] < id) lo = mid + 1; else hi = mid;
    }
    return lo < s->n_particles && s->id[lo] == id ? (long)lo : -1;
}

/* Sort permutation of the bonds by (id[0], id[1]), then by input order. */
static const jd_scene *sort_scene;
static int by_ids(const void *a, const void *b) {
    const size_t x = *(const size_t *)a, y = *(const size_t *)b;
    const int64_t *p = &sort_scene->bond_ids[2 * x], *q = &sort_scene->bond_ids[2 * y];
    if (p[0] != q[0]) return p[0] < q[0] ? -1 : 1;
    if (p[1] != q[1]) return p[1] < q[1] ? -1 : 1;
    return x < y ? -1 : x > y;
}

/* Whether a bond was made by a bond rule (its node is an item of bond_rules). */
static int is_rule_node(loader *L, const yaml_node_t *node) {
    const yaml_node_t *rules = sd_get(&L->c, L->root, "bond_rules");
    for (size_t r = 0; rules && r < sd_len(rules); r++)
        if (sd_item(&L->c, rules, r) == node) return 1;
    return 0;
}

static int sort_bonds(loader *L) {
    jd_scene *s = L->s;
    const size_t n = s->n_bonds;
    size_t *perm = malloc((n ? n : 1) * sizeof *perm);
    int64_t *ids = malloc((n ? 2 * n : 1) * sizeof *ids);
    int32_t *ty = malloc((n ? n : 1) * sizeof *ty);
    const yaml_node_t **bn = malloc((n ? n : 1) * sizeof *bn);
    int rc = 0;
    if (!perm || !ids || !ty || !bn) {
        rc = sd_no_memory(&L->c, L->root, "bonds");
        goto done;
    }
    for (size_t k = 0; k < n; k++) perm[k] = k;
    sort_scene = s;
    qsort(perm, n, sizeof *perm, by_ids);
    for (size_t k = 0; k < n; k++) {
        ids[2 * k] = s->bond_ids[2 * perm[k]];
        ids[2 * k + 1] = s->bond_ids[2 * perm[k] + 1];
        ty[k] = s->bond_type[perm[k]];
        bn[k] = L->bnode[perm[k]];
    }
    /* A pair bonded twice by bonds or generators is an error; a step-0 rule, like a rule during
     * the run, leaves a pair that is already bonded as it is (the earlier bond is kept). */
    size_t kept = 0;
    for (size_t k = 0; k < n && rc == 0; k++) {
        const int dup = kept > 0 && ids[2 * k] == ids[2 * kept - 2] &&
                        ids[2 * k + 1] == ids[2 * kept - 1];
        if (dup && is_rule_node(L, bn[k])) continue;
        if (dup)
            rc = sd_fail(&L->c, bn[k], "bonds", "particles %lld and %lld are bonded twice (also "
                         "by the entry at line %zu); valid: at most one bond per pair",
                         (long long)ids[2 * k], (long long)ids[2 * k + 1],
                         bn[kept - 1]->start_mark.line + 1);
        ids[2 * kept] = ids[2 * k];
        ids[2 * kept + 1] = ids[2 * k + 1];
        ty[kept] = ty[k];
        bn[kept++] = bn[k];
    }
    if (rc == 0 && kept > 0) {
        s->n_bonds = kept;
        memcpy(s->bond_ids, ids, 2 * kept * sizeof *ids);
        memcpy(s->bond_type, ty, kept * sizeof *ty);
        memcpy(L->bnode, bn, kept * sizeof *bn);
    }
done:
    free(perm);
    free(ids);
    free(ty);
    free(bn);
    return rc;
}

/* By step; rules of one step keep their order (insertion sort is stable; lists are short). */
static void sort_rules(jd_scene *s) {
    for (size_t i = 1; i < s->n_bond_rules; i++)
        for (size_t j = i; j > 0 && s->bond_rules[j - 1].step > s->bond_rules[j].step; j--) {
            const jd_bond_rule t = s->bond_rules[j];
            s->bond_rules[j] = s->bond_rules[j - 1];
            s->bond_rules[j - 1] = t;
        }
}

int scene_resolve_bonds(loader *L) {
    jd_scene *s = L->s;
    for (size_t k = 0; k < s->n_bonds; k++)
        for (int d = 0; d < 2; d++)
            if (index_of_id(s, s->bond_ids[2 * k + d]) < 0)
                return sd_fail(&L->c, L->bnode[k], "bonds", "no particle with id %lld; valid: "
                               "ids of the scene's particles (%lld to %lld)",
                               (long long)s->bond_ids[2 * k + d], (long long)s->id[0],
                               (long long)s->id[s->n_particles - 1]);
    /* explicit default id ranges; rules at step 0 become bonds on the initial positions */
    size_t kept = 0;
    for (size_t r = 0; r < s->n_bond_rules; r++) {
        jd_bond_rule *rule = &s->bond_rules[r];
        if (rule->id_range[0] > rule->id_range[1]) {
            rule->id_range[0] = s->id[0];
            rule->id_range[1] = s->id[s->n_particles - 1];
        }
        if (rule->step > 0) {
            s->bond_rules[kept++] = *rule;
            continue;
        }
        int32_t *pairs = NULL;
        const long np = jd_bond_rule_pairs(s, rule, s->position, &pairs);
        if (np < 0) return sd_no_memory(&L->c, L->root, "bond_rules");
        char path[SD_PATH_MAX];
        sd_join_index(path, "bond_rules", r);
        const yaml_node_t *node = sd_item(&L->c, sd_get(&L->c, L->root, "bond_rules"), r);
        int rc = 0;
        for (long p = 0; p < np && rc == 0; p++)
            rc = scene_add_bond(L, node, s->id[pairs[2 * p]], s->id[pairs[2 * p + 1]], rule->type);
        free(pairs);
        free(rule->materials);
        if (rc) {
            for (size_t q = r + 1; q < s->n_bond_rules; q++) free(s->bond_rules[q].materials);
            s->n_bond_rules = kept; /* the rules already moved stay owned by the scene */
            return -1;
        }
    }
    s->n_bond_rules = kept;
    sort_rules(s);
    return sort_bonds(L);
}

int scene_bond_rule_steps(loader *L) {
    jd_scene *s = L->s;
    for (size_t r = 0; r < s->n_bond_rules; r++)
        if (!isnan(s->bond_rules[r].time) &&
            scene_time_to_step(L, sd_get(&L->c, L->root, "bond_rules"), "bond_rules",
                         s->bond_rules[r].time, &s->bond_rules[r].step))
            return -1;
    sort_rules(s);
    return 0;
}
