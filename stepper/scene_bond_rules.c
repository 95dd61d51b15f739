/*
 * scene_bond_rules.c — which pairs a bond rule bonds (scene.h, jd_bond_rule_pairs): the group's
 * particles are binned into cubic cells of side h >= the largest bonding distance, and each
 * particle is tested against the particles of its own and the 26 neighbouring cells.
 */
#include <math.h>
#include <stdlib.h>

#include "scene.h"

typedef struct cell_item {
    uint64_t key;
    int32_t i;
} cell_item;

static int by_key(const void *a, const void *b) {
    const cell_item *x = a, *y = b;
    if (x->key != y->key) return x->key < y->key ? -1 : 1;
    return x->i < y->i ? -1 : x->i > y->i;
}

static int by_pair(const void *a, const void *b) {
    const int32_t *x = a, *y = b;
    if (x[0] != y[0]) return x[0] < y[0] ? -1 : 1;
    return x[1] < y[1] ? -1 : x[1] > y[1];
}

/* Cells per axis are capped at 2^20 so that a key fits in 64 bits. */
#define AXIS_CELLS 1048576.0

long jd_bond_rule_pairs(const jd_scene *s, const jd_bond_rule *rule, const double *x,
                        int32_t **pairs) {
    *pairs = NULL;
    size_t n = 0;
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    double rmax = 0.0;
    cell_item *items = malloc((s->n_particles ? s->n_particles : 1) * sizeof *items);
    if (!items) return -1;
    for (size_t i = 0; i < s->n_particles; i++) {
        if (!rule->materials[s->material[i]] || s->id[i] < rule->id_range[0] ||
            s->id[i] > rule->id_range[1])
            continue;
        items[n++].i = (int32_t)i;
        rmax = fmax(rmax, s->radius[i]);
        for (int d = 0; d < 3; d++) {
            lo[d] = fmin(lo[d], x[3 * i + d]);
            hi[d] = fmax(hi[d], x[3 * i + d]);
        }
    }
    /* bonding needs |dx| <= R_i + R_j + max_gap min(R) <= rmax (2 + max_gap) */
    double h = rmax * (2.0 + rule->max_gap);
    uint64_t dims[3];
    for (int d = 0; d < 3 && n; d++) h = fmax(h, (hi[d] - lo[d]) / (AXIS_CELLS - 1.0));
    for (int d = 0; d < 3 && n; d++) dims[d] = (uint64_t)((hi[d] - lo[d]) / h) + 1;
    for (size_t k = 0; k < n; k++) {
        const double *p = &x[3 * items[k].i];
        uint64_t key = 0;
        for (int d = 2; d >= 0; d--) key = key * dims[d] + (uint64_t)((p[d] - lo[d]) / h);
        items[k].key = key;
    }
    qsort(items, n, sizeof *items, by_key);
    size_t np = 0, cap = 0;
    int32_t *out = NULL;
    for (size_t k = 0; k < n; k++) {
        const int32_t i = items[k].i;
        const double *xi = &x[3 * i];
        uint64_t c[3];
        for (int d = 0; d < 3; d++) c[d] = (uint64_t)((xi[d] - lo[d]) / h);
        for (int dz = -1; dz <= 1; dz++)
            for (int dy = -1; dy <= 1; dy++)
                for (int dx = -1; dx <= 1; dx++) {
                    const int off[3] = {dx, dy, dz};
                    uint64_t key = 0;
                    int inside = 1;
                    for (int d = 2; d >= 0; d--) {
                        inside &= !(off[d] < 0 && c[d] == 0) &&
                                  !(off[d] > 0 && c[d] + 1 >= dims[d]);
                        key = key * dims[d] + (c[d] + (uint64_t)(int64_t)off[d]);
                    }
                    if (!inside) continue;
                    size_t a = 0, b = n; /* first item with this key */
                    while (a < b) {
                        size_t m = a + (b - a) / 2;
                        if (items[m].key < key) a = m + 1; else b = m;
                    }
                    for (; a < n && items[a].key == key; a++) {
                        const int32_t j = items[a].i;
                        if (j <= i) continue;
                        const double *xj = &x[3 * j];
                        const double dist = sqrt((xj[0] - xi[0]) * (xj[0] - xi[0]) +
                                                 (xj[1] - xi[1]) * (xj[1] - xi[1]) +
                                                 (xj[2] - xi[2]) * (xj[2] - xi[2]));
                        const double ri = s->radius[i], rj = s->radius[j];
                        if (dist - ri - rj > rule->max_gap * fmin(ri, rj)) continue;
                        if (np == cap) {
                            cap = cap ? 2 * cap : 64;
                            int32_t *q = realloc(out, 2 * cap * sizeof *q);
                            if (!q) {
                                free(out);
                                free(items);
                                return -1;
                            }
                            out = q;
                        }
                        out[2 * np] = i;
                        out[2 * np + 1] = j;
                        np++;
                    }
                }
    }
    free(items);
    if (np) qsort(out, np, 2 * sizeof *out, by_pair);
    *pairs = out;
    return (long)np;
}
