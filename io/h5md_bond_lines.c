/*
 * h5md_bond_lines.c — /jdem/bond_lines: the bonds intact at each frame, as pairs of particle
 * rows, for the sidecar's line cells (Xdmf Polyline over the frame's particle positions).
 *
 * Written at close from the bond tables already in the file (/jdem/bonds, /jdem/broken_bonds):
 * a bond is intact at a frame when it formed at or before the frame's step and has not broken
 * by then, so a broken bond disappears from the first frame at or after its break step.
 * Consecutive frames with the same intact bonds share one block of rows (frame_start,
 * frame_count), so the dataset grows with the changes, not with frames x bonds.
 */
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "h5md_internal.h"

typedef struct id_row {
    int64_t id, row;
} id_row;

typedef struct pair_step {
    int64_t a, b, step; /* ids a < b, and the step of the event */
    size_t index;       /* bonds: position in /jdem/bonds */
} pair_step;

static int by_id(const void *x, const void *y) {
    const id_row *p = x, *q = y;
    return (p->id > q->id) - (p->id < q->id);
}

static int by_pair_step(const void *x, const void *y) {
    const pair_step *p = x, *q = y;
    if (p->a != q->a) return (p->a > q->a) - (p->a < q->a);
    if (p->b != q->b) return (p->b > q->b) - (p->b < q->b);
    return (p->step > q->step) - (p->step < q->step);
}

/* Read a table's ids [k][2] and one int64 column [k]; k = 0 when the table is absent. */
static int read_table(hid_t file, const char *group, const char *column, pair_step **out,
                      size_t *k) {
    *out = NULL;
    *k = 0;
    char ids[64], col[64];
    snprintf(ids, sizeof ids, "%s/ids", group);
    snprintf(col, sizeof col, "%s/%s", group, column);
    if (H5Lexists(file, "jdem", H5P_DEFAULT) <= 0 || H5Lexists(file, group, H5P_DEFAULT) <= 0)
        return 0;
    hid_t di = H5Dopen2(file, ids, H5P_DEFAULT), dc = H5Dopen2(file, col, H5P_DEFAULT);
    hid_t sp = di >= 0 ? H5Dget_space(di) : H5I_INVALID_HID;
    hsize_t dims[2] = {0, 0};
    int rc = -1;
    if (sp >= 0 && dc >= 0 && H5Sget_simple_extent_dims(sp, dims, NULL) == 2) {
        const size_t n = (size_t)dims[0];
        int64_t *pairs = malloc((n ? n : 1) * 2 * sizeof *pairs);
        int64_t *steps = malloc((n ? n : 1) * sizeof *steps);
        *out = malloc((n ? n : 1) * sizeof **out);
        if (pairs && steps && *out &&
            (n == 0 || (H5Dread(di, H5T_NATIVE_INT64, H5S_ALL, H5S_ALL, H5P_DEFAULT, pairs) >= 0 &&
                        H5Dread(dc, H5T_NATIVE_INT64, H5S_ALL, H5S_ALL, H5P_DEFAULT, steps) >= 0))) {
            for (size_t i = 0; i < n; i++)
                (*out)[i] = (pair_step){pairs[2 * i], pairs[2 * i + 1], steps[i], i};
            *k = n;
            rc = 0;
        }
        free(pairs);
        free(steps);
    }
    h5md_close_id(&sp);
    h5md_close_id(&di);
    h5md_close_id(&dc);
    if (rc) {
        free(*out);
        *out = NULL;
    }
    return rc;
}

/* break_step[i] of bond i: the first break of its pair at or after its formation (INT64_MAX:
 * intact to the end).  Both lists are sorted by pair, then step. */
static void match_breaks(pair_step *formed, size_t nb, pair_step *broken, size_t nk,
                         int64_t *break_step) {
    qsort(formed, nb, sizeof *formed, by_pair_step);
    qsort(broken, nk, sizeof *broken, by_pair_step);
    size_t j = 0;
    for (size_t i = 0; i < nb; i++) {
        break_step[formed[i].index] = INT64_MAX;
        while (j < nk && by_pair_step(&broken[j], &formed[i]) < 0) j++;
        if (j < nk && broken[j].a == formed[i].a && broken[j].b == formed[i].b) {
            break_step[formed[i].index] = broken[j].step;
            j++;
        }
    }
}

static int64_t row_of(const id_row *map, size_t n, int64_t id) {
    const id_row key = {id, 0};
    const id_row *hit = bsearch(&key, map, n, sizeof *map, by_id);
    return hit ? hit->row : -1;
}

static int write_lines(hid_t file, const int64_t *rows, hsize_t total, const hsize_t *start,
                       const hsize_t *count, hsize_t nframes) {
    hid_t g = h5md_group_create(file, "jdem/bond_lines");
    if (g < 0) return -1;
    const hsize_t dims[2] = {total, 2};
    hid_t sp = H5Screate_simple(2, dims, NULL);
    hid_t d = sp >= 0 ? H5Dcreate2(g, "rows", H5T_STD_I64LE, sp, H5P_DEFAULT, H5P_DEFAULT,
                                   H5P_DEFAULT)
                      : H5I_INVALID_HID;
    int rc = (d >= 0 && (total == 0 ||
                         H5Dwrite(d, H5T_NATIVE_INT64, H5S_ALL, H5S_ALL, H5P_DEFAULT, rows) >= 0))
                 ? 0 : -1;
    h5md_close_id(&d);
    h5md_close_id(&sp);
    if (rc == 0)
        rc = h5md_dset_fixed(g, "frame_start", H5T_STD_U64LE, H5T_NATIVE_HSIZE, nframes, start,
                             NULL) |
             h5md_dset_fixed(g, "frame_count", H5T_STD_U64LE, H5T_NATIVE_HSIZE, nframes, count,
                             NULL);
    h5md_close_id(&g);
    return rc ? -1 : 0;
}

int h5md_bond_lines(hid_t file, const int64_t *row_id, size_t n, const int64_t *steps,
                    hsize_t nframes, hsize_t *start, hsize_t *count, hsize_t *total) {
    pair_step *formed = NULL, *broken = NULL;
    size_t nb = 0, nk = 0;
    *total = 0;
    if (read_table(file, "jdem/bonds", "formed_step", &formed, &nb) != 0 ||
        read_table(file, "jdem/broken_bonds", "step", &broken, &nk) != 0) {
        free(formed);
        return -1;
    }
    int rc = -1;
    id_row *map = malloc((n ? n : 1) * sizeof *map);
    int64_t *break_step = malloc((nb ? nb : 1) * sizeof *break_step);
    int64_t *pair_rows = malloc((nb ? nb : 1) * 2 * sizeof *pair_rows);
    int64_t *lines = NULL;
    size_t cap = 0;
    if (!map || !break_step || !pair_rows) goto done;
    for (size_t r = 0; r < n; r++) map[r] = (id_row){row_id[r], (int64_t)r};
    qsort(map, n, sizeof *map, by_id);
    /* the bonds in table order, with their rows, before match_breaks reorders the lists */
    for (size_t i = 0; i < nb; i++) {
        pair_rows[2 * i] = row_of(map, n, formed[i].a);
        pair_rows[2 * i + 1] = row_of(map, n, formed[i].b);
    }
    int64_t *formed_step = malloc((nb ? nb : 1) * sizeof *formed_step);
    if (!formed_step) goto done;
    for (size_t i = 0; i < nb; i++) formed_step[i] = formed[i].step;
    match_breaks(formed, nb, broken, nk, break_step);
    for (hsize_t f = 0; f < nframes; f++) {
        /* the intact set changes only at a formation or break step in (previous step, step] */
        int same = f > 0;
        for (size_t i = 0; same && i < nb; i++) {
            const int was = formed_step[i] <= steps[f - 1] && break_step[i] > steps[f - 1];
            const int is = formed_step[i] <= steps[f] && break_step[i] > steps[f];
            same = was == is;
        }
        if (same) {
            start[f] = start[f - 1];
            count[f] = count[f - 1];
            continue;
        }
        start[f] = *total;
        for (size_t i = 0; i < nb; i++) {
            if (!(formed_step[i] <= steps[f] && break_step[i] > steps[f])) continue;
            if (pair_rows[2 * i] < 0 || pair_rows[2 * i + 1] < 0) continue; /* not a row's id */
            if (*total == cap) {
                cap = cap ? 2 * cap : 256;
                int64_t *more = realloc(lines, cap * 2 * sizeof *lines);
                if (!more) {
                    free(formed_step);
                    goto done;
                }
                lines = more;
            }
            lines[2 * *total] = pair_rows[2 * i];
            lines[2 * *total + 1] = pair_rows[2 * i + 1];
            ++*total;
        }
        count[f] = *total - start[f];
    }
    free(formed_step);
    rc = write_lines(file, lines, *total, start, count, nframes);
done:
    free(formed);
    free(broken);
    free(map);
    free(break_step);
    free(pair_rows);
    free(lines);
    return rc;
}
