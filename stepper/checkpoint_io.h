/*
 * checkpoint_io.h — internal to the checkpoint (checkpoint.c, checkpoint_state.c,
 * checkpoint_io.c): one traversal of the run's state serves both directions, so that what is
 * written and what is read can never differ.  Each ck_* call writes its value to the file, or
 * reads it back into place, checking its size.
 */
#ifndef JDEM_CHECKPOINT_IO_H
#define JDEM_CHECKPOINT_IO_H

#include <hdf5.h>
#include <stddef.h>
#include <stdint.h>

#include "checkpoint.h"

typedef struct ck_io {
    hid_t file;
    int reading;         /* 1: read into place; 0: write */
    const char *path;    /* the file, for messages */
    int failed;          /* the first failure's message is in err */
    int no_memory;       /* that failure was an allocation */
    uint64_t digest;     /* FNV-1a over every value passed so far, with its name: stored last
                            and compared at a read, so that a changed value is caught */
    char *err;
    size_t errlen;
} ck_io;

/* count values of memtype (H5T_NATIVE_DOUBLE, _INT64, _INT32, _UINT8) as dataset `name` (a path
 * below the root; intermediate groups are created).  Reading: the dataset must hold count
 * values. */
void ck_array(ck_io *io, const char *name, hid_t memtype, size_t count, void *data);
/* one value (a dataset of one element) */
void ck_double(ck_io *io, const char *name, double *v);
void ck_int64(ck_io *io, const char *name, int64_t *v);
void ck_int(ck_io *io, const char *name, int *v);
/* a count written as int64; reading: it must be at most max */
void ck_count(ck_io *io, const char *name, size_t *n, size_t max);
/* FNV-1a (64 bit) of bytes */
uint64_t ck_fnv1a(const void *data, size_t bytes);
/* record a failure (the first one is kept) */
void ck_fail(ck_io *io, const char *fmt, ...);

/* checkpoint_state.c: the whole state of s, in or out */
void ck_state(ck_io *io, jd_sim *s);

#endif /* JDEM_CHECKPOINT_IO_H */
