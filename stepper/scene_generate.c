/*
 * scene_generate.c — the generate section: lattice generators and their seeded PRNG (the bonded
 * generators are in scene_bond_generators.c).
 */
#include <stdlib.h>

#include "scene_internal.h"

static const char *const GENERATOR_KEYS[] = {"lattice", "bonded_block", "bonded_sphere", NULL};
static const char *const LATTICE_ONLY_KEYS[] = {"lattice", NULL};
static const char *const LATTICE_KEYS[] = {"material", "radius", "radii", "origin", "spacing",
                                           "counts", "jitter", "velocity", "seed", NULL};
static const char *const RADII_KEYS[] = {"values", "fractions", NULL};

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
    if (sd_keys(&L->c, lat, path, LATTICE_KEYS) || scene_req_material(L, lat, path, &g->material) ||
        read_radii(L, lat, path, g) || sd_req_vec3(&L->c, lat, path, "origin", g->origin) ||
        sd_req_num(&L->c, lat, path, "spacing", SD_POSITIVE, &g->spacing) ||
        read_counts(L, lat, path, g) ||
        sd_opt_num(&L->c, lat, path, "jitter", UNIT, &g->jitter) ||
        sd_opt_vec3(&L->c, lat, path, "velocity", g->velocity) ||
        scene_opt_int(L, lat, path, "seed", 0, &g->seed))
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
    if (!which) return sd_no_memory(&L->c, lat, NULL);
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
        long i = scene_add_particle(L, lat, -(gen + 1));
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

int scene_generate_lattice(loader *L, const yaml_node_t *lat, const char *path, int32_t gen,
                           int64_t counts[3], int64_t *next_id) {
    lattice g = {0};
    if (read_lattice(L, lat, path, &g) || generate_lattice(L, lat, gen, &g, next_id)) return -1;
    for (int d = 0; d < 3; d++) counts[d] = g.counts[d];
    return 0;
}

int scene_generate_list(loader *L, const yaml_node_t *list, const char *prefix,
                        int lattice_only, int64_t *next_id) {
    if (sd_sequence(&L->c, list, prefix,
                    lattice_only ? "a list of {lattice: {...}}"
                                 : "a list of {lattice: {...}}, {bonded_block: {...}}, "
                                   "{bonded_sphere: {...}}"))
        return -1;
    for (size_t k = 0; k < sd_len(list); k++) {
        char path[SD_PATH_MAX], sub[SD_PATH_MAX];
        sd_join_index(path, prefix, k);
        const yaml_node_t *e = sd_item(&L->c, list, k);
        if (sd_keys(&L->c, e, path, lattice_only ? LATTICE_ONLY_KEYS : GENERATOR_KEYS)) return -1;
        if (e->data.mapping.pairs.top - e->data.mapping.pairs.start > 1)
            return sd_fail(&L->c, e, path, "more than one generator in one entry; valid: one of "
                           "lattice, bonded_block, bonded_sphere per list item");
        const yaml_node_t *lat = sd_get(&L->c, e, "lattice");
        if (!lat) {
            const char *key = sd_get(&L->c, e, "bonded_block") ? "bonded_block" : "bonded_sphere";
            const yaml_node_t *b = sd_get(&L->c, e, key);
            if (!b)
                return sd_missing(&L->c, e, path, "lattice", "one of lattice, bonded_block, "
                                  "bonded_sphere");
            sd_join(sub, path, key);
            if (scene_generate_bonded(L, b, key, sub, (int32_t)k, next_id)) return -1;
            continue;
        }
        sd_join(sub, path, "lattice");
        lattice g = {0};
        if (read_lattice(L, lat, sub, &g) || generate_lattice(L, lat, (int32_t)k, &g, next_id))
            return -1;
    }
    return 0;
}

int scene_read_generators(loader *L) {
    const yaml_node_t *list = sd_get(&L->c, L->root, "generate");
    if (!list) return 0;
    int64_t next_id = 1;
    for (size_t i = 0; i < L->s->n_particles; i++)
        next_id = L->s->id[i] >= next_id ? L->s->id[i] + 1 : next_id;
    return scene_generate_list(L, list, "generate", 0, &next_id);
}
