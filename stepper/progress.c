/*
 * progress.c — the progress line on stderr: on a terminal a line refreshed at most 10 times a
 * second; otherwise (logs, CI) a plain line every 30 s of wall time.  CLOCK_MONOTONIC only, so a
 * clock change cannot produce nonsense rates.
 */
#include <stdio.h>
#include <time.h>
#include <unistd.h>

#include "sim.h"

static double now(void) {
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

void progress_start(jd_progress *p, int enabled, int64_t total_steps) {
    *p = (jd_progress){.enabled = enabled, .tty = isatty(STDERR_FILENO), .total = total_steps};
    p->t_start = p->t_last = now();
}

/* The ETA: the work left in particle-steps (the present particles to the last step, and those
 * an inlet has still to insert) over the particle-steps per second so far, so that a growing
 * set is not timed at its early, cheaper rate. */
static void print_line(jd_progress *p, int64_t step, double sim_time, double t) {
    const double elapsed = t - p->t_start;
    const double rate = elapsed > 0.0 ? p->particle_steps / elapsed : 0.0; /* particle-steps/s */
    const double left = (double)p->n * (double)(p->total - step) +
                        (p->pending ? p->pending(p->ctx, p->total) : 0.0);
    char eta[32] = "?"; /* no rate yet (an inlet's first particles have not arrived) */
    if (rate > 0.0) snprintf(eta, sizeof eta, "%.0f s", left / rate);
    fprintf(stderr, "%sstep %lld/%lld  t = %.6g s  %zu particles  %.3g particle-steps/s  "
            "ETA %s%s", p->tty ? "\r\033[K" : "", (long long)step, (long long)p->total,
            sim_time, p->n, rate, eta, p->tty ? "" : "\n");
    fflush(stderr);
    p->printed = 1;
}

void progress_update(jd_progress *p, int64_t step, double sim_time, size_t n_particles) {
    p->n = n_particles;
    p->particle_steps += (double)n_particles;
    if (!p->enabled) return;
    const double t = now();
    if (t - p->t_last < (p->tty ? 0.1 : 30.0)) return;
    p->t_last = t;
    print_line(p, step, sim_time, t);
}

/* End a refreshing line so the next message starts on a fresh line. */
void progress_finish(jd_progress *p) {
    if (p->enabled && p->tty && p->printed) fputc('\n', stderr);
}
