/*
 * scene_deposit_h5md.c — one frame of an H5MD trajectory written by either engine (io/h5md.h),
 * read with HDF5's C library for the scene's particles_from (scene_deposit.c).
 *
 * The per-particle fields are /particles/all/NAME, either time-independent datasets [N] (or
 * [N][3]) or H5MD time series NAME/value [F][N] (or [F][N][3]); a slot whose id is -1 is empty (a
 * changing particle set) and is skipped by the caller.  The species are indices into the
 * materials of the scene stored as /parameters/scene, whose names the frame carries; so are the
 * bond types of the bonds intact at the frame, read when asked for.
 */
#include <hdf5.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <yaml.h>

#include "scene_deposit.h"

#define VALID_H5MD "valid: an H5MD trajectory written by jdem or liggghts-jdem"

/* Read NAME under group ALL at FRAME into out (n x width values of memtype); 0 or -1. */
static int read_field(hid_t all, const char *name, hsize_t frame, hid_t memtype, size_t width,
                      size_t n, void *out) {
    H5O_info_t info;
    if (H5Lexists(all, name, H5P_DEFAULT) <= 0 ||
        H5Oget_info_by_name(all, name, &info, H5P_DEFAULT) < 0)
        return -1;
    int series = info.type == H5O_TYPE_GROUP;
    char path[128];
    snprintf(path, sizeof path, series ? "%s/value" : "%s", name);
    hid_t d = H5Dopen2(all, path, H5P_DEFAULT);
    if (d < 0) return -1;
    hid_t fs = H5Dget_space(d);
    int rank = H5Sget_simple_extent_ndims(fs);
    hsize_t dims[3] = {0, 0, 0};
    int want = (series ? 2 : 1) + (width > 1);
    int rc = -1;
    if (rank == want && H5Sget_simple_extent_dims(fs, dims, NULL) == rank &&
        dims[series] == n && (width == 1 || dims[rank - 1] == width)) {
        hsize_t start[3] = {frame, 0, 0}, count[3] = {1, n, width};
        if (!series) {
            start[0] = 0;
            count[0] = n;
            count[1] = width;
        }
        hsize_t mdim[2] = {n, width};
        hid_t ms = H5Screate_simple(width > 1 ? 2 : 1, mdim, NULL);
        if (ms >= 0 && H5Sselect_hyperslab(fs, H5S_SELECT_SET, start, NULL, count, NULL) >= 0 &&
            H5Dread(d, memtype, ms, fs, H5P_DEFAULT, out) >= 0)
            rc = 0;
        if (ms >= 0) H5Sclose(ms);
    }
    H5Sclose(fs);
    H5Dclose(d);
    return rc;
}

/* The keys of the top-level mapping KEY of the resolved scene TEXT, in order, into names[n]
 * (none when the scene has no such mapping). */
static int mapping_keys(const char *text, const char *key, char ***names, size_t *n) {
    yaml_parser_t p;
    yaml_document_t doc;
    if (!yaml_parser_initialize(&p)) return -1;
    yaml_parser_set_input_string(&p, (const unsigned char *)text, strlen(text));
    int rc = -1;
    if (yaml_parser_load(&p, &doc)) {
        yaml_node_t *root = yaml_document_get_root_node(&doc), *map = NULL;
        for (yaml_node_pair_t *q = root && root->type == YAML_MAPPING_NODE
                                       ? root->data.mapping.pairs.start : NULL;
             q && q < root->data.mapping.pairs.top; q++) {
            yaml_node_t *k = yaml_document_get_node(&doc, q->key);
            if (k->type == YAML_SCALAR_NODE && strcmp((char *)k->data.scalar.value, key) == 0)
                map = yaml_document_get_node(&doc, q->value);
        }
        size_t m = map && map->type == YAML_MAPPING_NODE
                       ? (size_t)(map->data.mapping.pairs.top - map->data.mapping.pairs.start)
                       : 0;
        *names = calloc(m ? m : 1, sizeof **names);
        rc = *names ? 0 : -1;
        for (size_t i = 0; i < m && rc == 0; i++) {
            yaml_node_t *k = yaml_document_get_node(&doc, map->data.mapping.pairs.start[i].key);
            if (k->type != YAML_SCALAR_NODE) { rc = -1; break; }
            (*names)[i] = strdup((char *)k->data.scalar.value);
            if (!(*names)[i]) rc = -1;
            *n = i + 1;
        }
        yaml_document_delete(&doc);
    }
    yaml_parser_delete(&p);
    return rc;
}

/* /parameters/scene (a scalar variable-length string) -> the material names (at least one) and
 * the bond type names. */
static int read_scene_names(hid_t f, dep_frame *fr) {
    if (H5Lexists(f, "parameters", H5P_DEFAULT) <= 0 ||
        H5Lexists(f, "parameters/scene", H5P_DEFAULT) <= 0)
        return -1;
    hid_t d = H5Dopen2(f, "parameters/scene", H5P_DEFAULT);
    if (d < 0) return -1;
    hid_t t = H5Tcopy(H5T_C_S1);
    char *text = NULL;
    int rc = -1;
    if (t >= 0 && H5Tset_size(t, H5T_VARIABLE) >= 0 && H5Tset_cset(t, H5T_CSET_UTF8) >= 0 &&
        H5Dread(d, t, H5S_ALL, H5S_ALL, H5P_DEFAULT, &text) >= 0 && text) {
        rc = mapping_keys(text, "materials", &fr->materials, &fr->n_materials) ||
                     !fr->n_materials ||
                     mapping_keys(text, "bond_types", &fr->bond_types, &fr->n_bond_types)
                 ? -1
                 : 0;
        H5free_memory(text);
    }
    if (t >= 0) H5Tclose(t);
    H5Dclose(d);
    return rc;
}

/* Read the whole dataset PATH of n x width int64 values into a new array (n = its length). */
static int64_t *read_int64s(hid_t f, const char *path, size_t width, size_t *n) {
    *n = 0;
    hid_t d = H5Lexists(f, path, H5P_DEFAULT) > 0 ? H5Dopen2(f, path, H5P_DEFAULT) : -1;
    if (d < 0) return NULL;
    hid_t sp = H5Dget_space(d);
    hsize_t dims[2] = {0, 0};
    const int rank = width > 1 ? 2 : 1;
    int64_t *out = NULL;
    if (sp >= 0 && H5Sget_simple_extent_ndims(sp) == rank &&
        H5Sget_simple_extent_dims(sp, dims, NULL) == rank && (width == 1 || dims[1] == width)) {
        out = malloc((dims[0] ? dims[0] : 1) * width * sizeof *out);
        if (out && dims[0] &&
            H5Dread(d, H5T_NATIVE_INT64, H5S_ALL, H5S_ALL, H5P_DEFAULT, out) < 0) {
            free(out);
            out = NULL;
        }
        if (out) *n = (size_t)dims[0];
    }
    if (sp >= 0) H5Sclose(sp);
    H5Dclose(d);
    return out;
}

typedef struct typed_pair {
    int64_t a, b; /* ids, a < b */
    int64_t type;
} typed_pair;

static int by_pair(const void *x, const void *y) {
    const typed_pair *p = x, *q = y;
    if (p->a != q->a) return (p->a > q->a) - (p->a < q->a);
    return (p->b > q->b) - (p->b < q->b);
}

/* The bond table /jdem/bonds as pairs (smaller id first) with their types, sorted by pair. */
static typed_pair *bond_table(hid_t f, size_t *nb) {
    size_t ni = 0, nt = 0;
    int64_t *ids = read_int64s(f, "jdem/bonds/ids", 2, &ni);
    int64_t *type = read_int64s(f, "jdem/bonds/type", 1, &nt);
    typed_pair *t = ids && type && ni == nt ? malloc((ni ? ni : 1) * sizeof *t) : NULL;
    for (size_t i = 0; t && i < ni; i++) {
        const int64_t a = ids[2 * i], b = ids[2 * i + 1];
        t[i] = (typed_pair){a < b ? a : b, a < b ? b : a, type[i]};
    }
    if (t) {
        qsort(t, ni, sizeof *t, by_pair);
        *nb = ni;
    }
    free(ids);
    free(type);
    return t;
}

/* The bonds intact at frame `at`: frame_start[at] .. + frame_count[at] of /jdem/bond_lines/rows
 * (written at close by io/h5md_bond_lines.c, the writer's rule of "intact"), with each pair's
 * type from the bond table.  A trajectory without /jdem/bonds has none.  Returns NULL, or what
 * is missing. */
static const char *read_bond_lines(hid_t f, hsize_t at, dep_frame *fr) {
    if (H5Lexists(f, "jdem", H5P_DEFAULT) <= 0 || H5Lexists(f, "jdem/bonds", H5P_DEFAULT) <= 0)
        return NULL;
    if (H5Lexists(f, "jdem/bond_lines", H5P_DEFAULT) <= 0) return "/jdem/bond_lines";
    size_t nf = 0, nc = 0, nr = 0, nb = 0;
    int64_t *start = read_int64s(f, "jdem/bond_lines/frame_start", 1, &nf);
    int64_t *count = read_int64s(f, "jdem/bond_lines/frame_count", 1, &nc);
    int64_t *rows = read_int64s(f, "jdem/bond_lines/rows", 2, &nr);
    typed_pair *table = bond_table(f, &nb);
    const char *bad = NULL;
    if (!start || !count || !rows || nf != nc || at >= nf || start[at] < 0 || count[at] < 0 ||
        (size_t)(start[at] + count[at]) > nr)
        bad = "/jdem/bond_lines";
    else if (!table)
        bad = "/jdem/bonds";
    const size_t n = bad ? 0 : (size_t)count[at];
    if (!bad) {
        fr->line_row = malloc((n ? n : 1) * 2 * sizeof *fr->line_row);
        fr->line_type = malloc((n ? n : 1) * sizeof *fr->line_type);
        if (!fr->line_row || !fr->line_type) bad = "memory";
    }
    for (size_t l = 0; !bad && l < n; l++) {
        const int64_t r0 = rows[2 * (start[at] + (int64_t)l)],
                      r1 = rows[2 * (start[at] + (int64_t)l) + 1];
        if (r0 < 0 || r1 < 0 || (size_t)r0 >= fr->n || (size_t)r1 >= fr->n) {
            bad = "/jdem/bond_lines/rows";
            break;
        }
        const int64_t a = fr->id[r0], b = fr->id[r1];
        const typed_pair key = {a < b ? a : b, a < b ? b : a, 0};
        const typed_pair *hit = bsearch(&key, table, nb, sizeof *table, by_pair);
        if (!hit || hit->type < 0 || (size_t)hit->type >= fr->n_bond_types) {
            bad = "/jdem/bonds/type";
            break;
        }
        fr->line_row[2 * l] = r0;
        fr->line_row[2 * l + 1] = r1;
        fr->line_type[l] = (int32_t)hit->type;
        fr->n_lines = l + 1;
    }
    free(start);
    free(count);
    free(rows);
    free(table);
    return bad;
}

static int frame_arrays(dep_frame *fr, int velocities) {
    size_t n = fr->n ? fr->n : 1;
    fr->id = malloc(n * sizeof *fr->id);
    fr->species = malloc(n * sizeof *fr->species);
    fr->radius = malloc(n * sizeof *fr->radius);
    fr->position = malloc(3 * n * sizeof *fr->position);
    if (velocities) {
        fr->velocity = malloc(3 * n * sizeof *fr->velocity);
        fr->angular_velocity = malloc(3 * n * sizeof *fr->angular_velocity);
    }
    return fr->id && fr->species && fr->radius && fr->position &&
                   (!velocities || (fr->velocity && fr->angular_velocity))
               ? 0
               : -1;
}

/* Frame dims of /particles/all/position/value: [F][N][3]. */
static int position_dims(hid_t all, hsize_t *frames, hsize_t *n) {
    if (H5Lexists(all, "position", H5P_DEFAULT) <= 0 ||
        H5Lexists(all, "position/value", H5P_DEFAULT) <= 0)
        return -1;
    hid_t d = H5Dopen2(all, "position/value", H5P_DEFAULT);
    if (d < 0) return -1;
    hid_t s = H5Dget_space(d);
    hsize_t dims[3];
    int ok = H5Sget_simple_extent_ndims(s) == 3 && H5Sget_simple_extent_dims(s, dims, NULL) == 3 &&
             dims[2] == 3;
    H5Sclose(s);
    H5Dclose(d);
    if (!ok) return -1;
    *frames = dims[0];
    *n = dims[1];
    return 0;
}

static int read_frame_fields(hid_t f, const char *file, int64_t frame, int velocities,
                             int bonds, dep_frame *fr, char *msg, size_t len) {
    hid_t all = H5Lexists(f, "particles", H5P_DEFAULT) > 0 &&
                        H5Lexists(f, "particles/all", H5P_DEFAULT) > 0
                    ? H5Gopen2(f, "particles/all", H5P_DEFAULT)
                    : -1;
    hsize_t frames = 0, n = 0;
    if (all < 0 || position_dims(all, &frames, &n)) {
        if (all >= 0) H5Gclose(all);
        snprintf(msg, len, "%s: no /particles/all/position; " VALID_H5MD, file);
        return -1;
    }
    int rc = -1;
    int64_t nf = (int64_t)frames;
    if (frame < -nf || frame >= nf) {
        snprintf(msg, len, "%s: frame %lld does not exist; valid: %lld to %lld (%lld frames)",
                 file, (long long)frame, (long long)-nf, (long long)(nf - 1), (long long)nf);
    } else {
        hsize_t at = (hsize_t)(frame < 0 ? frame + nf : frame);
        fr->n = (size_t)n;
        const char *bad = NULL;
        if (frame_arrays(fr, velocities)) bad = "memory";
        else if (read_field(all, "id", at, H5T_NATIVE_INT64, 1, fr->n, fr->id)) bad = "id";
        else if (read_field(all, "species", at, H5T_NATIVE_INT32, 1, fr->n, fr->species))
            bad = "species";
        else if (read_field(all, "radius", at, H5T_NATIVE_DOUBLE, 1, fr->n, fr->radius))
            bad = "radius";
        else if (read_field(all, "position", at, H5T_NATIVE_DOUBLE, 3, fr->n, fr->position))
            bad = "position";
        else if (velocities &&
                 (read_field(all, "velocity", at, H5T_NATIVE_DOUBLE, 3, fr->n, fr->velocity) ||
                  read_field(all, "angular_velocity", at, H5T_NATIVE_DOUBLE, 3, fr->n,
                             fr->angular_velocity)))
            bad = "velocity";
        else if (read_scene_names(f, fr))
            bad = "parameters";
        else if (bonds && (bad = read_bond_lines(f, at, fr)) != NULL && strcmp(bad, "memory")) {
            snprintf(msg, len, "%s: cannot read the bonds intact at frame %lld (%s); valid: a "
                     "trajectory of a bonded run that ended (the bonds' lines are written at its "
                     "close), or bonds: none", file, (long long)frame, bad);
            H5Gclose(all);
            return -1;
        }
        if (!bad)
            rc = 0;
        else if (strcmp(bad, "memory") == 0)
            snprintf(msg, len, "%s: out of memory for %zu particles and their bonds", file, fr->n);
        else if (strcmp(bad, "parameters") == 0)
            snprintf(msg, len, "%s: no readable /parameters/scene with materials; " VALID_H5MD,
                     file);
        else
            snprintf(msg, len, "%s: cannot read /particles/all/%s of frame %lld; " VALID_H5MD,
                     file, bad, (long long)frame);
    }
    H5Gclose(all);
    return rc;
}

int dep_read_frame(const char *file, int64_t frame, int velocities, int bonds, dep_frame *fr,
                   char *msg, size_t len) {
    memset(fr, 0, sizeof *fr);
    struct stat st;
    if (stat(file, &st) != 0 || !S_ISREG(st.st_mode)) {
        snprintf(msg, len, "%s: no such file; " VALID_H5MD, file);
        return -1;
    }
    H5E_auto2_t old_func;
    void *old_data;
    H5Eget_auto2(H5E_DEFAULT, &old_func, &old_data);
    H5Eset_auto2(H5E_DEFAULT, NULL, NULL); /* the messages below say what is wrong */
    int rc = -1;
    hid_t f = H5Fis_hdf5(file) > 0
                  ? H5Fopen(file, H5F_ACC_RDONLY, H5P_DEFAULT)
                  : -1;
    if (f < 0)
        snprintf(msg, len, "%s: not an HDF5 file; " VALID_H5MD, file);
    else if (H5Lexists(f, "h5md", H5P_DEFAULT) <= 0)
        snprintf(msg, len, "%s: no /h5md group (not an H5MD file); " VALID_H5MD, file);
    else
        rc = read_frame_fields(f, file, frame, velocities, bonds, fr, msg, len);
    if (f >= 0) H5Fclose(f);
    H5Eset_auto2(H5E_DEFAULT, old_func, old_data);
    if (rc) dep_free_frame(fr);
    return rc;
}

void dep_free_frame(dep_frame *fr) {
    free(fr->id);
    free(fr->species);
    free(fr->radius);
    free(fr->position);
    free(fr->velocity);
    free(fr->angular_velocity);
    for (size_t i = 0; i < fr->n_materials; i++) free(fr->materials[i]);
    free(fr->materials);
    free(fr->line_row);
    free(fr->line_type);
    for (size_t i = 0; i < fr->n_bond_types; i++) free(fr->bond_types[i]);
    free(fr->bond_types);
    memset(fr, 0, sizeof *fr);
}
