/*
 * xdmf.c — the XDMF 3 sidecar of an H5MD file (written by jd_h5md_close before the .h5 and the
 * sidecar are renamed into place).
 *
 * Written for ParaView's default reader, Xdmf3ReaderS.  It does not evaluate the
 * ItemType="HyperSlab" items the old Xdmf2 reader needs (0 points, "Skipping unrecognized array
 * type [None]"), but it reads a selection written into an HDF item's content:
 * "file.h5:/dataset|start:stride:count:dataspace".  A temporal collection needs one grid per
 * time (Xdmf3 has no item that indexes a dataset by the time step), so each frame is one short
 * block: Polyvertex connectivity from /jdem/vertex_index (Xdmf3 makes no cells of its own),
 * the frame's positions and vector arrays, and radius, id and species whole.  The .h5 is
 * referenced by its basename, so the pair can move together.
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

/* Frame `frame` of /particles/all/GROUP/value [F][N][3]. */
static void xdmf_slab(FILE *fp, const xdmf_info *h, const char *file, const char *group,
                      hsize_t frame) {
    char dims[64], dset[96], sel[160];
    snprintf(dims, sizeof dims, "%zu 3", h->n);
    snprintf(dset, sizeof dset, "/particles/all/%s/value", group);
    snprintf(sel, sizeof sel, "%llu 0 0:1 1 1:1 %zu 3:%llu %zu 3", (unsigned long long)frame,
             h->n, (unsigned long long)h->nframes, h->n);
    xdmf_hdf_item(fp, file, dset, dims, "Float", 8, sel);
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
    char n1[32];
    snprintf(n1, sizeof n1, "%zu", h->n);
    fprintf(fp, "<?xml version=\"1.0\" ?>\n"
                "<Xdmf Version=\"3.0\">\n"
                "  <Domain>\n"
                "    <Grid Name=\"particles\" GridType=\"Collection\" "
                "CollectionType=\"Temporal\">\n");
    static const char *const vec[] = {"velocity", "angular_velocity", "force", "torque"};
    static const int veck[] = {TD_VELOCITY, TD_ANGVEL, TD_FORCE, TD_TORQUE};
    static const struct {
        const char *name, *ntype;
        int prec;
    } fixed[] = {{"radius", "Float", 8}, {"id", "Int", 8}, {"species", "Int", 4}};
    for (hsize_t i = 0; i < h->nframes; ++i) {
        fprintf(fp, "<Grid Name=\"frame_%llu\"><Time Value=\"%.17g\"/>\n",
                (unsigned long long)i, h->times[i]);
        fprintf(fp, "<Topology TopologyType=\"Polyvertex\" NumberOfElements=\"%zu\" "
                    "NodesPerElement=\"1\">", h->n);
        xdmf_hdf_item(fp, file, "/jdem/vertex_index", n1, "Int", 8, NULL);
        fprintf(fp, "</Topology>\n<Geometry GeometryType=\"XYZ\">");
        xdmf_slab(fp, h, file, "position", i);
        fprintf(fp, "</Geometry>\n");
        for (size_t k = 0; k < sizeof fixed / sizeof *fixed; ++k) {
            char dset[64];
            snprintf(dset, sizeof dset, "/particles/all/%s", fixed[k].name);
            fprintf(fp, "<Attribute Name=\"%s\" Center=\"Node\">", fixed[k].name);
            xdmf_hdf_item(fp, file, dset, n1, fixed[k].ntype, fixed[k].prec, NULL);
            fprintf(fp, "</Attribute>\n");
        }
        for (int v = 0; v < 4; ++v) {
            if (!h->present[veck[v]]) continue;
            fprintf(fp, "<Attribute Name=\"%s\" AttributeType=\"Vector\" Center=\"Node\">",
                    vec[v]);
            xdmf_slab(fp, h, file, vec[v], i);
            fprintf(fp, "</Attribute>\n");
        }
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
