/*
 * checkpoint_io.c — the checkpoint's values as HDF5 datasets, in both directions (see
 * checkpoint_io.h).
 */
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

#include "checkpoint_io.h"

void ck_fail(ck_io *io, const char *fmt, ...) {
    if (io->failed) return;
    io->failed = 1;
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(io->err, io->errlen, fmt, ap);
    va_end(ap);
}

static void write_array(ck_io *io, const char *name, hid_t memtype, size_t count,
                        const void *data) {
    const hsize_t dims[1] = {count};
    hid_t space = H5Screate_simple(1, dims, NULL);
    hid_t lcpl = H5Pcreate(H5P_LINK_CREATE);
    hid_t d = H5I_INVALID_HID;
    if (space >= 0 && lcpl >= 0 && H5Pset_create_intermediate_group(lcpl, 1) >= 0)
        d = H5Dcreate2(io->file, name, memtype, space, lcpl, H5P_DEFAULT, H5P_DEFAULT);
    const int ok = d >= 0 && (count == 0 ||
                              H5Dwrite(d, memtype, H5S_ALL, H5S_ALL, H5P_DEFAULT, data) >= 0);
    if (d >= 0) H5Dclose(d);
    if (lcpl >= 0) H5Pclose(lcpl);
    if (space >= 0) H5Sclose(space);
    if (!ok) ck_fail(io, "cannot write '%s' into '%s' (disk full or not writable?)", name, io->path);
}

static void read_array(ck_io *io, const char *name, hid_t memtype, size_t count, void *data) {
    hid_t d = H5Lexists(io->file, name, H5P_DEFAULT) > 0 ? H5Dopen2(io->file, name, H5P_DEFAULT)
                                                         : H5I_INVALID_HID;
    hid_t space = d >= 0 ? H5Dget_space(d) : H5I_INVALID_HID;
    const hssize_t have = space >= 0 ? H5Sget_simple_extent_npoints(space) : -1;
    const int ok = have == (hssize_t)count &&
                   (count == 0 || H5Dread(d, memtype, H5S_ALL, H5S_ALL, H5P_DEFAULT, data) >= 0);
    if (space >= 0) H5Sclose(space);
    if (d >= 0) H5Dclose(d);
    if (!ok)
        ck_fail(io, "checkpoint '%s' is damaged: '%s' is missing, unreadable or not of %zu "
                "values; valid: a checkpoint written completely by jdem run", io->path, name, count);
}

static uint64_t fnv1a(uint64_t h, const void *data, size_t bytes) {
    const unsigned char *p = data;
    for (size_t k = 0; k < bytes; k++) h = (h ^ p[k]) * 0x100000001b3ull;
    return h;
}

uint64_t ck_fnv1a(const void *data, size_t bytes) {
    return fnv1a(0xcbf29ce484222325ull, data, bytes);
}

void ck_array(ck_io *io, const char *name, hid_t memtype, size_t count, void *data) {
    if (io->failed) return;
    if (io->reading) read_array(io, name, memtype, count, data);
    else write_array(io, name, memtype, count, data);
    if (io->failed) return;
    io->digest = fnv1a(io->digest, name, strlen(name));
    io->digest = fnv1a(io->digest, data, count * H5Tget_size(memtype));
}

void ck_double(ck_io *io, const char *name, double *v) {
    ck_array(io, name, H5T_NATIVE_DOUBLE, 1, v);
}

void ck_int64(ck_io *io, const char *name, int64_t *v) {
    ck_array(io, name, H5T_NATIVE_INT64, 1, v);
}

void ck_int(ck_io *io, const char *name, int *v) {
    int64_t x = *v;
    ck_int64(io, name, &x);
    if (io->reading && !io->failed) *v = (int)x;
}

void ck_count(ck_io *io, const char *name, size_t *n, size_t max) {
    int64_t x = (int64_t)*n;
    ck_int64(io, name, &x);
    if (!io->reading || io->failed) return;
    if (x < 0 || (uint64_t)x > (uint64_t)max)
        ck_fail(io, "checkpoint '%s' is damaged: '%s' = %lld, valid: 0 to %zu for this scene",
                io->path, name, (long long)x, max);
    else
        *n = (size_t)x;
}
