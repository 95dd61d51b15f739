/*
 * scene_particles.c — the particles section, the per-particle arrays (also filled by the
 * generators), their sort by id with the duplicate-id check, and the start-overlap checks
 * (particle against particle, particle against wall).
 */
#include <stdlib.h>
#include <string.h>

#include "jdem_geometry.h"
#include "scene_internal.h"

/* Relative tolerance of docs/scenes.md: initial overlap, fraction of the smaller radius. */
#define OVERLAP_TOL 1e-6

static const char *const PARTICLE_KEYS[] = {"id", "material", "radius", "position", "velocity",
                                            "angular_velocity", "fixed", "force", "settled",
                                            NULL};
static const char *const BOOLEANS[] = {"false", "true", NULL};

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
        if (!q) return sd_no_memory(&L->c, L->root, NULL);            \
        (p) = q;                                                      \
    } while (0)
    GROW(s->id, 1);
    GROW(s->material, 1);
    GROW(s->radius, 1);
    GROW(s->position, 3);
    GROW(s->velocity, 3);
    GROW(s->angular_velocity, 3);
    GROW(s->fixed, 1);
    GROW(s->settled, 1);
    GROW(s->force, 3);
    GROW(L->pnode, 1);
    GROW(L->psrc, 1);
#undef GROW
    L->cap = cap;
    return 0;
}

/* Append a particle with zero velocities; returns its index or -1. */
long scene_add_particle(loader *L, const yaml_node_t *node, int32_t src) {
    jd_scene *s = L->s;
    if (s->n_particles >= MAX_PARTICLES)
        return sd_fail(&L->c, node, "particles", "more than %d particles; valid: fewer",
                       MAX_PARTICLES);
    if (grow_particles(L, s->n_particles + 1)) return -1;
    size_t i = s->n_particles++;
    memset(&s->velocity[3 * i], 0, 3 * sizeof(double));
    memset(&s->angular_velocity[3 * i], 0, 3 * sizeof(double));
    memset(&s->force[3 * i], 0, 3 * sizeof(double));
    s->fixed[i] = 0;
    s->settled[i] = 0;
    L->pnode[i] = node;
    L->psrc[i] = src;
    return (long)i;
}

static int particle_material(loader *L, const yaml_node_t *map, const char *path, int *mat) {
    if (scene_req_material(L, map, path, mat)) return -1;
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
    long i = scene_add_particle(L, p, (int32_t)index);
    if (i < 0) return -1;
    int mat;
    s->id[i] = (int64_t)index + 1;
    if (scene_opt_int(L, p, path, "id", 1, &s->id[i]) || particle_material(L, p, path, &mat) ||
        sd_req_num(&L->c, p, path, "radius", SD_POSITIVE, &s->radius[i]) ||
        sd_req_vec3(&L->c, p, path, "position", &s->position[3 * i]) ||
        sd_opt_vec3(&L->c, p, path, "velocity", &s->velocity[3 * i]) ||
        sd_opt_vec3(&L->c, p, path, "angular_velocity", &s->angular_velocity[3 * i]) ||
        sd_opt_vec3(&L->c, p, path, "force", &s->force[3 * i]))
        return -1;
    int fixed = 0, settled = 0;
    if (sd_opt_enum(&L->c, p, path, "fixed", BOOLEANS, &fixed) ||
        sd_opt_enum(&L->c, p, path, "settled", BOOLEANS, &settled))
        return -1;
    s->fixed[i] = (unsigned char)fixed;
    s->settled[i] = (unsigned char)settled;
    s->has_loads |= fixed || s->force[3 * i] != 0.0 || s->force[3 * i + 1] != 0.0 ||
                    s->force[3 * i + 2] != 0.0;
    s->material[i] = mat;
    return 0;
}

int scene_read_particles(loader *L) {
    const yaml_node_t *list = sd_get(&L->c, L->root, "particles");
    if (!list) return 0;
    if (sd_sequence(&L->c, list, "particles", "a list of {id, material, radius, position, ...}"))
        return -1;
    for (size_t i = 0; i < sd_len(list); i++)
        if (read_particle(L, sd_item(&L->c, list, i), i)) return -1;
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
    else if (PSRC_IS_DEPOSIT(L->psrc[i]))
        sd_join_index(out, "particles_from", (size_t)(L->psrc[i] - INT32_MIN));
    else
        snprintf(out, SD_PATH_MAX, "generate.%d.lattice", -L->psrc[i] - 1);
}

/* Reorder every per-particle array by perm (new i <- old perm[i]). */
static int permute(loader *L, const id_index *perm) {
    jd_scene *s = L->s;
    size_t n = s->n_particles;
    void *tmp = malloc(n * 3 * sizeof(double));
    if (!tmp) return sd_no_memory(&L->c, L->root, NULL);
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
    PERMUTE(s->fixed, 1);
    PERMUTE(s->settled, 1);
    PERMUTE(s->force, 3);
    PERMUTE(L->pnode, 1);
    PERMUTE(L->psrc, 1);
#undef PERMUTE
    free(tmp);
    return 0;
}

int scene_sort_particles(loader *L) {
    size_t n = L->s->n_particles;
    id_index *perm = malloc(n * sizeof *perm);
    if (!perm) return sd_no_memory(&L->c, L->root, NULL);
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

/* The start overlap allowed between particles i and j, a fraction of the smaller radius: two
 * particles of a settled deposit keep their contacts, up to the watchdog's limit. */
static double overlap_tolerance(const jd_scene *s, size_t i, size_t j) {
    return s->settled[i] && s->settled[j] ? s->watchdog.max_overlap_fraction : OVERLAP_TOL;
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
                    if (j > i && ov > overlap_tolerance(s, i, j) * rmin && (!found || j < found)) {
                        found = j;
                        *by = ov;
                    }
                }
            }
    return found;
}

int scene_check_overlaps(loader *L) {
    const jd_scene *s = L->s;
    grid g;
    if (s->n_particles < 2) return 0;
    if (build_grid(s, &g)) return sd_no_memory(&L->c, L->root, NULL);
    int rc = 0;
    for (size_t i = 0; i < s->n_particles && rc == 0; i++) {
        double by = 0.0;
        size_t j = overlapping(s, &g, i, &by);
        if (!j) continue;
        char path[SD_PATH_MAX];
        particle_path(L, j, path);
        rc = sd_fail(&L->c, L->pnode[j], path, "particles %lld and %lld overlap by %.3g m at the "
                     "start; valid: an overlap of at most %g of the smaller radius%s",
                     (long long)s->id[i], (long long)s->id[j], by, overlap_tolerance(s, i, j),
                     s->settled[i] && s->settled[j] ? " (watchdog.max_overlap_fraction, for two "
                     "particles of a settled deposit)" : "");
    }
    free(g.e);
    return rc;
}

/* Overlap [m] of particle i with wall w at the start (kernel geometry, as the engines see it),
 * 0 without contact. */
static double wall_overlap(const jd_scene *s, size_t i, const jd_wall *w) {
    jd_contact_geom g;
    const double *x = &s->position[3 * i];
    if (w->type == JD_WALL_PLANE) {
        jd_plane p;
        if (jd_plane_init(&p, w->corners, 1e-6) != JD_GEOM_OK) return 0.0; /* checked already */
        return jd_geom_plane(&p, x, s->radius[i], &g) ? g.delta : 0.0;
    }
    jd_cylinder c = {.rc = w->radius, .inside = w->inside};
    memcpy(c.a0, w->axis[0], sizeof c.a0);
    memcpy(c.a1, w->axis[1], sizeof c.a1);
    return jd_geom_cylinder(&c, x, s->radius[i], &g) ? g.delta : 0.0;
}

/* A settled particle keeps its contact with the walls it rested on, up to the watchdog's limit. */
static double wall_overlap_tolerance(const jd_scene *s, size_t i) {
    return s->settled[i] ? s->watchdog.max_overlap_fraction : OVERLAP_TOL;
}

int scene_check_wall_overlaps(loader *L) {
    const jd_scene *s = L->s;
    for (size_t i = 0; i < s->n_particles; i++)
        for (size_t k = 0; k < s->n_walls; k++) {
            const double by = wall_overlap(s, i, &s->walls[k]);
            if (!(by > wall_overlap_tolerance(s, i) * s->radius[i])) continue;
            char path[SD_PATH_MAX];
            particle_path(L, i, path);
            return sd_fail(&L->c, L->pnode[i], path, "particle %lld overlaps wall '%s' by %.3g m "
                           "at the start; valid: an overlap of at most %g of its radius%s",
                           (long long)s->id[i], s->walls[k].name, by, wall_overlap_tolerance(s, i),
                           s->settled[i] ? " (watchdog.max_overlap_fraction, for a particle of a "
                           "settled deposit)" : "");
        }
    return 0;
}
