/*
 * scene_inlet_blocks.c — bonded blocks in an inlet's repeated section (Jiang (2021) Ch. 5: the
 * 2 x 2 x 8 blocks; docs/scenes.md "Bonded blocks in an inlet section").
 *
 *   section.blocks   lattices cut into blocks of spheres, every face neighbour inside a block
 *                    bonded; read before the section's other particles (section index 0 on)
 *   section.bonds    explicit bonds between section particles by section index (the resolved
 *                    form of blocks, also a user key)
 *
 * Both end up as one sorted list of section bonds in the jd_inlet; its connected components are
 * the groups the kernel inserts whole (kernel/jdem_inlet.h "Bonded groups of a section").  Which
 * spheres are face neighbours is decided on the integer lattice coordinates, never by comparing
 * rounded distances.
 */
#include <stdlib.h>
#include <string.h>

#include "jdem_inlet.h"
#include "scene_internal.h"

static const char *const BLOCKS_KEYS[] = {"lattice", "block", "axis", "bond_type", NULL};
static const char *const AXES[] = {"x", "y", "z", NULL};
static const char *const SECTION_BOND_KEYS[] = {"pair", "type", NULL};

/* One entry of section.blocks. */
typedef struct block_entry {
    const yaml_node_t *node; /* the entry (messages) */
    size_t from;             /* section index of its first sphere */
    int64_t counts[3];       /* lattice sites along x, y, z */
    int64_t extent[3];       /* sites of one block along x, y, z */
} block_entry;

struct section_blocks {
    size_t n;
    block_entry *entry;
    size_t n_bonds, cap;
    int32_t *pair; /* 2 n_bonds section indices */
    int32_t *type; /* n_bonds */
};

void scene_free_section_blocks(section_blocks *b) {
    if (!b) return;
    free(b->entry);
    free(b->pair);
    free(b->type);
    free(b);
}

static int add_pair(section_blocks *b, int64_t i, int64_t j, int type) {
    if (b->n_bonds == b->cap) {
        const size_t cap = b->cap ? 2 * b->cap : 256;
        int32_t *p = realloc(b->pair, 2 * cap * sizeof *p);
        if (p) b->pair = p;
        int32_t *t = realloc(b->type, cap * sizeof *t);
        if (t) b->type = t;
        if (!p || !t) return -1;
        b->cap = cap;
    }
    b->pair[2 * b->n_bonds] = (int32_t)(i < j ? i : j);
    b->pair[2 * b->n_bonds + 1] = (int32_t)(i < j ? j : i);
    b->type[b->n_bonds++] = type;
    return 0;
}

/* block: [across, across, along]: the third count runs along axis, the other two along the
 * remaining axes in x, y, z order. */
static void block_extent(const int64_t block[3], int axis, int64_t extent[3]) {
    int other = 0;
    for (int d = 0; d < 3; d++) extent[d] = d == axis ? block[2] : block[other++];
}

/* The face-neighbour bonds of a lattice cut into blocks: site s = i + nx (j + ny k) (the lattice
 * generator's order) at section index from + s, bonded to its +x, +y and +z neighbours in the
 * same block. */
static int block_bonds(section_blocks *b, const block_entry *e, int type) {
    const int64_t nx = e->counts[0], ny = e->counts[1], nz = e->counts[2];
    const int64_t step[3] = {1, nx, nx * ny};
    for (int64_t k = 0; k < nz; k++)
        for (int64_t j = 0; j < ny; j++)
            for (int64_t i = 0; i < nx; i++) {
                const int64_t at[3] = {i, j, k}, s = (int64_t)e->from + i + nx * (j + ny * k);
                for (int d = 0; d < 3; d++)
                    if (at[d] + 1 < e->counts[d] && (at[d] + 1) % e->extent[d] != 0 &&
                        add_pair(b, s, s + step[d], type))
                        return -1;
            }
    return 0;
}

static int read_block_entry(loader *L, const yaml_node_t *g, const char *path, size_t from,
                            int32_t gen, section_blocks *b, block_entry *e) {
    char sub[SD_PATH_MAX], item[SD_PATH_MAX];
    int64_t block[3], unused_id = 1; /* ids are the stream's */
    int type, axis = 2;
    e->node = g;
    e->from = from;
    if (sd_keys(&L->c, g, path, BLOCKS_KEYS)) return -1;
    const yaml_node_t *lat = sd_get(&L->c, g, "lattice");
    if (!lat)
        return sd_missing(&L->c, g, path, "lattice", "{material, radius, origin, spacing, "
                          "counts}: the lattice cut into blocks");
    sd_join(sub, path, "lattice");
    if (scene_generate_lattice(L, lat, sub, gen, e->counts, &unused_id)) return -1;
    const yaml_node_t *bl = sd_get(&L->c, g, "block");
    sd_join(sub, path, "block");
    if (!bl) return sd_missing(&L->c, g, path, "block", "[n1, n2, n_axis]: spheres of one block");
    if (bl->type != YAML_SEQUENCE_NODE || sd_len(bl) != 3)
        return sd_fail(&L->c, bl, sub, "expected three integers, got %s; valid: [n1, n2, n_axis]",
                       sd_kind(bl));
    for (size_t d = 0; d < 3; d++) {
        sd_join_index(item, sub, d);
        if (sd_int(&L->c, sd_item(&L->c, bl, d), item, 1, &block[d])) return -1;
    }
    if (sd_opt_enum(&L->c, g, path, "axis", AXES, &axis) ||
        scene_req_bond_type(L, g, path, "bond_type", &type))
        return -1;
    block_extent(block, axis, e->extent);
    for (int d = 0; d < 3; d++)
        if (e->counts[d] % e->extent[d] != 0)
            return sd_fail(&L->c, bl, sub, "a block of %lld x %lld x %lld spheres along x, y, z "
                           "(axis %s) does not tile the lattice's %lld x %lld x %lld; valid: "
                           "lattice counts that are multiples of the block's along each axis",
                           (long long)e->extent[0], (long long)e->extent[1],
                           (long long)e->extent[2], AXES[axis], (long long)e->counts[0],
                           (long long)e->counts[1], (long long)e->counts[2]);
    return block_bonds(b, e, type) ? sd_no_memory(&L->c, g, path) : 0;
}

int scene_read_section_blocks(loader *L, const yaml_node_t *sec, const char *path,
                              section_blocks **out) {
    *out = NULL;
    const yaml_node_t *list = sd_get(&L->c, sec, "blocks");
    if (!list) return 0;
    char sub[SD_PATH_MAX], item[SD_PATH_MAX];
    sd_join(sub, path, "blocks");
    if (sd_sequence(&L->c, list, sub, "a list of {lattice: {...}, block: [n1, n2, n_axis], "
                    "axis, bond_type}"))
        return -1;
    section_blocks *b = calloc(1, sizeof *b);
    if (b) b->entry = calloc(sd_len(list) ? sd_len(list) : 1, sizeof *b->entry);
    *out = b;
    if (!b || !b->entry) return sd_no_memory(&L->c, list, sub);
    const size_t section_from = L->s->n_particles;
    for (size_t k = 0; k < sd_len(list); k++) {
        sd_join_index(item, sub, k);
        b->n = k + 1;
        if (read_block_entry(L, sd_item(&L->c, list, k), item, L->s->n_particles - section_from,
                             (int32_t)k, b, &b->entry[k]))
            return -1;
    }
    return 0;
}

/* ---------------------------------------------------------------------------------------- */
/* Explicit section bonds, the merged list, the groups                                      */

static int read_section_bond(loader *L, const yaml_node_t *e, const char *path, size_t n,
                             section_blocks *b) {
    char sub[SD_PATH_MAX], item[SD_PATH_MAX];
    int type;
    if (sd_keys(&L->c, e, path, SECTION_BOND_KEYS) || scene_req_bond_type(L, e, path, "type", &type))
        return -1;
    const yaml_node_t *pr = sd_get(&L->c, e, "pair");
    sd_join(sub, path, "pair");
    if (!pr) return sd_missing(&L->c, e, path, "pair", "[i, j]: two section particle indices");
    if (pr->type != YAML_SEQUENCE_NODE || sd_len(pr) != 2)
        return sd_fail(&L->c, pr, sub, "expected two indices, got %s; valid: [i, j]", sd_kind(pr));
    int64_t p[2];
    for (size_t d = 0; d < 2; d++) {
        sd_join_index(item, sub, d);
        if (sd_int(&L->c, sd_item(&L->c, pr, d), item, 0, &p[d])) return -1;
        if (p[d] >= (int64_t)n)
            return sd_fail(&L->c, sd_item(&L->c, pr, d), item, "section particle %lld does not "
                           "exist; valid: 0 to %zu (the section's particles in order: blocks, "
                           "generate, particles, from_deposit)", (long long)p[d], n - 1);
    }
    if (p[0] == p[1])
        return sd_fail(&L->c, pr, sub, "a particle bonded to itself (%lld); valid: two different "
                       "section particles", (long long)p[0]);
    return add_pair(b, p[0], p[1], type) ? sd_no_memory(&L->c, e, path) : 0;
}

/* The connected components of the bonds (the kernel's rule, jd_inlet_groups). */
static int make_groups(jd_inlet *in) {
    int32_t *parent = malloc(in->n * sizeof *parent);
    in->group_of = malloc(in->n * sizeof *in->group_of);
    in->group_first = malloc((in->n + 1) * sizeof *in->group_first);
    in->group_member = malloc(in->n * sizeof *in->group_member);
    if (!parent || !in->group_of || !in->group_first || !in->group_member) {
        free(parent);
        return -1;
    }
    in->n_groups = jd_inlet_groups(in->n, in->n_bonds, in->bond_pair, parent, in->group_of,
                                   in->group_first, in->group_member);
    free(parent);
    return 0;
}

int scene_read_section_bonds(loader *L, const yaml_node_t *sec, const char *path, jd_inlet *in,
                             section_blocks *blocks) {
    char sub[SD_PATH_MAX], item[SD_PATH_MAX];
    section_blocks none = {0}, *b = blocks ? blocks : &none;
    const yaml_node_t *list = sd_get(&L->c, sec, "bonds");
    sd_join(sub, path, "bonds");
    int rc = 0;
    if (list && sd_sequence(&L->c, list, sub, "a list of {pair: [i, j], type: NAME}")) rc = -1;
    for (size_t k = 0; rc == 0 && list && k < sd_len(list); k++) {
        sd_join_index(item, sub, k);
        rc = read_section_bond(L, sd_item(&L->c, list, k), item, in->n, b);
    }
    const size_t n = b->n_bonds;
    if (rc == 0 && n && (!(in->bond_pair = malloc(2 * n * sizeof *in->bond_pair)) ||
                         !(in->bond_type = malloc(n * sizeof *in->bond_type))))
        rc = sd_no_memory(&L->c, sec, path);
    if (rc == 0 && n) {
        memcpy(in->bond_pair, b->pair, 2 * n * sizeof *in->bond_pair);
        memcpy(in->bond_type, b->type, n * sizeof *in->bond_type);
        const size_t k = jd_inlet_sort_bonds(n, in->bond_pair, in->bond_type);
        if (k < n)
            rc = sd_fail(&L->c, list ? list : sec, list ? sub : path, "section particles %d "
                         "and %d are bonded twice; valid: at most one bond per pair",
                         in->bond_pair[2 * k], in->bond_pair[2 * k + 1]);
        in->n_bonds = n;
        if (rc == 0 && make_groups(in)) rc = sd_no_memory(&L->c, sec, path);
    }
    if (b == &none) {
        free(none.pair);
        free(none.type);
    }
    return rc;
}

/* ---------------------------------------------------------------------------------------- */
/* The blocks' fit in the section                                                            */

/* Section index of sphere m (0-based, lattice order within its block) of block q of entry e. */
static size_t block_member(const block_entry *e, int64_t q, int64_t m) {
    const int64_t bx = e->counts[0] / e->extent[0], by = e->counts[1] / e->extent[1];
    const int64_t corner[3] = {q % bx * e->extent[0], q / bx % by * e->extent[1],
                               q / (bx * by) * e->extent[2]};
    const int64_t i = corner[0] + m % e->extent[0], j = corner[1] + m / e->extent[0] % e->extent[1],
                  k = corner[2] + m / (e->extent[0] * e->extent[1]);
    return e->from + (size_t)(i + e->counts[0] * (j + e->counts[1] * k));
}

/* A block overlaps a section particle outside it, or is longer along the belt than the period
 * (the same tolerance as the kernel's overlap check: tol of the smaller radius). */
static int check_block(loader *L, const jd_inlet *in, const block_entry *e, const char *path,
                       int64_t q, double tol, const double u[3], int periodic) {
    const int64_t members = e->extent[0] * e->extent[1] * e->extent[2];
    const size_t first = block_member(e, q, 0), last = block_member(e, q, members - 1);
    double lo = INFINITY, hi = -INFINITY, rmin = INFINITY;
    for (int64_t m = 0; m < members; m++) {
        const size_t p = block_member(e, q, m);
        const double *x = &in->rel[3 * p], r = in->radius[p];
        for (size_t o = 0; o < in->n; o++) {
            const int same_group = in->group_of && in->group_of[p] >= 0 &&
                                   in->group_of[o] == in->group_of[p];
            if (o == p || same_group) continue;
            double d[3];
            sub3(&in->rel[3 * o], x, d);
            const double ov = r + in->radius[o] - norm3(d);
            if (ov > tol * fmin(r, in->radius[o]))
                return sd_fail(&L->c, e->node, path, "block %lld (section particles %zu to %zu) "
                               "overlaps section particle %zu by %.6g m (its sphere %zu); valid: "
                               "blocks clear of the section's other particles",
                               (long long)q, first, last, o, ov, p);
        }
        lo = fmin(lo, jd_dot(u, x) - r);
        hi = fmax(hi, jd_dot(u, x) + r);
        rmin = fmin(rmin, r);
    }
    if (periodic && hi - lo > in->period + tol * rmin)
        return sd_fail(&L->c, e->node, path, "block %lld (section particles %zu to %zu) is "
                       "%.6g m long along the belt, longer than the period %.6g m; valid: blocks "
                       "that fit in one period (a longer period, or a block shorter along the belt)",
                       (long long)q, first, last, hi - lo, in->period);
    return 0;
}

int scene_check_section_blocks(loader *L, const char *path, const jd_inlet *in,
                               const section_blocks *b) {
    if (!b) return 0;
    const double speed = norm3(in->velocity);
    if (!(speed > 0.0)) return 0; /* the kernel's check names the belt */
    const double u[3] = {in->velocity[0] / speed, in->velocity[1] / speed, in->velocity[2] / speed};
    const double tol = in->settled ? L->s->watchdog.max_overlap_fraction : JD_INLET_OVERLAP_TOL;
    const int periodic = !(in->stop == JD_INLET_STOP_SECTIONS && in->sections == 1);
    for (size_t k = 0; k < b->n; k++) {
        const block_entry *e = &b->entry[k];
        char sub[SD_PATH_MAX];
        snprintf(sub, sizeof sub, "%s.section.blocks.%zu", path, k);
        const int64_t blocks = e->counts[0] / e->extent[0] * (e->counts[1] / e->extent[1]) *
                               (e->counts[2] / e->extent[2]);
        for (int64_t q = 0; q < blocks; q++)
            if (check_block(L, in, e, sub, q, tol, u, periodic)) return -1;
    }
    return 0;
}
