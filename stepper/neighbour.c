/*
 * neighbour.c — contact candidates.
 *
 * A cell list (cell edge >= twice the largest radius + half skin) yields a half Verlet list of
 * the pairs i < j whose surfaces are closer than the sum of their half skins, and a list of
 * (particle, wall) candidates closer to a wall than the particle's half skin and the wall's
 * (skin/2).  Each particle has a half skin of its own, skin/2 or more for a fast one
 * (half_skin_of).  The lists are rebuilt only when some particle has moved more than its
 * half skin, or some wall more than skin/2, since the last build: then no pair can have closed
 * its gap in between, so no contact is missed.  (The particles' displacement is checked in the
 * drift, integrate.c.)
 *
 * A build is partial when few particles have moved (sim_neighbour_build): the particles that
 * moved more than JD_MOVED_FRACTION of their half skin get new half skins and reference
 * positions, and only their pairs and wall candidates are searched again; every other entry is
 * kept.  A kept particle can still move its whole half skin from its reference position, that
 * is up to its half skin plus the distance it has drifted from there already; so the search
 * range of a pair with a kept particle has the largest such drift added (pairs_of_moved), and
 * an entry kept or left out at one build stays right until either particle triggers the next.
 * Every JD_FULL_BUILD_EVERY-th build, any build after particles were deleted or a wall moved,
 * and any build when many moved, is full: everything searched again, every half skin renewed and
 * the particles renumbered in cell order.
 *
 * Both lists are sorted by (i, j), which fixes the force summation order (deterministic) and
 * lets the contact history be carried over to a new list by one merge of the two sorted lists.
 * Entries that are not carried over are dropped after their dissipated energies are added to
 * the run's totals, so the dissipation observables lose nothing at a rebuild.
 */
#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "geometry.h"
#include "hugepages.h"
#include "sim.h"

/* The bytes of l's arrays at capacity cap with history widths hw and rw (rw 0: no rhist). */
static void list_array_bytes(size_t cap, int hw, int rw, size_t bytes[4]) {
    bytes[0] = bytes[1] = cap * sizeof(int32_t);
    bytes[2] = cap * (size_t)hw * sizeof(double);
    bytes[3] = cap * (size_t)rw * sizeof(double);
}

/* Every array of l resized to cap entries with history widths hw and rw (rhist only if rw > 0),
 * keeping their leading bytes like realloc, on huge pages (hugepages.h).  Returns 0, or -1 when
 * there was no memory: then l is as it was. */
static int list_resize(jd_contact_list *l, size_t cap, int hw, int rw) {
    size_t old[4], now[4];
    list_array_bytes(l->cap, l->hw, l->rhist ? l->rw : 0, old);
    list_array_bytes(cap, hw, rw, now);
    void *from[4] = {l->i, l->j, l->hist, l->rhist}, *to[4] = {NULL, NULL, NULL, NULL};
    int failed = 0;
    for (int k = 0; k < 4; k++) failed |= now[k] && !(to[k] = jd_huge_alloc(now[k]));
    if (failed) {
        for (int k = 0; k < 4; k++) jd_huge_free(to[k], now[k]);
        return -1;
    }
    for (int k = 0; k < 4; k++) {
        if (from[k] && to[k]) memcpy(to[k], from[k], old[k] < now[k] ? old[k] : now[k]);
        jd_huge_free(from[k], old[k]);
    }
    l->i = to[0];
    l->j = to[1];
    l->hist = to[2];
    l->rhist = to[3];
    return 0;
}

/* Every list of a run is of the run's kind (history widths hw, rw); buffers swap roles between
 * the lists (sim_neighbour_build, sim_reorder), and every array a list has is kept at its
 * capacity. */
int sim_list_reserve(jd_contact_list *l, size_t need, unsigned kind) {
    const int rolling = (kind & JD_F_ROLLING) != 0;
    const int hw = jd_contact_record_len(kind), rw = jd_rolling_record_len(kind);
    const int complete = l->hw == hw && l->rw == rw && (!rolling || l->rhist);
    if (need <= l->cap && complete) return 0;
    size_t cap = l->cap ? l->cap : 256;
    while (cap < need) cap += cap / 2;
    if (list_resize(l, cap, hw, rw) != 0) return -1;
    l->cap = cap;
    l->hw = hw;
    l->rw = rw;
    return 0;
}

/* Give back what a list holds beyond twice its entries and the 256 a list starts with: a list
 * that was once much longer (a burst of candidates) does not keep its room for the rest of the
 * run, while one that breathes by a few per cent from build to build is never reallocated. */
static void list_fit(jd_contact_list *l) {
    const size_t cap = 2 * l->n + 256;
    if (cap >= l->cap) return;
    if (list_resize(l, cap, l->hw, l->rw) == 0) l->cap = cap; /* if not, the list keeps its room */
}

static int list_push(jd_contact_list *l, int32_t i, int32_t j, unsigned kind) {
    if ((l->n == l->cap || l->n == 0) && sim_list_reserve(l, l->n + 1, kind) != 0) return -1;
    l->i[l->n] = i;
    l->j[l->n] = j;
    l->n++;
    return 0;
}

void sim_contact_list_free(jd_contact_list *l) {
    size_t bytes[4];
    list_array_bytes(l->cap, l->hw, l->rhist ? l->rw : 0, bytes);
    jd_huge_free(l->i, bytes[0]);
    jd_huge_free(l->j, bytes[1]);
    jd_huge_free(l->hist, bytes[2]);
    jd_huge_free(l->rhist, bytes[3]);
    memset(l, 0, sizeof *l);
}

/* The entry (i, j) as one number whose order is the lists' order, (i, j) (indices >= 0). */
static int64_t pair_key(int32_t i, int32_t j) {
    return ((int64_t)i << 32) | (int64_t)(uint32_t)j;
}

static int64_t entry_key(const jd_contact_list *l, size_t c) {
    return pair_key(l->i[c], l->j[c]);
}

static int key_less(const jd_contact_list *a, size_t p, const jd_contact_list *b, size_t q) {
    return entry_key(a, p) < entry_key(b, q);
}

/* The dissipation accumulated by entry c (energy bookkeeping only), harvested into the run's
 * totals when the entry is dropped (jd_contact_harvest). */
static void drop_entry(jd_accounts *accounts, const jd_contact_list *l, size_t c) {
    if (l->hw < JD_CONTACT_ENERGY_LEN) return; /* no accounts (a MEPA record without them holds zeros) */
    jd_contact_state st;
    sim_hist_get(l, c, &st, NULL);
    jd_contact_harvest(&st, 1.0, &accounts->e_damp_dropped, &accounts->e_fric_dropped);
}

static void copy_entry(const jd_contact_list *from, size_t c, jd_contact_list *to, size_t d) {
    const size_t hw = (size_t)from->hw, rw = (size_t)from->rw;
    to->i[d] = from->i[c];
    to->j[d] = from->j[c];
    memcpy(to->hist + hw * d, from->hist + hw * c, hw * sizeof *to->hist);
    if (rw) memcpy(to->rhist + rw * d, from->rhist + rw * c, rw * sizeof *to->rhist);
}

/* Entries of l with an index >= keep (a deleted particle; `pairs`: j too) are dropped, their
 * dissipation harvested; the others keep their order within each of the two runs. */
static void drop_from(jd_accounts *accounts, jd_contact_list *l, int pairs, size_t keep) {
    size_t w = 0, touch = 0;
    for (size_t c = 0; c < l->n; c++) {
        if ((size_t)l->i[c] >= keep || (pairs && (size_t)l->j[c] >= keep)) {
            drop_entry(accounts, l, c);
            continue;
        }
        if (w != c) copy_entry(l, c, l, w);
        touch += c < l->n_touch;
        w++;
    }
    l->n = w;
    l->n_touch = touch;
}

void sim_lists_drop_from(jd_sim *s, size_t keep) {
    s->lists.renumbered = 1;
    drop_from(&s->accounts, &s->lists.pairs, 1, keep);
    drop_from(&s->accounts, &s->lists.wall_pairs, 0, keep);
}

/* Give every entry of nw (one sorted run) the history of the same (i, j) in old, or a fresh
 * (zero) history: one merge with each of old's two sorted runs (jd_contact_list). */
static void carry_over(jd_accounts *accounts, const jd_contact_list *old, jd_contact_list *nw) {
    const size_t hw = (size_t)nw->hw, rw = (size_t)nw->rw;
    size_t a = 0, a_end = old->n_touch, q = old->n_touch;
    for (size_t b = 0; b < nw->n; b++) {
        for (; a < a_end && key_less(old, a, nw, b); a++) drop_entry(accounts, old, a);
        for (; q < old->n && key_less(old, q, nw, b); q++) drop_entry(accounts, old, q);
        const int in_a = a < a_end && !key_less(nw, b, old, a);
        const int in_q = !in_a && q < old->n && !key_less(nw, b, old, q);
        if (in_a || in_q) {
            const size_t at = in_a ? a++ : q++;
            memcpy(nw->hist + hw * b, old->hist + hw * at, hw * sizeof *nw->hist);
            if (rw) memcpy(nw->rhist + rw * b, old->rhist + rw * at, rw * sizeof *nw->rhist);
        } else {
            memset(nw->hist + hw * b, 0, hw * sizeof *nw->hist);
            if (rw) memset(nw->rhist + rw * b, 0, rw * sizeof *nw->rhist);
        }
    }
    for (; a < a_end; a++) drop_entry(accounts, old, a);
    for (; q < old->n; q++) drop_entry(accounts, old, q);
}

/* Can particle i touch wall w before the next rebuild: is it within margin (its half skin and
 * the wall's) of the wall? */
static int wall_candidate(const jd_sim_wall *w, const double *x, double R, double margin) {
    return w->type == JD_WALL_PLANE ? jd_geom_plane_near(&w->plane, x, R, margin)
                                    : jd_geom_cylinder_near(&w->cyl, x, R, margin);
}


/* Entry c of `from` into entry d of `to` (same kind of list). */

/* The pair list `in` (one sorted run) into `out` as two sorted runs: the candidates whose
 * spheres touch now (LIGGGHTS' rsq < radsum^2), then the others (jd_contact_list). */
static int split_touching(const jd_particles *ps, unsigned kind, const jd_contact_list *in,
                          jd_contact_list *out) {
    if (sim_list_reserve(out, in->n, kind) != 0) return -1;
    size_t touching = 0;
    for (size_t c = 0; c < in->n; c++) touching += sim_pair_touching(ps, in->i[c], in->j[c]);
    size_t t = 0, o = touching;
    for (size_t c = 0; c < in->n; c++)
        copy_entry(in, c, out, sim_pair_touching(ps, in->i[c], in->j[c]) ? t++ : o++);
    out->n = in->n;
    out->n_touch = touching;
    return 0;
}

static void sort_segment(int32_t *j, size_t n) { /* insertion sort: a few dozen entries */
    for (size_t a = 1; a < n; a++) {
        const int32_t v = j[a];
        size_t b = a;
        for (; b > 0 && j[b - 1] > v; b--) j[b] = j[b - 1];
        j[b] = v;
    }
}

/* The order of the cell numbering: ax[0] the slowest axis, ax[2] the fastest.  Slowest is the
 * axis with the most cells, so that the partners j of a row i reach over one slab of the other
 * two axes, the smallest window (forces.c, prefetch_particles): in a bed 20 cells deep and
 * 128 x 128 wide, a slab of 128 x 20 cells instead of a layer of 128 x 128, which stays in the
 * L2 cache.  Of the other two, the one with more cells is the fastest (the longest contiguous
 * rows), so a flat bed's floor particles come in one run per slab.  Ties keep z, y, x
 * (docs/performance.md). */
static void cell_axes(const int nc[3], int ax[3]) {
    int slow = 2;
    for (int d = 1; d >= 0; d--)
        if (nc[d] > nc[slow]) slow = d;
    const int p = (slow + 1) % 3, q = (slow + 2) % 3;
    const int fast = nc[p] != nc[q] ? (nc[p] > nc[q] ? p : q) : (p < q ? p : q);
    ax[0] = slow;
    ax[1] = 3 - slow - fast;
    ax[2] = fast;
}

/* Cell number of the cell with coordinates c[3] in the numbering order ax (cell_axes). */
static inline size_t cell_number(const int c[3], const int nc[3], const int ax[3]) {
    return ((size_t)c[ax[0]] * (size_t)nc[ax[1]] + (size_t)c[ax[1]]) * (size_t)nc[ax[2]] + (size_t)c[ax[2]];
}

/* Sort particles into cells (counting sort, so each cell lists its particles in index order). */
static int bin_particles(jd_neighbour_lists *lists, const jd_particles *ps, double h,
                         const double lo[3], const int nc[3], const int ax[3]) {
    const size_t ncell = (size_t)nc[0] * (size_t)nc[1] * (size_t)nc[2];
    if (ncell + 1 > lists->cell_cap) {
        int32_t *cs = realloc(lists->cell_start, (ncell + 1) * sizeof *cs);
        if (!cs) return -1;
        lists->cell_start = cs;
        lists->cell_cap = ncell + 1;
    }
    memset(lists->cell_start, 0, (ncell + 1) * sizeof *lists->cell_start);
    for (size_t i = 0; i < ps->n; i++) {
        int c[3];
        for (int d = 0; d < 3; d++) { /* a particle outside the grid goes to its edge cell */
            const double t = floor((ps->x[3 * i + d] - lo[d]) / h);
            c[d] = t < 0.0 ? 0 : t >= (double)nc[d] ? nc[d] - 1 : (int)t;
        }
        lists->cell_of[i] = (int32_t)cell_number(c, nc, ax);
        lists->cell_start[lists->cell_of[i] + 1]++;
    }
    for (size_t c = 0; c < ncell; c++) lists->cell_start[c + 1] += lists->cell_start[c];
    for (size_t i = 0; i < ps->n; i++) lists->cell_items[lists->cell_start[lists->cell_of[i]]++] = (int32_t)i;
    for (size_t c = ncell; c > 0; c--) lists->cell_start[c] = lists->cell_start[c - 1]; /* undo the shift */
    lists->cell_start[0] = 0;
    return 0;
}

static double grid_cells(const double lo[3], const double hi[3], double h) {
    double cells = 1.0;
    for (int d = 0; d < 3; d++) cells *= floor((hi[d] - lo[d]) / h) + 1.0;
    return cells;
}

/* The k-th smallest (from 0) of a[0, n), n > k, reordering a (Hoare's selection). */
static double kth_smallest(double *a, ptrdiff_t n, ptrdiff_t k) {
    ptrdiff_t lo = 0, hi = n - 1;
    while (lo < hi) {
        const double pivot = a[lo + (hi - lo) / 2];
        ptrdiff_t i = lo, j = hi;
        while (i <= j) {
            while (a[i] < pivot) i++;
            while (a[j] > pivot) j--;
            if (i <= j) {
                const double t = a[i];
                a[i++] = a[j];
                a[j--] = t;
            }
        }
        if (k <= j)
            hi = j;
        else if (k >= i)
            lo = i;
        else
            return a[k];
    }
    return a[k];
}

/* A grid over the box that holds all particles but the JD_GRID_TRIM-th part lowest and highest
 * along each axis, from JD_GRID_TRIM_MIN_N particles: a few that left the bulk (a sphere thrown
 * out of a container and falling) would otherwise stretch the box, and with it the cells, by
 * orders of magnitude.  The few outside are binned into the edge cells (bin_particles), which
 * keeps the list exact: a partner within range of such a particle lies in its edge cell or the
 * next one along every axis (LAMMPS bins the same way). */
#define JD_GRID_TRIM 1000
#define JD_GRID_TRIM_MIN_N 1024
static int core_box(const jd_particles *ps, double lo[3], double hi[3]) {
    const ptrdiff_t n = (ptrdiff_t)ps->n, k = n / JD_GRID_TRIM;
    double *a = malloc((size_t)n * sizeof *a);
    if (!a) return -1;
    for (int d = 0; d < 3; d++) {
        for (ptrdiff_t i = 0; i < n; i++) a[i] = ps->x[3 * i + d];
        lo[d] = kth_smallest(a, n, k);
        hi[d] = kth_smallest(a, n, n - 1 - k);
    }
    free(a);
    return 0;
}

/* The cell grid over the particles' bounding box: cell edge h >= the largest interaction
 * range (twice the largest radius + half skin, and `extra` [m]: a partial build's kept
 * drift); over the core box (core_box) instead if the whole box would need more than about 8
 * cells per particle and the core box would not; the edge grown if even that needs more
 * (sparse or scattered systems).  Fails on a non-finite position or out of memory. */
static int cell_grid(const jd_particles *ps, const double *hs, double extra, int64_t step,
                     double *h_out, double lo[3], int nc[3], char *err, size_t errlen) {
    double hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    double reach = 0.0; /* the largest radius + half skin */
    for (int d = 0; d < 3; d++) lo[d] = INFINITY;
    for (size_t i = 0; i < ps->n; i++) {
        for (int d = 0; d < 3; d++) {
            const double xd = ps->x[3 * i + d];
            if (!isfinite(xd)) {
                snprintf(err, errlen, "particle %lld has a non-finite position at step %lld",
                         sim_particle_id(ps, i), (long long)step);
                return -1;
            }
            lo[d] = xd < lo[d] ? xd : lo[d]; /* not fmin: a call into libm at every build */
            hi[d] = xd > hi[d] ? xd : hi[d];
        }
        const double ri = ps->radius[i] + hs[i];
        reach = ri > reach ? ri : reach;
    }
    double h = 2.0 * reach + extra;
    const double max_cells = 8.0 * (double)ps->n + 64.0;
    double cells = grid_cells(lo, hi, h);
    if (cells > max_cells && ps->n >= JD_GRID_TRIM_MIN_N) {
        double core_lo[3], core_hi[3];
        if (core_box(ps, core_lo, core_hi) != 0) {
            snprintf(err, errlen, "out of memory for the cell grid of %zu particles", ps->n);
            return -1;
        }
        if (grid_cells(core_lo, core_hi, h) <= max_cells) {
            memcpy(lo, core_lo, sizeof core_lo);
            memcpy(hi, core_hi, sizeof core_hi);
            cells = grid_cells(lo, hi, h);
        }
    }
    if (cells > max_cells) h *= cbrt(cells / max_cells) * 1.01;
    /* the cube root fits a box spread in three dimensions; a flat one (one particle far away
     * along one axis) can keep far more cells than that, without bound: cap them at 8x */
    while (grid_cells(lo, hi, h) > 8.0 * max_cells && isfinite(h)) h *= 2.0;
    for (int d = 0; d < 3; d++) nc[d] = (int)floor((hi[d] - lo[d]) / h) + 1;
    *h_out = h;
    return 0;
}

/* Renumber the particles in cell order (cell_axes; within a cell by index), so that neighbours
 * lie close in memory. */
static int sort_into_cells(jd_sim *s, char *err, size_t errlen) {
    double h, lo[3];
    int nc[3], ax[3];
    if (cell_grid(&s->particles, s->lists.half_skin, 0.0, s->step, &h, lo, nc, err, errlen) != 0) return -1;
    cell_axes(nc, ax);
    if (bin_particles(&s->lists, &s->particles, h, lo, nc, ax) != 0) {
        snprintf(err, errlen, "out of memory sorting %zu particles", s->particles.n);
        return -1;
    }
    /* cell_items is the new order (new index -> old index) */
    return sim_reorder(s, s->lists.cell_items, err, errlen);
}

/* Room for one more entry in part p (its arrays grow by half, from 1024).  0 or -1. */
static int part_room(jd_pair_part *p) {
    if (p->n < p->cap) return 0;
    const size_t cap = p->cap ? p->cap + p->cap / 2 : 1024;
    int32_t *a = realloc(p->i, cap * sizeof *a);
    if (!a) return -1;
    p->i = a;
    int32_t *b = realloc(p->j, cap * sizeof *b);
    if (!b) return -1;
    p->j = b;
    p->cap = cap;
    return 0;
}

/* Push the pairs (i, j) of the partners j > i at [q0, q1) of the cell arrays whose surfaces are
 * closer than the sum of their half skins into part p: j = items[q], or j = q when items is NULL (particles
 * numbered in cell order).  The tests of a block of JD_NEAR_BLOCK partners first, in SIMD
 * lanes, then the pushes in order. */
#define JD_NEAR_BLOCK 32
static int push_near(const jd_particles *ps, const double *restrict hs, size_t i,
                     const int32_t *items, int32_t q0, int32_t q1, jd_pair_part *p) {
    const double *restrict x = ps->x, *restrict rad = ps->radius;
    const double xi0 = x[3 * i], xi1 = x[3 * i + 1], xi2 = x[3 * i + 2], ri = rad[i], hi = hs[i];
    for (int32_t b = q0; b < q1; b += JD_NEAR_BLOCK) {
        const int nb = q1 - b < JD_NEAR_BLOCK ? (int)(q1 - b) : JD_NEAR_BLOCK;
        int near[JD_NEAR_BLOCK];
        for (int k = 0; k < nb; k++) {
            const size_t j = (size_t)(items ? items[b + k] : b + k);
            const double d0 = x[3 * j] - xi0, d1 = x[3 * j + 1] - xi1, d2 = x[3 * j + 2] - xi2;
            /* the radii and the half skins summed apart: with one skin, hi + hs[j] is the skin
             * exactly, and the range the bits of ri + rj + skin */
            const double range = (ri + rad[j]) + (hi + hs[j]);
            near[k] = j > i && d0 * d0 + d1 * d1 + d2 * d2 < range * range;
        }
        for (int k = 0; k < nb; k++) {
            if (!near[k]) continue;
            if (part_room(p) != 0) return -1;
            p->i[p->n] = (int32_t)i;
            p->j[p->n++] = items ? items[b + k] : b + k;
        }
    }
    return 0;
}

/* The cell grid a build searches (cell_grid, cell_axes) and how the particles are numbered. */
typedef struct cell_search {
    const jd_particles *ps;
    const jd_neighbour_lists *lists; /* its cell arrays, binned */
    int nc[3], ax[3];
    int sorted;  /* particles numbered in cell order (sort_into_cells) */
} cell_search;

/* The runs [lo[r], hi[r]) of the cell arrays that hold the 3 x 3 x 3 cells around particle
 * i's: one per row of three cells along the fast axis (up to 9); their count. */
static int cell_runs(const cell_search *g, size_t i, int32_t lo[9], int32_t hi[9]) {
    const int *nc = g->nc, *ax = g->ax;
    const int32_t ci = g->lists->cell_of[i];
    int c[3];
    c[ax[2]] = ci % nc[ax[2]];
    c[ax[1]] = (ci / nc[ax[2]]) % nc[ax[1]];
    c[ax[0]] = ci / (nc[ax[2]] * nc[ax[1]]);
    const int f0 = c[ax[2]] > 0 ? c[ax[2]] - 1 : 0; /* the row's cells along the fast axis */
    const int f1 = c[ax[2]] + 1 < nc[ax[2]] ? c[ax[2]] + 1 : nc[ax[2]] - 1;
    int n = 0;
    for (int ds = -1; ds <= 1; ds++) {
        int nb[3];
        nb[ax[0]] = c[ax[0]] + ds;
        if (nb[ax[0]] < 0 || nb[ax[0]] >= nc[ax[0]]) continue;
        for (int dm = -1; dm <= 1; dm++) {
            nb[ax[1]] = c[ax[1]] + dm;
            if (nb[ax[1]] < 0 || nb[ax[1]] >= nc[ax[1]]) continue;
            nb[ax[2]] = f0;
            const size_t row = cell_number(nb, nc, ax), end = row + (size_t)(f1 - f0) + 1;
            lo[n] = g->lists->cell_start[row];
            hi[n++] = g->lists->cell_start[end];
        }
    }
    return n;
}

/* Particle i's pairs (i, j > i) within their half skins into part p, sorted by j: the 9 rows of cells
 * around i's cell, each one run of the cell arrays (its three cells along the fast axis).
 * With the particles in cell order that run is the partners themselves, and those before i + 1
 * are skipped unread; the entries are the same either way. */
static int pairs_of(const void *ctx, size_t i, jd_pair_part *p) {
    const cell_search *g = ctx;
    int32_t lo[9], hi[9];
    const int runs = cell_runs(g, i, lo, hi);
    const size_t first = p->n;
    for (int r = 0; r < runs; r++) {
        const int32_t q0 = g->sorted && lo[r] <= (int32_t)i ? (int32_t)i + 1 : lo[r];
        if (q0 < hi[r] && push_near(g->ps, g->lists->half_skin, i,
                                    g->sorted ? NULL : g->lists->cell_items, q0, hi[r], p) != 0)
            return -1;
    }
    sort_segment(p->j + first, p->n - first);
    return 0;
}

/* What a wall-list build searches. */
typedef struct wall_search {
    const jd_particles *ps;
    const jd_walls *walls;
    const jd_neighbour_lists *lists; /* the skins (sim_wall_margin) */
    int allpairs;                    /* every particle with every wall */
} wall_search;

/* Particle i's (particle, wall) candidates within the skins into part p, by wall. */
static int walls_of(const void *ctx, size_t i, jd_pair_part *p) {
    const wall_search *q = ctx;
    for (size_t w = 0; w < q->walls->n; w++) {
        if (q->walls->wall[w].gone) continue; /* vanished (sim_walls_retire) */
        if (!q->allpairs &&
            !wall_candidate(&q->walls->wall[w], q->ps->x + 3 * i, q->ps->radius[i],
                            sim_wall_margin(q->lists, i)))
            continue;
        if (part_room(p) != 0) return -1;
        p->i[p->n] = (int32_t)i;
        p->j[p->n++] = (int32_t)w;
    }
    return 0;
}

/* Room for the parts of `threads` threads (kept from one build to the next).  0 or -1. */
static int parts_reserve(jd_neighbour_lists *lists, int threads) {
    if (lists->n_parts >= threads) return 0;
    jd_pair_part *p = realloc(lists->parts, (size_t)threads * sizeof *p);
    if (!p) return -1;
    memset(p + lists->n_parts, 0, (size_t)(threads - lists->n_parts) * sizeof *p);
    lists->parts = p;
    lists->n_parts = threads;
    return 0;
}

/* The entries of items 0 .. n - 1, entries_of(ctx, k, part) each, into the threads' parts:
 * each of `threads` threads takes one equal range of k, so that the parts joined in thread
 * order are the same for every thread count.  0, or -1 when out of memory. */
typedef int (*entries_fn)(const void *ctx, size_t k, jd_pair_part *p);
static int run_parts(jd_neighbour_lists *lists, size_t n, int threads, entries_fn entries_of,
                     const void *ctx) {
    if (parts_reserve(lists, threads) != 0) return -1;
    for (int t = 0; t < threads; t++) lists->parts[t].n = 0; /* also of a thread OpenMP withholds */
    int failed = 0;
#pragma omp parallel num_threads(threads) if (threads > 1) reduction(| : failed)
    {
        const int t = omp_get_thread_num(), nt = omp_get_num_threads();
        jd_pair_part p = lists->parts[t]; /* a copy: the parts share cache lines */
        for (size_t k = n * (size_t)t / (size_t)nt; k < n * (size_t)(t + 1) / (size_t)nt && !failed; k++)
            failed |= entries_of(ctx, k, &p) != 0;
        lists->parts[t] = p;
    }
    return failed ? -1 : 0;
}

/* The parts' entries (run_parts), in thread order, appended to l (of this kind).  0 or -1. */
static int build_in_parts(jd_neighbour_lists *lists, size_t n, int threads, entries_fn entries_of,
                          const void *ctx, unsigned kind, jd_contact_list *l) {
    if (run_parts(lists, n, threads, entries_of, ctx) != 0) return -1;
    size_t total = l->n;
    for (int t = 0; t < threads; t++) total += lists->parts[t].n;
    if (sim_list_reserve(l, total, kind) != 0) return -1;
    for (int t = 0; t < threads; t++) {
        const jd_pair_part *p = &lists->parts[t];
        if (!p->n) continue; /* its arrays may not exist yet */
        memcpy(l->i + l->n, p->i, p->n * sizeof *l->i);
        memcpy(l->j + l->n, p->j, p->n * sizeof *l->j);
        l->n += p->n;
    }
    return 0;
}

void sim_neighbour_parts_free(jd_neighbour_lists *lists) {
    for (int t = 0; t < lists->n_parts; t++) {
        free(lists->parts[t].i);
        free(lists->parts[t].j);
    }
    free(lists->parts);
    lists->parts = NULL;
    lists->n_parts = 0;
}

/* The pairs within their half skins, from the cell grid (lists' cell arrays), into l, on `threads`
 * threads (build_in_parts); step: for a message; sorted: the particles are numbered in the
 * grid's cell order (sort_into_cells). */
static int build_pair_list_cells(const jd_particles *ps, jd_neighbour_lists *lists, unsigned kind,
                                 int sorted, int threads, int64_t step, jd_contact_list *l,
                                 char *err, size_t errlen) {
    if (ps->n < 2) return 0;
    double h, lo[3];
    cell_search g = {.ps = ps, .lists = lists, .sorted = sorted};
    if (cell_grid(ps, lists->half_skin, 0.0, step, &h, lo, g.nc, err, errlen) != 0) return -1;
    cell_axes(g.nc, g.ax);
    if (bin_particles(lists, ps, h, lo, g.nc, g.ax) != 0 ||
        build_in_parts(lists, ps->n, threads, pairs_of, &g, kind, l) != 0) {
        snprintf(err, errlen, "out of memory building the neighbour list (%zu pairs)", l->n);
        return -1;
    }
    return 0;
}

static int build_pair_list_all(size_t n, unsigned kind, jd_contact_list *l) {
    for (size_t i = 0; i < n; i++)
        for (size_t j = i + 1; j < n; j++)
            if (list_push(l, (int32_t)i, (int32_t)j, kind) != 0) return -1;
    return 0;
}

/* The distance from x to the nearest face of the domain [lo, hi) [m] (0 outside). */
static double domain_clearance(const double lo[3], const double hi[3], const double *x) {
    double d = INFINITY;
    for (int k = 0; k < 3; k++) {
        const double a = x[k] - lo[k], b = hi[k] - x[k];
        d = a < d ? a : d;
        d = b < d ? b : d;
    }
    return d > 0.0 ? d : 0.0;
}

/* A particle's half skin for the lists about to be built: skin/2, or, for a particle that
 * would cross that in fewer than skin_steps steps at its speed now, the distance it crosses in
 * skin_steps steps, up to its radius and, with a domain, up to its distance from the domain's
 * faces.  A particle triggers the next build when it has moved its own half skin (integrate.c),
 * and a pair is a candidate while its gap is within the sum of the two half skins, so no
 * contact is missed; a falling stream no longer rebuilds every list every few steps, and a bed
 * at rest keeps its short list (docs/performance.md).  The domain's bound keeps the deletions
 * where they were with one skin (stepper/domain.c deletes at builds): a fast particle that
 * leaves across a face triggers a build at the step its centre crosses it. */
static double half_skin_of(const jd_neighbour_lists *lists, const jd_particles *ps,
                           const jd_scene *sc, double dt, size_t i) {
    const double h0 = 0.5 * lists->skin, reach = (double)lists->skin_steps * dt;
    const double *v = ps->v + 3 * i;
    double h = reach * sqrt(jd_dot(v, v));
    h = h < ps->radius[i] ? h : ps->radius[i];
    if (sc->has_domain && h > h0) {
        const double c = domain_clearance(sc->domain_lo, sc->domain_hi, ps->x + 3 * i);
        h = h < c ? h : c;
    }
    return h > h0 ? h : h0; /* never below skin/2 (integrate.c's fast check) */
}

/* Partial builds.  A particle is searched again when it has moved more than this fraction of
 * its half skin since its last search (the one that triggered the build has moved all of it);
 * the others keep their entries. */
#define JD_MOVED_FRACTION 0.25
/* A build is full when more than n / JD_PARTIAL_LIMIT particles moved, and every
 * JD_FULL_BUILD_EVERY-th build: the particles renumbered in cell order again, and the entries
 * of pairs that drifted apart dropped (docs/performance.md, "Partial neighbour builds"). */
#define JD_PARTIAL_LIMIT 2
#define JD_FULL_BUILD_EVERY 16

/* Whether some wall has moved further than sqrt(lim2) [m] since the last full build. */
static int walls_moved_beyond(const jd_walls *walls, double lim2) {
    for (size_t w = 0; w < walls->n; w++)
        if (jd_dot(walls->wall[w].disp, walls->wall[w].disp) > lim2) return 1;
    return 0;
}

/* Whether this build may be partial: nothing renumbered or deleted since the last one, no wall
 * moved since the last full build (a kept wall candidate's margin covers the wall's travel only
 * from where it was then), no mesh walls (their candidates are searched for every
 * particle), and not a build due to be full. */
static int partial_allowed(const jd_sim *s) {
    return s->lists.n_builds % JD_FULL_BUILD_EVERY != 0 && !s->lists.renumbered && !s->meshes &&
           s->particles.n >= s->lists.n_built && !walls_moved_beyond(&s->walls, 0.0);
}

/* Mark the particles that moved more than JD_MOVED_FRACTION of their half skin since their last
 * search, and those inserted since the last build (lists->moved, in_moved); their count.
 * *kept_drift: the largest displacement of the others [m], the drift bound they carry on. */
static size_t mark_moved(jd_neighbour_lists *lists, const jd_particles *ps, double *kept_drift) {
    size_t m = 0;
    double d2max = 0.0;
    for (size_t i = 0; i < ps->n; i++) {
        int moved = 1;
        if (i < lists->n_built) {
            const double *x = ps->x + 3 * i, *x0 = lists->x_build + 3 * i;
            const double d0 = x[0] - x0[0], d1 = x[1] - x0[1], d2 = x[2] - x0[2];
            const double r2 = d0 * d0 + d1 * d1 + d2 * d2, lim = JD_MOVED_FRACTION * lists->half_skin[i];
            moved = r2 > lim * lim;
            if (!moved && r2 > d2max) d2max = r2;
        }
        lists->in_moved[i] = (uint8_t)moved;
        if (moved) lists->moved[m++] = (int32_t)i;
    }
    *kept_drift = sqrt(d2max);
    return m;
}

/* What a partial build searches: the grid, and the particles that moved. */
typedef struct moved_search {
    cell_search g; /* binned in index order (items), not renumbered */
    const int32_t *moved;
    const uint8_t *in_moved;
    double drift;  /* the largest distance of a kept particle from its reference position [m] */
} moved_search;

/* The pairs of moved particle moved[k] with every particle within their half skins, into part
 * p as (lower index, higher): against an unmoved partner always, its range grown by the kept
 * particles' drift (it may still move its half skin from its reference position), against a
 * moved one only from the lower index, so that each pair comes once.  The 27 cells around its
 * own (the grid's cells are grown by the drift too), all partners. */
static int pairs_of_moved(const void *ctx, size_t k, jd_pair_part *p) {
    const moved_search *q = ctx;
    const double *x = q->g.ps->x, *rad = q->g.ps->radius, *hs = q->g.lists->half_skin;
    const int32_t *items = q->g.lists->cell_items;
    const size_t i = (size_t)q->moved[k];
    int32_t lo[9], hi[9];
    const int runs = cell_runs(&q->g, i, lo, hi);
    for (int r = 0; r < runs; r++) {
        for (int32_t e = lo[r]; e < hi[r]; e++) {
            const size_t j = (size_t)items[e];
            if (j == i || (q->in_moved[j] && j < i)) continue;
            const double d0 = x[3 * j] - x[3 * i], d1 = x[3 * j + 1] - x[3 * i + 1],
                         d2 = x[3 * j + 2] - x[3 * i + 2];
            const double range = (rad[i] + rad[j]) + (hs[i] + hs[j]) + (q->in_moved[j] ? 0.0 : q->drift);
            if (!(d0 * d0 + d1 * d1 + d2 * d2 < range * range)) continue;
            if (part_room(p) != 0) return -1;
            p->i[p->n] = (int32_t)(i < j ? i : j);
            p->j[p->n++] = (int32_t)(i < j ? j : i);
        }
    }
    return 0;
}

/* The wall candidates of moved particle moved[k] (walls_of). */
typedef struct moved_walls {
    wall_search ws;
    const int32_t *moved;
} moved_walls;

static int walls_of_moved(const void *ctx, size_t k, jd_pair_part *p) {
    const moved_walls *q = ctx;
    return walls_of(&q->ws, (size_t)q->moved[k], p);
}

static int key_cmp(const void *a, const void *b) {
    const int64_t x = *(const int64_t *)a, y = *(const int64_t *)b;
    return (x > y) - (x < y);
}

/* The parts (run_parts) as sorted keys in lists->keys; their count, or -1 out of memory. */
static ptrdiff_t sorted_part_keys(jd_neighbour_lists *lists, int threads) {
    size_t total = 0;
    for (int t = 0; t < threads; t++) total += lists->parts[t].n;
    if (total > lists->keys_cap) {
        int64_t *k = realloc(lists->keys, (total + total / 2) * sizeof *k);
        if (!k) return -1;
        lists->keys = k;
        lists->keys_cap = total + total / 2;
    }
    size_t n = 0;
    for (int t = 0; t < threads; t++)
        for (size_t e = 0; e < lists->parts[t].n; e++)
            lists->keys[n++] = pair_key(lists->parts[t].i[e], lists->parts[t].j[e]);
    if (n > 1) qsort(lists->keys, n, sizeof *lists->keys, key_cmp); /* keys is NULL while empty */
    return (ptrdiff_t)n;
}

/* The first entry at or after c of old's run [c, end) that no moved particle is in (`pairs`: j
 * is a particle too), or end. */
static size_t next_kept(const jd_contact_list *old, size_t c, size_t end, const uint8_t *in_moved,
                        int pairs) {
    while (c < end && (in_moved[old->i[c]] || (pairs && in_moved[old->j[c]]))) c++;
    return c;
}

/* Into nw (empty, one sorted run): old's entries that no moved particle is in (its two sorted
 * runs) merged with the nkeys new ones (sorted keys).  0 or -1 out of memory. */
static int merge_kept(const jd_contact_list *old, const uint8_t *in_moved, int pairs,
                      const int64_t *keys, size_t nkeys, unsigned kind, jd_contact_list *nw) {
    if (sim_list_reserve(nw, old->n + nkeys, kind) != 0) return -1;
    size_t a = next_kept(old, 0, old->n_touch, in_moved, pairs);
    size_t b = next_kept(old, old->n_touch, old->n, in_moved, pairs);
    size_t k = 0, n = 0;
    while (a < old->n_touch || b < old->n || k < nkeys) {
        const int64_t ka = a < old->n_touch ? entry_key(old, a) : INT64_MAX;
        const int64_t kb = b < old->n ? entry_key(old, b) : INT64_MAX;
        const int64_t kk = k < nkeys ? keys[k] : INT64_MAX;
        const int64_t m = ka < kb ? (ka < kk ? ka : kk) : (kb < kk ? kb : kk);
        nw->i[n] = (int32_t)(m >> 32);
        nw->j[n++] = (int32_t)(uint32_t)(m & 0xffffffff);
        if (m == ka) a = next_kept(old, a + 1, old->n_touch, in_moved, pairs);
        else if (m == kb) b = next_kept(old, b + 1, old->n, in_moved, pairs);
        else k++;
    }
    nw->n = n;
    nw->n_touch = n;
    return 0;
}

/* The new pair list (nw, one sorted run) of a partial build: the moved particles' pairs searched
 * on the grid, the others' kept. */
static int partial_pair_list(jd_sim *s, size_t m, double kept_drift, unsigned kind,
                             jd_contact_list *nw, char *err, size_t errlen) {
    jd_neighbour_lists *lists = &s->lists;
    const jd_particles *ps = &s->particles;
    moved_search q = {.g = {.ps = ps, .lists = lists, .sorted = 0}, .moved = lists->moved,
                      .in_moved = lists->in_moved, .drift = kept_drift};
    double h, lo[3];
    if (cell_grid(ps, lists->half_skin, q.drift, s->step, &h, lo, q.g.nc, err, errlen) != 0) return -1;
    cell_axes(q.g.nc, q.g.ax);
    ptrdiff_t nkeys = -1;
    if (bin_particles(lists, ps, h, lo, q.g.nc, q.g.ax) == 0 &&
        run_parts(lists, m, s->threads.n, pairs_of_moved, &q) == 0)
        nkeys = sorted_part_keys(lists, s->threads.n);
    if (nkeys < 0 || merge_kept(&lists->pairs, lists->in_moved, 1, lists->keys, (size_t)nkeys, kind, nw) != 0) {
        snprintf(err, errlen, "out of memory building the neighbour list (%zu pairs)", lists->pairs.n);
        return -1;
    }
    return 0;
}

/* The new wall list (wn, one sorted run) of a partial build: the moved particles' candidates
 * searched (ws), the others' kept. */
static int partial_wall_list(jd_sim *s, const wall_search *ws, size_t m, unsigned kind,
                             jd_contact_list *wn) {
    jd_neighbour_lists *lists = &s->lists;
    const moved_walls q = {.ws = *ws, .moved = lists->moved};
    if (run_parts(lists, m, s->threads.n, walls_of_moved, &q) != 0) return -1;
    const ptrdiff_t nkeys = sorted_part_keys(lists, s->threads.n);
    return nkeys < 0 ? -1 : merge_kept(&lists->wall_pairs, lists->in_moved, 0, lists->keys,
                                       (size_t)nkeys, kind, wn);
}

/* Build a new list into `spare`, carry the history over, swap.  The spares keep their buffers
 * between builds, and the pair spare is reserved at once for the last list and an eighth more,
 * so a build reallocates only when the list grows by more than that.  Partial when
 * partial_allowed and at most n / JD_PARTIAL_LIMIT particles moved; a full build renews every
 * half skin and reference position.  The all-pairs reference keeps the same half skins,
 * reference positions and build steps, with every pair. */
int sim_neighbour_build(jd_sim *s, char *err, size_t errlen) {
    jd_neighbour_lists *lists = &s->lists;
    jd_particles *ps = &s->particles;
    double kept_drift = 0.0;
    size_t m = ps->n; /* the particles searched again (and given new half skins): all, if full */
    const int may = partial_allowed(s);
    const size_t n_moved = may ? mark_moved(lists, ps, &kept_drift) : ps->n;
    const int partial = may && n_moved <= ps->n / JD_PARTIAL_LIMIT;
    if (partial)
        m = n_moved;
    else
        kept_drift = 0.0;
    for (size_t k = 0; k < m; k++) {
        const size_t i = partial ? (size_t)lists->moved[k] : k;
        lists->half_skin[i] = half_skin_of(lists, ps, s->run.scene, s->run.dt, i);
    }
    const int sorted = !partial && !s->opt.allpairs && !s->opt.no_sort && ps->n > 1;
    if (sorted && sort_into_cells(s, err, errlen) != 0) return -1;
    const unsigned kind = sim_list_kind(s->run.features);
    jd_contact_list *nw = &lists->spare;
    nw->n = 0;
    if (sim_list_reserve(nw, lists->pairs.n + lists->pairs.n / 8 + 1, kind) != 0) {
        snprintf(err, errlen, "out of memory building the neighbour list (%zu pairs)", lists->pairs.n);
        return -1;
    }
    if (s->opt.allpairs) {
        if (build_pair_list_all(ps->n, kind, nw) != 0) {
            snprintf(err, errlen, "out of memory building the all-pairs list (%zu particles)", ps->n);
            return -1;
        }
    } else if (partial ? partial_pair_list(s, m, kept_drift, kind, nw, err, errlen) != 0
                       : build_pair_list_cells(ps, lists, kind, sorted, s->threads.n, s->step, nw,
                                               err, errlen) != 0) {
        return -1;
    }
    nw->n_touch = nw->n;
    carry_over(&s->accounts, &lists->pairs, nw);
    /* the old list's buffers take the new list, split */
    if (split_touching(ps, kind, nw, &lists->pairs) != 0) {
        snprintf(err, errlen, "out of memory building the neighbour list (%zu pairs)", nw->n);
        return -1;
    }
    list_fit(&lists->pairs);
    list_fit(nw);

    jd_contact_list *wn = &lists->wall_spare;
    wn->n = 0;
    const wall_search ws = {.ps = ps, .walls = &s->walls, .lists = lists, .allpairs = s->opt.allpairs};
    if (s->walls.n &&
        (partial ? partial_wall_list(s, &ws, m, kind, wn)
                 : build_in_parts(lists, ps->n, s->threads.n, walls_of, &ws, kind, wn)) != 0) {
        snprintf(err, errlen, "out of memory building the wall candidate list");
        return -1;
    }
    wn->n_touch = wn->n;
    carry_over(&s->accounts, &lists->wall_pairs, wn);
    const jd_contact_list t = lists->wall_pairs;
    lists->wall_pairs = *wn;
    *wn = t;
    list_fit(&lists->wall_pairs);
    list_fit(wn);

    if (sim_forces_partition(&s->threads, lists, ps->n) != 0) {
        snprintf(err, errlen, "out of memory for the force buffers of %d threads", s->threads.n);
        return -1;
    }
    if (sim_walls_reserve(&s->walls, lists->wall_pairs.n, err, errlen) != 0) return -1;
    if (partial) {
        for (size_t k = 0; k < m; k++) {
            const size_t i = (size_t)lists->moved[k];
            memcpy(lists->x_build + 3 * i, ps->x + 3 * i, 3 * sizeof *ps->x);
        }
    } else {
        memcpy(lists->x_build, ps->x, 3 * ps->n * sizeof *ps->x);
        for (size_t w = 0; w < s->walls.n; w++) memset(s->walls.wall[w].disp, 0, sizeof s->walls.wall[w].disp);
    }
    lists->drift_bound = kept_drift;
    lists->n_built = ps->n;
    lists->renumbered = 0;
    lists->n_partial += partial;
    lists->n_builds++;
    return 0;
}

int sim_neighbour_walls_moved(const jd_walls *walls, double skin) {
    return walls_moved_beyond(walls, 0.25 * skin * skin); /* (skin/2)^2 */
}
