/*
 * h5md_file.c — the trajectory's life on disk (see h5md_internal.h): PATH.part created without
 * following links and locked before anything is truncated, HDF5 made to open that same file, a
 * readability check after a failure, and the final renames of the .h5 and its sidecar.
 *
 * Why a lock of our own: HDF5's own lock is taken only after H5Fcreate has truncated the file, so
 * a second run on the same path used to destroy the first run's live PATH.part.  We take an
 * exclusive flock(2) on PATH.part before touching its contents and keep it until the file is
 * renamed into place; HDF5's lock is switched off for our handle (a second flock on another
 * descriptor of the same file would conflict with ours).
 */
#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <string.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include "h5md_internal.h"

#ifndef O_CLOEXEC
#define O_CLOEXEC 0
#endif

/* A path that must be a regular file (or absent) where the run will put its result. */
static int check_target(const char *path, char *err, size_t errlen) {
    struct stat st;
    if (stat(path, &st) != 0) return 0;
    if (S_ISDIR(st.st_mode)) {
        h5md_set_err(err, errlen, "output path '%s' is a directory (give a file name, e.g. "
                     "'%s/run.h5')", path, path);
        return -1;
    }
    return 0;
}

int h5md_part_open(const char *path, const char *part, const char *sidecar, int *fd_out,
                   char *err, size_t errlen) {
    *fd_out = -1;
    if (check_target(path, err, errlen) != 0 || check_target(sidecar, err, errlen) != 0)
        return -1;
    int fd = open(part, O_RDWR | O_CREAT | O_NOFOLLOW | O_CLOEXEC, 0666);
    if (fd < 0) {
        if (errno == ELOOP)
            h5md_set_err(err, errlen, "'%s' is a symbolic link; a trajectory is never written "
                         "through one (remove it or choose another output path)", part);
        else
            h5md_set_err(err, errlen, "cannot create '%s': %s", part, strerror(errno));
        return -1;
    }
    struct stat st;
    const char *why = NULL;
    if (fstat(fd, &st) != 0)
        why = strerror(errno);
    else if (!S_ISREG(st.st_mode))
        why = "it exists and is not a regular file";
    else if (st.st_nlink > 1)
        why = "it has other hard links, whose contents would be destroyed";
    if (why) {
        h5md_set_err(err, errlen, "cannot write '%s': %s (remove it or choose another output "
                     "path)", part, why);
        close(fd);
        return -1;
    }
    if (flock(fd, LOCK_EX | LOCK_NB) != 0) {
        if (errno == EWOULDBLOCK)
            h5md_set_err(err, errlen, "'%s' is being written by another run (it holds the "
                         "file's lock); choose another output path or wait for it to end", part);
        else
            h5md_set_err(err, errlen, "cannot lock '%s': %s", part, strerror(errno));
        close(fd);
        return -1;
    }
    if (ftruncate(fd, 0) != 0) {
        h5md_set_err(err, errlen, "cannot truncate '%s': %s", part, strerror(errno));
        close(fd);
        return -1;
    }
    *fd_out = fd;
    return 0;
}

/* HDF5 opens the file by name: make sure it is the inode we locked (the name could have been
 * replaced between our open and H5Fcreate). */
static int same_file(hid_t file, int fd) {
    void *handle = NULL;
    struct stat a, b;
    if (H5Fget_vfd_handle(file, H5P_DEFAULT, &handle) < 0 || !handle) return 0;
    if (fstat(*(int *)handle, &a) != 0 || fstat(fd, &b) != 0) return 0;
    return a.st_dev == b.st_dev && a.st_ino == b.st_ino;
}

hid_t h5md_part_create(const char *part, int fd, char *err, size_t errlen, char *detail) {
    hid_t fapl = H5Pcreate(H5P_FILE_ACCESS);
    hid_t file = H5I_INVALID_HID;
    if (fapl >= 0 && H5Pset_file_locking(fapl, 0, 1) >= 0)
        file = H5Fcreate(part, H5F_ACC_TRUNC, H5P_DEFAULT, fapl);
    if (fapl >= 0) H5Pclose(fapl);
    if (file < 0) {
        h5md_err(detail, err, errlen, "cannot create '%s'", part);
        return H5I_INVALID_HID;
    }
    if (!same_file(file, fd)) {
        h5md_set_err(err, errlen, "'%s' was replaced while it was being created; nothing was "
                     "written", part);
        H5Fclose(file);
        return H5I_INVALID_HID;
    }
    return file;
}

/* Opened through another file driver (stdio), HDF5 treats the file as a different one from
 * the writer's (sec2) handle, which after a failed close is still registered: this reads what
 * is on disk, not the library's memory of it. */
int h5md_part_readable(const char *part) {
    hid_t fapl = H5Pcreate(H5P_FILE_ACCESS);
    if (fapl < 0) return 0;
    hid_t f = H5I_INVALID_HID;
    if (H5Pset_fapl_stdio(fapl) >= 0 && H5Pset_file_locking(fapl, 0, 1) >= 0)
        f = H5Fopen(part, H5F_ACC_RDONLY, fapl);
    H5Pclose(fapl);
    if (f < 0) return 0;
    int ok = 0;
    hid_t d = H5Dopen2(f, "/particles/all/position/step", H5P_DEFAULT);
    if (d >= 0) {
        hid_t sp = H5Dget_space(d);
        ok = sp >= 0 && H5Sget_simple_extent_npoints(sp) >= 0;
        if (sp >= 0) H5Sclose(sp);
        H5Dclose(d);
    } else {
        ok = H5Lexists(f, "/h5md", H5P_DEFAULT) > 0; /* closed before the first frame */
    }
    H5Fclose(f);
    return ok;
}

/* A failed run (clean: every write and the close succeeded): keep PATH.part if it can be read,
 * else remove it, say so in err and return -1. */
int h5md_part_keep_or_remove(const char *part, int clean, char *err, size_t errlen) {
    if (clean || h5md_part_readable(part)) return 0;
    char why[512];
    snprintf(why, sizeof why, "%s", err ? err : "");
    unlink(part);
    if (why[0])
        h5md_set_err(err, errlen, "%s; '%s' was unreadable after the failure and has been "
                     "removed: nothing could be kept", why, part);
    else
        h5md_set_err(err, errlen, "'%s' was unreadable after an earlier write error and has "
                     "been removed: nothing could be kept", part);
    return -1;
}

int h5md_publish(const char *part, const char *path, const char *sidecar_part,
                 const char *sidecar, char *err, size_t errlen) {
    if (rename(part, path) != 0) {
        h5md_set_err(err, errlen, "cannot rename '%s' to '%s': %s (the previous result is "
                     "unchanged)", part, path, strerror(errno));
        unlink(sidecar_part);
        return -1;
    }
    if (rename(sidecar_part, sidecar) != 0) {
        h5md_set_err(err, errlen, "cannot rename '%s' to '%s': %s ('%s' is complete; its old "
                     "sidecar was removed)", sidecar_part, sidecar, strerror(errno), path);
        unlink(sidecar);
        unlink(sidecar_part);
        return -1;
    }
    return 0;
}
