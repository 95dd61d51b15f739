/* mesh_cells.c — the triangle grid of mesh_cells.h. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "mesh_cells.h"

/* More cells than this per triangle only cost memory: the cell edge grows instead. */
#define CELLS_PER_TRIANGLE 8.0

static void tri_box(const double t[3][3], double lo[3], double hi[3]) {
    for (int d = 0; d < 3; d++) {
        lo[d] = fmin(t[0][d], fmin(t[1][d], t[2][d]));
        hi[d] = fmax(t[0][d], fmax(t[1][d], t[2][d]));
    }
}

/* The cell along axis d of coordinate c, clamped to the grid (monotone in c, so overlapping
 * intervals get overlapping cell ranges). */
static int cell_of(const jd_mesh_cells *g, int d, double c) {
    const double f = floor((c - g->lo[d]) * g->inv_h);
    return f < 0.0 ? 0 : f >= (double)g->n[d] ? g->n[d] - 1 : (int)f;
}

static size_t cell_index(const jd_mesh_cells *g, int i, int j, int k) {
    return ((size_t)k * (size_t)g->n[1] + (size_t)j) * (size_t)g->n[0] + (size_t)i;
}

/* The cell ranges [a, b] of the box [lo, hi]. */
static void cell_range(const jd_mesh_cells *g, const double lo[3], const double hi[3], int a[3], int b[3]) {
    for (int d = 0; d < 3; d++) {
        a[d] = cell_of(g, d, lo[d]);
        b[d] = cell_of(g, d, hi[d]);
    }
}

/* The grid's box and cell edge: at least 2 reach_max, and at most CELLS_PER_TRIANGLE cells per
 * triangle over the mesh's box. */
static void layout(jd_mesh_cells *g, size_t ntri, const double (*corner)[3][3], double reach_max) {
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (size_t t = 0; t < ntri; t++) {
        double a[3], b[3];
        tri_box(corner[t], a, b);
        for (int d = 0; d < 3; d++) {
            lo[d] = fmin(lo[d], a[d]);
            hi[d] = fmax(hi[d], b[d]);
        }
    }
    double h = fmax(2.0 * reach_max, 1e-300);
    for (;;) {
        double cells = 1.0;
        for (int d = 0; d < 3; d++) cells *= floor((hi[d] - lo[d]) / h) + 1.0;
        if (cells <= CELLS_PER_TRIANGLE * (double)ntri + 64.0) break;
        h *= 1.25;
    }
    for (int d = 0; d < 3; d++) {
        g->lo[d] = lo[d];
        g->n[d] = (int)floor((hi[d] - lo[d]) / h) + 1;
    }
    g->inv_h = 1.0 / h;
}

static int reserve(void **p, size_t *cap, size_t need, size_t size) {
    if (need <= *cap) return 0;
    void *q = realloc(*p, need * size);
    if (!q) return -1;
    *p = q;
    *cap = need;
    return 0;
}

/* Each triangle into every cell its box overlaps: counted first, then placed in ascending id. */
static int fill(jd_mesh_cells *g, size_t ntri, const double (*corner)[3][3]) {
    const size_t cells = (size_t)g->n[0] * (size_t)g->n[1] * (size_t)g->n[2];
    if (reserve((void **)&g->start, &g->cap_cells, cells + 1, sizeof *g->start)) return -1;
    memset(g->start, 0, (cells + 1) * sizeof *g->start);
    for (int pass = 0; pass < 2; pass++) {
        for (size_t t = 0; t < ntri; t++) {
            double lo[3], hi[3];
            int a[3], b[3];
            tri_box(corner[t], lo, hi);
            cell_range(g, lo, hi, a, b);
            for (int k = a[2]; k <= b[2]; k++)
                for (int j = a[1]; j <= b[1]; j++)
                    for (int i = a[0]; i <= b[0]; i++) {
                        const size_t c = cell_index(g, i, j, k);
                        if (pass == 0) g->start[c + 1]++;
                        else g->tri[g->start[c]++] = (int32_t)t;
                    }
        }
        if (pass == 0) {
            for (size_t c = 0; c < cells; c++) g->start[c + 1] += g->start[c];
            if (reserve((void **)&g->tri, &g->cap_tri, g->start[cells] ? g->start[cells] : 1, sizeof *g->tri))
                return -1;
        }
    }
    /* the second pass moved each start to its cell's end, the next cell's start */
    memmove(g->start + 1, g->start, cells * sizeof *g->start);
    g->start[0] = 0;
    return 0;
}

int sim_mesh_cells_build(jd_mesh_cells *g, size_t ntri, const double (*corner)[3][3], double reach_max) {
    layout(g, ntri, corner, reach_max);
    if (g->n_tri != ntri) {
        free(g->stamp);
        g->stamp = calloc(ntri ? ntri : 1, sizeof *g->stamp);
        if (!g->stamp) return -1;
        g->n_tri = ntri;
        g->query = 0;
    }
    if (reserve((void **)&g->found, &g->cap_found, ntri ? ntri : 1, sizeof *g->found)) return -1;
    return fill(g, ntri, corner);
}

static int ascending(const void *a, const void *b) {
    const int32_t x = *(const int32_t *)a, y = *(const int32_t *)b;
    return (x > y) - (x < y);
}

long sim_mesh_cells_near(jd_mesh_cells *g, const double x[3], double reach) {
    if (++g->query == 0) { /* the stamps wrapped round: none is current */
        memset(g->stamp, 0, g->n_tri * sizeof *g->stamp);
        g->query = 1;
    }
    const double lo[3] = {x[0] - reach, x[1] - reach, x[2] - reach};
    const double hi[3] = {x[0] + reach, x[1] + reach, x[2] + reach};
    for (int d = 0; d < 3; d++) /* a box beside the grid's meets no triangle */
        if (hi[d] < g->lo[d] || lo[d] > g->lo[d] + (double)g->n[d] / g->inv_h) return 0;
    int a[3], b[3];
    cell_range(g, lo, hi, a, b);
    size_t n = 0;
    for (int k = a[2]; k <= b[2]; k++)
        for (int j = a[1]; j <= b[1]; j++)
            for (int i = a[0]; i <= b[0]; i++) {
                const size_t c = cell_index(g, i, j, k);
                for (size_t e = g->start[c]; e < g->start[c + 1]; e++) {
                    const int32_t t = g->tri[e];
                    if (g->stamp[t] == g->query) continue;
                    g->stamp[t] = g->query;
                    g->found[n++] = t;
                }
            }
    qsort(g->found, n, sizeof *g->found, ascending);
    return (long)n;
}

void sim_mesh_cells_free(jd_mesh_cells *g) {
    free(g->start);
    free(g->tri);
    free(g->stamp);
    free(g->found);
    memset(g, 0, sizeof *g);
}
