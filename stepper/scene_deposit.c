/*
 * scene_deposit.c — the particles_from section (docs/scenes.md "particles_from"): the particles
 * of one frame of an H5MD trajectory, optionally only those whose centre lies in a region, moved
 * by a translation, and the bonds intact between them.  They become ordinary particles and bonds
 * of the resolved scene, so `jdem resolve` (and the LIGGGHTS deck made from it) lists them
 * explicitly.
 *
 * The region messages use the wording and number format of scripts/mixing/deposit.py (Python's
 * repr of a float), so that a cut refused by the generators and by the engines reads the same.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "scene_deposit.h"
#include "scene_internal.h"

static const char *const ENTRY_KEYS[] = {"file", "frame", "region", "dilate", "translate",
                                         "velocities", "ids", "bonds", NULL};
/* A dilation spreads a cut that was under the deposit's pressure until its overlaps are gone;
 * past 2 the cut is no longer the packing it was taken from. */
static const sd_range DILATION = {1.0, 2.0, 0, 0};
static const char *const REGION_KEYS[] = {"lo", "hi", NULL};
static const char *const VELOCITIES[] = {"zero", "keep", NULL};
static const char *const IDS[] = {"keep", "renumber", NULL};
static const char *const BONDS[] = {"keep", "none", NULL};

/* x as Python's repr(float) writes it: the shortest digits that read back as x, in fixed
 * notation for decimal exponents -4 to 15 (with ".0" if integral), else d.ddde+XX. */
static void py_float(double x, char *out, size_t len) {
    if (!isfinite(x)) {
        snprintf(out, len, "%s", isnan(x) ? "nan" : x > 0 ? "inf" : "-inf");
        return;
    }
    char buf[40];
    for (int p = 0; p < 17; p++) {
        snprintf(buf, sizeof buf, "%.*e", p, x);
        if (strtod(buf, NULL) == x) break;
    }
    const char *s = buf + (buf[0] == '-');
    char digits[24];
    int nd = 0;
    for (; *s != 'e'; s++)
        if (*s != '.') digits[nd++] = *s;
    while (nd > 1 && digits[nd - 1] == '0') nd--;
    digits[nd] = '\0';
    const int exp = atoi(s + 1);
    char fixed[64];
    size_t o = 0;
    if (signbit(x)) fixed[o++] = '-';
    if (exp < -4 || exp >= 16) {
        snprintf(fixed + o, sizeof fixed - o, "%c%s%se%c%02d", digits[0], nd > 1 ? "." : "",
                 digits + 1, exp < 0 ? '-' : '+', abs(exp));
    } else {
        int pos = 0; /* index into digits of the next digit to write */
        if (exp < 0) {
            fixed[o++] = '0';
            fixed[o++] = '.';
            for (int z = 0; z < -exp - 1; z++) fixed[o++] = '0';
        } else {
            for (int k = 0; k <= exp; k++) fixed[o++] = pos < nd ? digits[pos++] : '0';
            fixed[o++] = '.';
            if (pos >= nd) fixed[o++] = '0';
        }
        while (pos < nd) fixed[o++] = digits[pos++];
        fixed[o] = '\0';
    }
    snprintf(out, len, "%s", fixed);
}

/* A vector as Python's list repr: "[a, b, c]". */
static void py_list(const double v[3], char *out, size_t len) {
    char a[32], b[32], c[32];
    py_float(v[0], a, sizeof a);
    py_float(v[1], b, sizeof b);
    py_float(v[2], c, sizeof c);
    snprintf(out, len, "[%s, %s, %s]", a, b, c);
}

/* numpy's round(x, 6). */
static double round6(double x) { return rint(x * 1e6) / 1e6; }

typedef struct deposit_entry {
    const yaml_node_t *map, *file_node, *frame_node, *region_node;
    char path[SD_PATH_MAX];
    char file[1024]; /* the H5MD trajectory, relative paths resolved against the scene's folder */
    int64_t frame;
    int has_region;
    double lo[3], hi[3], shift[3];
    double dilate; /* positions scaled by this about the region's centre, before the shift */
    int velocities, renumber;
    int no_bonds;  /* bonds: none (default keep: the frame's intact bonds between kept particles) */
    int section;   /* an inlet section's from_deposit, whose bonds are not carried over */
} deposit_entry;

static int read_region(loader *L, deposit_entry *d) {
    d->region_node = sd_get(&L->c, d->map, "region");
    if (!d->region_node) return 0;
    char sub[SD_PATH_MAX];
    sd_join(sub, d->path, "region");
    if (sd_mapping(&L->c, d->region_node, sub, "{lo: [x, y, z], hi: [x, y, z]}") ||
        sd_keys(&L->c, d->region_node, sub, REGION_KEYS) ||
        sd_req_vec3(&L->c, d->region_node, sub, "lo", d->lo) ||
        sd_req_vec3(&L->c, d->region_node, sub, "hi", d->hi))
        return -1;
    d->has_region = 1;
    return 0;
}

/* dilate: about the region's centre, so a region is needed. */
static int read_dilation(loader *L, deposit_entry *d) {
    const yaml_node_t *n = sd_get(&L->c, d->map, "dilate");
    if (!n) return 0;
    char sub[SD_PATH_MAX];
    sd_join(sub, d->path, "dilate");
    if (!d->has_region)
        return sd_fail(&L->c, n, sub, "a dilation needs a region (it scales the kept positions "
                       "about the region's centre); valid: add region: {lo: [x, y, z], hi: [x, y, z]}");
    return sd_num(&L->c, n, sub, DILATION, &d->dilate);
}

static int read_entry(loader *L, const yaml_node_t *map, const char *list_path, size_t k,
                      deposit_entry *d) {
    memset(d, 0, sizeof *d);
    d->map = map;
    d->frame = -1;
    d->dilate = 1.0;
    sd_join_index(d->path, list_path, k);
    if (sd_mapping(&L->c, map, d->path,
                   "{file, frame, region, dilate, translate, velocities, ids, bonds}") ||
        sd_keys(&L->c, map, d->path, ENTRY_KEYS))
        return -1;
    d->file_node = sd_get(&L->c, map, "file");
    if (!d->file_node)
        return sd_missing(&L->c, map, d->path, "file", "the path of an H5MD trajectory");
    char sub[SD_PATH_MAX];
    sd_join(sub, d->path, "file");
    if (scene_file_path(L, d->file_node, sub, "an H5MD trajectory", d->file, sizeof d->file))
        return -1;
    d->frame_node = sd_get(&L->c, map, "frame");
    return scene_opt_int(L, map, d->path, "frame", INT64_MIN + 1, &d->frame) ||
                   read_region(L, d) || read_dilation(L, d) ||
                   sd_opt_vec3(&L->c, map, d->path, "translate", d->shift) ||
                   sd_opt_enum(&L->c, map, d->path, "velocities", VELOCITIES, &d->velocities) ||
                   sd_opt_enum(&L->c, map, d->path, "ids", IDS, &d->renumber) ||
                   sd_opt_enum(&L->c, map, d->path, "bonds", BONDS, &d->no_bonds)
               ? -1
               : 0;
}

/* The checks of deposit.keep_box: lo < hi, and the region no further outside the deposit's
 * outline (centres -/+ the largest radius) than the largest radius. */
static int check_region(loader *L, const deposit_entry *d, const dep_frame *fr) {
    char sub[SD_PATH_MAX], lo[100], hi[100];
    sd_join(sub, d->path, "region");
    py_list(d->lo, lo, sizeof lo);
    py_list(d->hi, hi, sizeof hi);
    for (int a = 0; a < 3; a++)
        if (!(d->hi[a] > d->lo[a]))
            return sd_fail(&L->c, d->region_node, sub, "region %s..%s: empty; valid: lo < hi",
                           lo, hi);
    double pmin[3] = {INFINITY, INFINITY, INFINITY}, pmax[3] = {-INFINITY, -INFINITY, -INFINITY};
    double rmax = 0.0;
    for (size_t i = 0; i < fr->n; i++) {
        if (fr->id[i] < 0) continue;
        rmax = fmax(rmax, fr->radius[i]);
        for (int a = 0; a < 3; a++) {
            pmin[a] = fmin(pmin[a], fr->position[3 * i + a]);
            pmax[a] = fmax(pmax[a], fr->position[3 * i + a]);
        }
    }
    double elo[3], ehi[3];
    int outside = 0;
    for (int a = 0; a < 3; a++) {
        elo[a] = pmin[a] - rmax;
        ehi[a] = pmax[a] + rmax;
        outside |= d->lo[a] < elo[a] - rmax || d->hi[a] > ehi[a] + rmax;
    }
    if (!outside) return 0;
    double rlo[3], rhi[3];
    for (int a = 0; a < 3; a++) {
        rlo[a] = round6(elo[a]);
        rhi[a] = round6(ehi[a]);
    }
    char xlo[100], xhi[100];
    py_list(rlo, xlo, sizeof xlo);
    py_list(rhi, xhi, sizeof xhi);
    return sd_fail(&L->c, d->region_node, sub, "region %s..%s lies outside the deposit (extent "
                   "%s..%s); valid: a region inside it", lo, hi, xlo, xhi);
}

static int kept(const deposit_entry *d, const double x[3]) {
    for (int a = 0; d->has_region && a < 3; a++)
        if (!(x[a] >= d->lo[a] && x[a] < d->hi[a])) return 0;
    return 1;
}

/* This scene's material for the deposit's species sp, or -1 after reporting. */
static int deposit_material(loader *L, const deposit_entry *d, const dep_frame *fr, int32_t sp) {
    char sub[SD_PATH_MAX];
    sd_join(sub, d->path, "file");
    if (sp < 0 || (size_t)sp >= fr->n_materials)
        return sd_fail(&L->c, d->file_node, sub, "%s: species %d has no material in "
                       "/parameters/scene; valid: an H5MD trajectory written by jdem or "
                       "liggghts-jdem", d->file, (int)sp);
    const jd_scene *s = L->s;
    for (size_t m = 0; m < s->n_materials; m++)
        if (strcmp(s->materials[m].name, fr->materials[sp]) == 0) {
            if (!s->materials[m].has_elastic) break;
            L->by_particle[m] = 1;
            return (int)m;
        }
    return sd_fail(&L->c, d->file_node, sub, "%s: the deposit's material '%s' is not a particle "
                   "material of this scene; valid: a material of that name with youngs_modulus, "
                   "poisson_ratio and density in materials", d->file, fr->materials[sp]);
}

/* Add the kept particles; new_id[j] is the id slot j got (-1: not kept). */
static int add_kept(loader *L, const deposit_entry *d, const dep_frame *fr, int32_t src,
                    int64_t *next_id, int64_t *new_id) {
    jd_scene *s = L->s;
    size_t count = 0;
    for (size_t j = 0; j < fr->n; j++) {
        new_id[j] = -1;
        if (fr->id[j] < 0 || !kept(d, &fr->position[3 * j])) continue;
        int mat = deposit_material(L, d, fr, fr->species[j]);
        long i = mat < 0 ? -1 : scene_add_particle(L, d->map, src);
        if (i < 0) return -1;
        s->id[i] = d->renumber ? (*next_id)++ : fr->id[j];
        new_id[j] = s->id[i];
        s->material[i] = mat;
        s->radius[i] = fr->radius[j];
        s->settled[i] = 1;
        for (int a = 0; a < 3; a++) {
            const double centre = 0.5 * (d->lo[a] + d->hi[a]), x = fr->position[3 * j + a];
            s->position[3 * i + a] =
                (d->dilate == 1.0 ? x : centre + d->dilate * (x - centre)) + d->shift[a];
            if (d->velocities) {
                s->velocity[3 * i + a] = fr->velocity[3 * j + a];
                s->angular_velocity[3 * i + a] = fr->angular_velocity[3 * j + a];
            }
        }
        count++;
    }
    if (count) return 0;
    char sub[SD_PATH_MAX], lo[100], hi[100];
    sd_join(sub, d->path, "region");
    py_list(d->lo, lo, sizeof lo);
    py_list(d->hi, hi, sizeof hi);
    if (!d->has_region)
        return sd_fail(&L->c, d->file_node, d->path, "%s: frame %lld holds no particle; valid: "
                       "a frame with particles", d->file, (long long)d->frame);
    return sd_fail(&L->c, d->region_node, sub, "region %s..%s keeps no particle of the deposit; "
                   "valid: a region holding at least one particle centre", lo, hi);
}

/* This scene's bond type for the deposit's type t, or -1 after reporting. */
static int deposit_bond_type(loader *L, const deposit_entry *d, const dep_frame *fr, int32_t t) {
    const jd_scene *s = L->s;
    for (size_t i = 0; i < s->n_bond_types; i++)
        if (strcmp(s->bond_types[i].name, fr->bond_types[t]) == 0) return (int)i;
    char sub[SD_PATH_MAX];
    sd_join(sub, d->path, "file");
    return sd_fail(&L->c, d->file_node, sub, "%s: the deposit's bond type '%s' is not a bond type "
                   "of this scene; valid: a bond type of that name under bond_types, or bonds: "
                   "none", d->file, fr->bond_types[t]);
}

/* The bonds intact at the frame between two kept particles become explicit bonds of the scene,
 * formed at step 0 with zero force where the particles now are (the deposit's bond forces, like
 * its tangential contact history, are not carried over). */
static int add_kept_bonds(loader *L, const deposit_entry *d, const dep_frame *fr,
                          const int64_t *new_id) {
    size_t carried = 0;
    for (size_t l = 0; l < fr->n_lines; l++) {
        const int64_t a = new_id[fr->line_row[2 * l]], b = new_id[fr->line_row[2 * l + 1]];
        if (a < 0 || b < 0) continue;
        if (d->section) {
            carried++;
            continue;
        }
        const int type = deposit_bond_type(L, d, fr, fr->line_type[l]);
        if (type < 0 || scene_add_bond(L, d->map, a, b, type)) return -1;
    }
    if (!carried) return 0;
    return sd_fail(&L->c, d->map, d->path, "%s: %zu bonds intact between the kept particles, "
                   "which an inlet section does not carry over; valid: bonds: none (the section "
                   "unbonded), or the section's blocks and bonds", d->file, carried);
}

static int read_deposit(loader *L, const yaml_node_t *map, const char *list_path, size_t k,
                        int section, int64_t *next_id) {
    deposit_entry d;
    if (read_entry(L, map, list_path, k, &d)) return -1;
    d.section = section;
    dep_frame fr;
    char msg[1024];
    if (dep_read_frame(d.file, d.frame, d.velocities, !d.no_bonds, &fr, msg, sizeof msg)) {
        char sub[SD_PATH_MAX];
        int frame_error = strstr(msg, "does not exist") != NULL && d.frame_node;
        sd_join(sub, d.path, frame_error ? "frame" : "file");
        return sd_fail(&L->c, frame_error ? d.frame_node : d.file_node, sub, "%s", msg);
    }
    int64_t *new_id = malloc((fr.n ? fr.n : 1) * sizeof *new_id);
    int rc = !new_id ? sd_no_memory(&L->c, map, d.path)
                     : (d.has_region && check_region(L, &d, &fr)) ||
                           add_kept(L, &d, &fr, PSRC_DEPOSIT(k), next_id, new_id) ||
                           add_kept_bonds(L, &d, &fr, new_id);
    free(new_id);
    dep_free_frame(&fr);
    return rc ? -1 : 0;
}

int scene_read_deposit_list(loader *L, const yaml_node_t *list, const char *path, int section) {
    if (sd_sequence(&L->c, list, path, "a list of {file, frame, region, dilate, translate, "
                    "velocities, ids, bonds}"))
        return -1;
    int64_t next_id = 1;
    for (size_t i = 0; i < L->s->n_particles; i++)
        next_id = L->s->id[i] >= next_id ? L->s->id[i] + 1 : next_id;
    for (size_t k = 0; k < sd_len(list); k++)
        if (read_deposit(L, sd_item(&L->c, list, k), path, k, section, &next_id)) return -1;
    return 0;
}

int scene_read_deposits(loader *L) {
    const yaml_node_t *list = sd_get(&L->c, L->root, "particles_from");
    return list ? scene_read_deposit_list(L, list, "particles_from", 0) : 0;
}
