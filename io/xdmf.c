/*
 * xdmf.c — the XDMF 3 sidecar of an H5MD file (written by jd_h5md_close before the .h5 and the
 * sidecar are renamed into place).
 *
 * Written for ParaView's default reader, Xdmf3ReaderS.  It does not evaluate the
 * ItemType="HyperSlab" items the old Xdmf2 reader needs (0 points, "Skipping unrecognized array
 * type [None]"), but it reads a selection written into an HDF item's content:
 * "file.h5:/dataset|start:stride:count:dataspace".  A temporal collection needs one grid per
 * time (Xdmf3 has no item that indexes a dataset by the time step), so each frame is a short
 * spatial collection (which Xdmf3ReaderS reads as one multi-piece data set):
 *  - "particles": one grid per run of consecutive live rows (one for a fixed set), Polyvertex
 *    cells from /jdem/vertex_index (Xdmf3 makes no cells of its own), the run's positions,
 *    vector arrays, radius, id and species; empty rows are left out, so the points are the
 *    live particles;
 *  - "bonds": the frame's intact bonds as Polyline cells (/jdem/bond_lines) over the frame's
 *    positions, with radius;
 *  - "walls": the walls' quadrilaterals (/jdem/walls/mesh), with a zero radius at every vertex
 *    so that a Point Gaussian representation scaled by radius gives them no sphere.
 * A grid with no cells is left out.  The .h5 is referenced by its basename, so the pair can
 * move together.
 */
#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "h5md_internal.h"

static void xml_escaped(FILE *fp, const char *s) {
    for (; *s; ++s) {
        switch (*s) {
        case '&': fputs("&amp;", fp); break;
        case '<': fputs("&lt;", fp); break;
        case '>': fputs("&gt;", fp); break;
        case '"': fputs("&quot;", fp); break;
        case '\'': fputs("&apos;", fp); break;
        default: fputc(*s, fp);
        }
    }
}

/* PATH with its extension replaced by .xdmf (only the last one: a.jdem.h5 -> a.jdem.xdmf). */
char *xdmf_path(const char *path) {
    const char *slash = strrchr(path, '/');
    const char *base = slash ? slash + 1 : path;
    const char *dot = strrchr(base, '.');
    size_t stem = (dot && dot != base) ? (size_t)(dot - path) : strlen(path);
    char *x = malloc(stem + 6);
    if (!x) return NULL;
    memcpy(x, path, stem);
    memcpy(x + stem, ".xdmf", 6);
    return x;
}

/* An HDF DataItem; with a selection ("start:stride:count:dataspace", Xdmf3's own hyperslab
 * syntax inside the content, which its reader evaluates) or the whole dataset (sel NULL). */
static void xdmf_hdf_item(FILE *fp, const char *file, const char *dset, const char *dims,
                          const char *ntype, int prec, const char *sel) {
    fprintf(fp, "<DataItem Dimensions=\"%s\" NumberType=\"%s\" Precision=\"%d\" Format=\"HDF\">",
            dims, ntype, prec);
    xml_escaped(fp, file);
    fprintf(fp, ":%s%s%s</DataItem>", dset, sel ? "|" : "", sel ? sel : "");
}

typedef struct xdmf_out {
    FILE *fp;
    const xdmf_info *h;
    const char *file; /* the .h5's basename */
} xdmf_out;

/* Rows [start, start + count) of frame f of a [F][rows][width] dataset (width 0: [F][rows]). */
static void frame_rows(const xdmf_out *o, const char *dset, hsize_t f, hsize_t rows,
                       hsize_t start, hsize_t count, int width, const char *ntype, int prec) {
    char dims[64], sel[192];
    const unsigned long long F = o->h->nframes;
    if (width) {
        snprintf(dims, sizeof dims, "%llu %d", (unsigned long long)count, width);
        snprintf(sel, sizeof sel, "%llu %llu 0:1 1 1:1 %llu %d:%llu %llu %d",
                 (unsigned long long)f, (unsigned long long)start, (unsigned long long)count,
                 width, F, (unsigned long long)rows, width);
    } else {
        snprintf(dims, sizeof dims, "%llu", (unsigned long long)count);
        snprintf(sel, sizeof sel, "%llu %llu:1 1:1 %llu:%llu %llu", (unsigned long long)f,
                 (unsigned long long)start, (unsigned long long)count, F,
                 (unsigned long long)rows);
    }
    xdmf_hdf_item(o->fp, o->file, dset, dims, ntype, prec, sel);
}

/* Entries [start, start + count) of a 1-D dataset of `rows` entries. */
static void range(const xdmf_out *o, const char *dset, hsize_t rows, hsize_t start,
                  hsize_t count, const char *ntype, int prec) {
    char dims[32], sel[128];
    snprintf(dims, sizeof dims, "%llu", (unsigned long long)count);
    snprintf(sel, sizeof sel, "%llu:1:%llu:%llu", (unsigned long long)start,
             (unsigned long long)count, (unsigned long long)rows);
    xdmf_hdf_item(o->fp, o->file, dset, dims, ntype, prec, sel);
}

/* XInclude of element k of frame 0's particle grid (element(): child numbers from the root:
 * Xdmf, Domain, the temporal grid, frame 0, its grid 2 — the first after Time). */
static void include_particles_item(FILE *fp, int k) {
    fprintf(fp, "<xi:include xpointer=\"element(/1/1/1/1/2/%d)\"/>", k);
}

/* Frame f's grid of the live rows `run`.  same_as_first: the run is frame 0's first run, so its
 * cells and time-independent arrays are frame 0's, included instead of written again. */
static void particles_grid(const xdmf_out *o, hsize_t f, const xdmf_run *run, int same_as_first) {
    static const char *const vec[] = {"velocity", "angular_velocity", "force", "torque"};
    static const int veck[] = {TD_VELOCITY, TD_ANGVEL, TD_FORCE, TD_TORQUE};
    const xdmf_info *h = o->h;
    const hsize_t n = h->n, c = run->count;
    const int share = same_as_first && f > 0; /* children: Topology 1, Geometry 2, radius 3, id 4,
                                                 species 5 */
    fprintf(o->fp, "<Grid Name=\"particles\">");
    if (share) {
        include_particles_item(o->fp, 1);
    } else {
        fprintf(o->fp, "<Topology TopologyType=\"Polyvertex\" NumberOfElements=\"%llu\" "
                       "NodesPerElement=\"1\">", (unsigned long long)c);
        range(o, "/jdem/vertex_index", n, 0, c, "Int", 8);
        fprintf(o->fp, "</Topology>");
    }
    fprintf(o->fp, "\n<Geometry GeometryType=\"XYZ\">");
    frame_rows(o, "/particles/all/position/value", f, n, run->start, c, 3, "Float", 8);
    fprintf(o->fp, "</Geometry>\n");
    if (share) {
        include_particles_item(o->fp, 3);
    } else {
        fprintf(o->fp, "<Attribute Name=\"radius\" Center=\"Node\">");
        range(o, "/particles/all/radius", n, run->start, c, "Float", 8);
        fprintf(o->fp, "</Attribute>");
    }
    if (share && !h->growing) {
        include_particles_item(o->fp, 4);
    } else {
        fprintf(o->fp, "<Attribute Name=\"id\" Center=\"Node\">");
        if (h->growing)
            frame_rows(o, "/particles/all/id/value", f, n, run->start, c, 0, "Int", 8);
        else
            range(o, "/particles/all/id", n, run->start, c, "Int", 8);
        fprintf(o->fp, "</Attribute>");
    }
    if (share) {
        include_particles_item(o->fp, 5);
    } else {
        fprintf(o->fp, "<Attribute Name=\"species\" Center=\"Node\">");
        range(o, "/particles/all/species", n, run->start, c, "Int", 4);
        fprintf(o->fp, "</Attribute>");
    }
    fprintf(o->fp, "\n");
    for (int v = 0; v < 4; ++v) {
        if (!h->present[veck[v]]) continue;
        char dset[64];
        snprintf(dset, sizeof dset, "/particles/all/%s/value", vec[v]);
        fprintf(o->fp, "<Attribute Name=\"%s\" AttributeType=\"Vector\" Center=\"Node\">", vec[v]);
        frame_rows(o, dset, f, n, run->start, c, 3, "Float", 8);
        fprintf(o->fp, "</Attribute>\n");
    }
    fprintf(o->fp, "</Grid>\n");
}

static void bonds_grid(const xdmf_out *o, hsize_t f) {
    const xdmf_info *h = o->h;
    const hsize_t c = h->bond_count[f];
    char dims[64], sel[160];
    snprintf(dims, sizeof dims, "%llu 2", (unsigned long long)c);
    snprintf(sel, sizeof sel, "%llu 0:1 1:%llu 2:%llu 2", (unsigned long long)h->bond_start[f],
             (unsigned long long)c, (unsigned long long)h->bond_rows);
    fprintf(o->fp, "<Grid Name=\"bonds\"><Topology TopologyType=\"Polyline\" "
                   "NumberOfElements=\"%llu\" NodesPerElement=\"2\">", (unsigned long long)c);
    xdmf_hdf_item(o->fp, o->file, "/jdem/bond_lines/rows", dims, "Int", 8, sel);
    fprintf(o->fp, "</Topology>\n<Geometry GeometryType=\"XYZ\">");
    frame_rows(o, "/particles/all/position/value", f, h->n, 0, h->n, 3, "Float", 8);
    fprintf(o->fp, "</Geometry>\n<Attribute Name=\"radius\" Center=\"Node\">");
    range(o, "/particles/all/radius", h->n, 0, h->n, "Float", 8);
    fprintf(o->fp, "</Attribute></Grid>\n");
}

/* Frame f's walls; walls that stand still are frame 0's grid (child `first` of frame 0),
 * included. */
static void walls_grid(const xdmf_out *o, hsize_t f, int first) {
    const h5md_wall_mesh *m = o->h->walls;
    char dims[64];
    if (!m->moving && f > 0) {
        fprintf(o->fp, "<xi:include xpointer=\"element(/1/1/1/1/%d)\"/>\n", first);
        return;
    }
    fprintf(o->fp, "<Grid Name=\"walls\"><Topology TopologyType=\"Quadrilateral\" "
                   "NumberOfElements=\"%zu\">", m->nq);
    snprintf(dims, sizeof dims, "%zu 4", m->nq);
    xdmf_hdf_item(o->fp, o->file, "/jdem/walls/mesh/quads", dims, "Int", 8, NULL);
    fprintf(o->fp, "</Topology>\n<Geometry GeometryType=\"XYZ\">");
    if (m->moving) {
        frame_rows(o, "/jdem/walls/mesh/vertex_position", f, m->nv, 0, m->nv, 3, "Float", 8);
    } else {
        snprintf(dims, sizeof dims, "%zu 3", m->nv);
        xdmf_hdf_item(o->fp, o->file, "/jdem/walls/mesh/vertices", dims, "Float", 8, NULL);
    }
    fprintf(o->fp, "</Geometry>\n<Attribute Name=\"radius\" Center=\"Node\">");
    snprintf(dims, sizeof dims, "%zu", m->nv);
    xdmf_hdf_item(o->fp, o->file, "/jdem/walls/mesh/radius", dims, "Float", 8, NULL);
    fprintf(o->fp, "</Attribute></Grid>\n");
}

int xdmf_write(const xdmf_info *h, const char *tmp, char *err, size_t errlen) {
    const char *slash = strrchr(h->path, '/');
    const char *file = slash ? slash + 1 : h->path; /* relative: the pair moves together */
    unlink(tmp); /* a link or a stale file at TMP is replaced, never written through */
    int fd = open(tmp, O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW, 0666);
    FILE *fp = fd >= 0 ? fdopen(fd, "w") : NULL;
    if (!fp) {
        h5md_set_err(err, errlen, "cannot create '%s': %s", tmp, strerror(errno));
        if (fd >= 0) close(fd);
        return -1;
    }
    const xdmf_out o = {fp, h, file};
    fprintf(fp, "<?xml version=\"1.0\" ?>\n"
                "<Xdmf xmlns:xi=\"http://www.w3.org/2001/XInclude\" Version=\"3.0\">\n"
                "  <Domain>\n"
                "    <Grid Name=\"run\" GridType=\"Collection\" CollectionType=\"Temporal\">\n");
    for (hsize_t i = 0; i < h->nframes; ++i) {
        fprintf(fp, "<Grid Name=\"frame_%llu\" GridType=\"Collection\" "
                    "CollectionType=\"Spatial\"><Time Value=\"%.17g\"/>\n",
                (unsigned long long)i, h->times[i]);
        for (size_t r = h->frame_runs[i]; r < h->frame_runs[i + 1]; ++r) {
            const xdmf_run *run = &h->runs[r];
            const int same = h->frame_runs[1] > 0 && run->start == h->runs[0].start &&
                             run->count == h->runs[0].count;
            particles_grid(&o, i, run, same);
        }
        if (h->bonds && h->bond_count[i] > 0) bonds_grid(&o, i);
        /* frame 0's walls grid: after Time, its particle grids and its bond grid */
        const int walls_at = 2 + (int)h->frame_runs[1] + (h->bonds && h->bond_count[0] > 0);
        if (h->walls->present && h->walls->nq > 0) walls_grid(&o, i, walls_at);
        fprintf(fp, "</Grid>\n");
    }
    fprintf(fp, "    </Grid>\n  </Domain>\n</Xdmf>\n");
    int bad = ferror(fp);
    if (fclose(fp) != 0) bad = 1;
    if (bad) {
        h5md_set_err(err, errlen, "cannot write '%s': %s", tmp, strerror(errno));
        unlink(tmp);
        return -1;
    }
    return 0;
}
