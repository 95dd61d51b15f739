/*
 * h5md_resume.h — continuing the trajectory of an interrupted run (both engines: build/jdem's
 * --resume and dump h5md/jdem's `resume yes` after a LIGGGHTS read_restart).
 *
 * The interrupted run left OUT.part (its frames up to where it stopped).  The resumed run
 * moves it aside (jd_h5md_resume_source), creates a fresh writer for OUT and copies into it the
 * prefix up to the step it resumes at (jd_h5md_resume_copy), then writes on; the result equals
 * the uninterrupted run's file.  A dump that assigns its own rows to a growing particle set
 * takes the prefix's rows first (jd_h5md_resume_rows).
 */
#ifndef JDEM_IO_H5MD_RESUME_H
#define JDEM_IO_H5MD_RESUME_H

#include <stddef.h>
#include <stdint.h>

#include "h5md.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Before a resumed run writes to the trajectory OUT: the killed run's OUT.part (or, after an
 * interrupted resume, OUT.resume) is moved to OUT.resume, written into src (srclen bytes); it
 * must hold the frames up to frame_step.  0, or -1 with err (OUT.part locked by a running run,
 * or neither file holds the prefix). */
int jd_h5md_resume_source(const char *out, int64_t frame_step, char *src, size_t srclen,
                          char *err, size_t errlen);

/* Copy src's frames up to frame_step and its observables and bond tables up to step into the
 * fresh writer h; the caller then removes src.  0, or -1 with err. */
int jd_h5md_resume_copy(const char *src, jd_h5md *h, int64_t frame_step, int64_t step,
                        char *err, size_t errlen);

/* The particle rows of src up to frame_step, as jd_h5md_create takes them: for a fixed set all
 * of its rows; for a growing set the rows live in one of the frames up to frame_step, each with
 * the id it first shows there (the rows the interrupted run added later follow the order of
 * its later frames, which the resumed run assigns again).  The arrays (id, species, radius,
 * mass) are malloc'd: release them with jd_h5md_resume_rows_free.  0, or -1 with err. */
int jd_h5md_resume_rows(const char *src, int64_t frame_step, jd_h5md_particles *rows, char *err,
                        size_t errlen);
void jd_h5md_resume_rows_free(jd_h5md_particles *rows);

#ifdef __cplusplus
}
#endif

#endif
