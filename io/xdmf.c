/*
 * xdmf.c — the XDMF 3 sidecar of an H5MD file (written by jd_h5md_close once the .h5 is final).
 *
 * Xdmf3 (unlike the old Xdmf2 reader) does not invent connectivity for a Polyvertex topology, so
 * the 0..N-1 list is written inline once, in the first frame's grid, and the other frames
 * xi:include that Topology.  Geometry and the vector attributes are HyperSlabs [frame, 0, 0] x
 * [1, N, 3] of the .h5 (referenced by basename).
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

static void xdmf_hdf_item(FILE *fp, const char *file, const char *dset, const char *dims,
                          const char *ntype, int prec) {
    fprintf(fp, "<DataItem Dimensions=\"%s\" NumberType=\"%s\" Precision=\"%d\" Format=\"HDF\">",
            dims, ntype, prec);
    xml_escaped(fp, file);
    fprintf(fp, ":%s</DataItem>", dset);
}

static void xdmf_slab(FILE *fp, const xdmf_info *h, const char *file, const char *group,
                      hsize_t frame) {
    char dims[64], full[96], dset[96];
    snprintf(dims, sizeof dims, "%zu 3", h->n);
    snprintf(full, sizeof full, "%llu %zu 3", (unsigned long long)h->nframes, h->n);
    snprintf(dset, sizeof dset, "/particles/all/%s/value", group);
    fprintf(fp,
            "\n          <DataItem ItemType=\"HyperSlab\" Type=\"HyperSlab\" Dimensions=\"%s\">\n"
            "            <DataItem Dimensions=\"3 3\" NumberType=\"UInt\" Format=\"XML\">"
            "%llu 0 0 1 1 1 1 %zu 3</DataItem>\n            ",
            dims, (unsigned long long)frame, h->n);
    xdmf_hdf_item(fp, file, dset, full, "Float", 8);
    fprintf(fp, "\n          </DataItem>\n        ");
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
    fprintf(fp, "<?xml version=\"1.0\" ?>\n<!DOCTYPE Xdmf SYSTEM \"Xdmf.dtd\" []>\n"
                "<Xdmf Version=\"3.0\" xmlns:xi=\"http://www.w3.org/2001/XInclude\">\n"
                "  <Domain>\n"
                "    <Grid Name=\"particles\" GridType=\"Collection\" "
                "CollectionType=\"Temporal\">\n");
    static const char *const vec[] = {"velocity", "angular_velocity", "force", "torque"};
    static const int veck[] = {TD_VELOCITY, TD_ANGVEL, TD_FORCE, TD_TORQUE};
    for (hsize_t i = 0; i < h->nframes; ++i) {
        fprintf(fp,
                "      <Grid Name=\"frame_%06llu\" GridType=\"Uniform\">\n"
                "        <Time Value=\"%.17g\"/>\n",
                (unsigned long long)i, h->times[i]);
        if (i == 0) {
            /* Xdmf3 needs explicit connectivity for Polyvertex; written once, included below */
            fprintf(fp,
                    "        <Topology TopologyType=\"Polyvertex\" NumberOfElements=\"%zu\" "
                    "NodesPerElement=\"1\">\n          <DataItem Dimensions=\"%zu\" "
                    "NumberType=\"Int\" Precision=\"8\" Format=\"XML\">",
                    h->n, h->n);
            for (size_t j = 0; j < h->n; ++j)
                fprintf(fp, (j % 16 == 15) ? "%zu\n" : "%zu ", j);
            fprintf(fp, "</DataItem>\n        </Topology>\n");
        } else {
            fprintf(fp, "        <xi:include xpointer=\"xpointer(/Xdmf/Domain/Grid/Grid[1]/"
                        "Topology)\"/>\n");
        }
        fprintf(fp, "        <Geometry GeometryType=\"XYZ\">");
        xdmf_slab(fp, h, file, "position", i);
        fprintf(fp, "</Geometry>\n");
        fprintf(fp, "        <Attribute Name=\"radius\" AttributeType=\"Scalar\" "
                    "Center=\"Node\">");
        xdmf_hdf_item(fp, file, "/particles/all/radius", n1, "Float", 8);
        fprintf(fp, "</Attribute>\n        <Attribute Name=\"id\" AttributeType=\"Scalar\" "
                    "Center=\"Node\">");
        xdmf_hdf_item(fp, file, "/particles/all/id", n1, "Int", 8);
        fprintf(fp, "</Attribute>\n        <Attribute Name=\"species\" AttributeType=\"Scalar\" "
                    "Center=\"Node\">");
        xdmf_hdf_item(fp, file, "/particles/all/species", n1, "Int", 4);
        fprintf(fp, "</Attribute>\n");
        for (int v = 0; v < 4; ++v) {
            if (!h->present[veck[v]]) continue;
            fprintf(fp, "        <Attribute Name=\"%s\" AttributeType=\"Vector\" "
                        "Center=\"Node\">", vec[v]);
            xdmf_slab(fp, h, file, vec[v], i);
            fprintf(fp, "</Attribute>\n");
        }
        fprintf(fp, "      </Grid>\n");
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
