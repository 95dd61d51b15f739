/*
 * scene_bond_generators.c — aggregates of touching, bonded spheres (docs/scenes.md):
 *   bonded_block   Jiang (2021) Ch. 5: n x m x k spheres on a simple-cubic lattice of spacing
 *                  2 R, every face neighbour bonded;
 *   bonded_sphere  Zhang et al. (2021): a face-centred-cubic cluster of spheres of radius r
 *                  (nearest neighbours 2 r apart) filling a sphere of diameter D, every nearest
 *                  neighbour pair bonded.
 * Both are built on integer lattice coordinates, so which spheres touch is decided exactly,
 * never by comparing rounded distances.
 */
#include <stdlib.h>
#include <string.h>

#include "scene_internal.h"

static const char *const BLOCK_KEYS[] = {"material", "radius", "origin", "counts", "bond_type",
                                         "velocity", NULL};
static const char *const SPHERE_KEYS[] = {"material", "radius", "centre", "diameter",
                                          "bond_type", "velocity", NULL};

#define MAX_SPHERE_CELLS 200000000.0 /* (2 n + 1)^3 lattice-index table of bonded_sphere */

typedef struct bonded {
    int material, type;
    double radius, velocity[3];
} bonded;

static int read_common(loader *L, const yaml_node_t *g, const char *path, bonded *b) {
    char sub[SD_PATH_MAX];
    if (scene_req_material(L, g, path, &b->material) ||
        sd_req_num(&L->c, g, path, "radius", SD_POSITIVE, &b->radius) ||
        scene_req_bond_type(L, g, path, "bond_type", &b->type) ||
        sd_opt_vec3(&L->c, g, path, "velocity", b->velocity))
        return -1;
    if (!L->s->materials[b->material].has_elastic) {
        sd_join(sub, path, "material");
        return sd_fail(&L->c, sd_get(&L->c, g, "material"), sub, "material '%s' has no "
                       "youngs_modulus, poisson_ratio and density; valid: a material with "
                       "elastic properties", L->s->materials[b->material].name);
    }
    L->by_particle[b->material] = 1;
    return 0;
}

static long add_sphere(loader *L, const yaml_node_t *g, int32_t gen, const bonded *b,
                       const double x[3], int64_t *next_id) {
    jd_scene *s = L->s;
    long i = scene_add_particle(L, g, -(gen + 1));
    if (i < 0) return -1;
    s->id[i] = (*next_id)++;
    s->material[i] = b->material;
    s->radius[i] = b->radius;
    for (int d = 0; d < 3; d++) {
        s->position[3 * i + d] = x[d];
        s->velocity[3 * i + d] = b->velocity[d];
    }
    return i;
}

/* Sites origin + 2 R (i, j, k), i fastest; ids in that order; bonds to the +x, +y, +z face
 * neighbours. */
static int block(loader *L, const yaml_node_t *g, const char *path, int32_t gen,
                 int64_t *next_id) {
    bonded b = {0};
    double origin[3];
    int64_t n[3];
    char sub[SD_PATH_MAX], item[SD_PATH_MAX];
    if (sd_keys(&L->c, g, path, BLOCK_KEYS) || read_common(L, g, path, &b) ||
        sd_req_vec3(&L->c, g, path, "origin", origin))
        return -1;
    const yaml_node_t *c = sd_get(&L->c, g, "counts");
    sd_join(sub, path, "counts");
    if (!c) return sd_missing(&L->c, g, path, "counts", "[nx, ny, nz], integers >= 1");
    if (c->type != YAML_SEQUENCE_NODE || sd_len(c) != 3)
        return sd_fail(&L->c, c, sub, "expected three integers, got %s; valid: [nx, ny, nz]",
                       sd_kind(c));
    for (size_t d = 0; d < 3; d++) {
        sd_join_index(item, sub, d);
        if (sd_int(&L->c, sd_item(&L->c, c, d), item, 1, &n[d])) return -1;
    }
    if ((double)n[0] * (double)n[1] * (double)n[2] > MAX_PARTICLES)
        return sd_fail(&L->c, c, sub, "too many spheres; valid: at most %d", MAX_PARTICLES);
    const int64_t first = *next_id;
    for (int64_t k = 0; k < n[2]; k++)
        for (int64_t j = 0; j < n[1]; j++)
            for (int64_t i = 0; i < n[0]; i++) {
                const double x[3] = {origin[0] + 2.0 * b.radius * (double)i,
                                     origin[1] + 2.0 * b.radius * (double)j,
                                     origin[2] + 2.0 * b.radius * (double)k};
                if (add_sphere(L, g, gen, &b, x, next_id) < 0) return -1;
            }
    for (int64_t k = 0; k < n[2]; k++)
        for (int64_t j = 0; j < n[1]; j++)
            for (int64_t i = 0; i < n[0]; i++) {
                const int64_t id = first + i + n[0] * (j + n[1] * k);
                if ((i + 1 < n[0] && scene_add_bond(L, g, id, id + 1, b.type)) ||
                    (j + 1 < n[1] && scene_add_bond(L, g, id, id + n[0], b.type)) ||
                    (k + 1 < n[2] && scene_add_bond(L, g, id, id + n[0] * n[1], b.type)))
                    return -1;
            }
    return 0;
}

/* FCC sites in units of a/2 = sqrt(2) r (a the cubic cell): integer (i, j, k) with i + j + k
 * even, one site on the centre; kept when |site| <= D/2 - r, i.e. (i^2 + j^2 + k^2) 2 r^2 <=
 * (D/2 - r)^2 (with a relative tolerance of 1e-12 for sites exactly on the boundary).  Ids in
 * the order k, j, i (i fastest).  The 12 nearest neighbours are the offsets with two components
 * +-1 and one 0, at distance 2 r. */
static int sphere(loader *L, const yaml_node_t *g, const char *path, int32_t gen,
                  int64_t *next_id) {
    bonded b = {0};
    double centre[3], D;
    char sub[SD_PATH_MAX];
    if (sd_keys(&L->c, g, path, SPHERE_KEYS) || read_common(L, g, path, &b) ||
        sd_req_vec3(&L->c, g, path, "centre", centre) ||
        sd_req_num(&L->c, g, path, "diameter", SD_POSITIVE, &D))
        return -1;
    sd_join(sub, path, "diameter");
    if (D < 2.0 * b.radius)
        return sd_fail(&L->c, sd_get(&L->c, g, "diameter"), sub, "%.17g is smaller than one "
                       "micro-element (2 radius = %.17g); valid: diameter >= 2 radius", D,
                       2.0 * b.radius);
    const double h = sqrt(2.0) * b.radius;        /* a/2 [m] */
    const double rho = 0.5 * D - b.radius;         /* largest site distance [m] */
    const double lim = rho * rho / (2.0 * b.radius * b.radius) * (1.0 + 1e-12); /* in (a/2)^2 */
    const int64_t m = (int64_t)floor(sqrt(lim)) + 1;
    const double side = (double)(2 * m + 1);
    if (side * side * side > MAX_SPHERE_CELLS)
        return sd_fail(&L->c, sd_get(&L->c, g, "diameter"), sub, "diameter/radius = %g needs "
                       "too large a lattice; valid: diameter/radius below about 800",
                       D / b.radius);
    const size_t w = (size_t)(2 * m + 1);
    int64_t *idx = malloc(w * w * w * sizeof *idx); /* lattice index -> id, 0: no site */
    if (!idx) return sd_no_memory(&L->c, g, path);
    int rc = 0;
#define AT(i, j, k) idx[((size_t)((k) + m) * w + (size_t)((j) + m)) * w + (size_t)((i) + m)]
    for (int64_t k = -m; k <= m && rc == 0; k++)
        for (int64_t j = -m; j <= m && rc == 0; j++)
            for (int64_t i = -m; i <= m && rc == 0; i++) {
                AT(i, j, k) = 0;
                if (((i + j + k) & 1) || (double)(i * i + j * j + k * k) > lim) continue;
                const double x[3] = {centre[0] + h * (double)i, centre[1] + h * (double)j,
                                     centre[2] + h * (double)k};
                AT(i, j, k) = *next_id;
                if (add_sphere(L, g, gen, &b, x, next_id) < 0) rc = -1;
            }
    /* the 6 of the 12 neighbour offsets that point "forwards" (the others are their negatives) */
    static const int off[6][3] = {{1, 1, 0}, {1, -1, 0}, {1, 0, 1}, {1, 0, -1}, {0, 1, 1}, {0, 1, -1}};
    for (int64_t k = -m; k <= m && rc == 0; k++)
        for (int64_t j = -m; j <= m && rc == 0; j++)
            for (int64_t i = -m; i <= m && rc == 0; i++) {
                if (!AT(i, j, k)) continue;
                for (int q = 0; q < 6 && rc == 0; q++) {
                    const int64_t a = i + off[q][0], bb = j + off[q][1], c = k + off[q][2];
                    if (a < -m || a > m || bb < -m || bb > m || c < -m || c > m) continue;
                    if (AT(a, bb, c)) rc = scene_add_bond(L, g, AT(i, j, k), AT(a, bb, c), b.type);
                }
            }
#undef AT
    free(idx);
    return rc;
}

int scene_generate_bonded(loader *L, const yaml_node_t *g, const char *key, const char *path,
                          int32_t gen, int64_t *next_id) {
    return strcmp(key, "bonded_block") == 0 ? block(L, g, path, gen, next_id)
                                            : sphere(L, g, path, gen, next_id);
}
