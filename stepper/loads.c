/*
 * loads.c — held particles and constant external forces (scene keys particles[].fixed and
 * particles[].force, docs/scenes.md), applied after every other force as LIGGGHTS' post-force
 * fixes do (fix addforce, then fix freeze): the external force is added, then a held particle's
 * force and torque are set to zero, so it keeps its initial velocity and spin.
 *
 * Both do work on the particles, which the energy balance books into wall_work (the external
 * work term) with the trapezoidal rule of the contacts (jd_load_work, kernel/jdem_kernel.h, the
 * same call as LIGGGHTS' fix jdem/loads): half the sum of the forces at the two ends of a step
 * times the step's displacement (v at force time is the half-step velocity).
 */
#include <stdlib.h>
#include <string.h>

#include "checkpoint.h"
#include "sim.h"

struct jd_loads {
    size_t n;
    int32_t *index;   /* loaded particles (engine indices; set up in scene order, before the
                         first renumbering, and remapped by sim_loads_permute) */
    int32_t *scene;   /* their index in the scene's arrays (force, fixed): the scene index at
                         the start, which a deletion outside the domain does not change */
    double *f_prev;   /* 6 per loaded particle: force and torque applied at the previous
                         evaluation (external force, or the constraint's reaction) */
};

int sim_loads_init(jd_loads **loads, const jd_scene *sc, char *err, size_t errlen) {
    if (!sc->has_loads) return 0;
    jd_loads *l = calloc(1, sizeof *l);
    size_t n = 0;
    for (size_t i = 0; i < sc->n_particles; i++) {
        const double *F = &sc->force[3 * i];
        n += sc->fixed[i] || F[0] != 0.0 || F[1] != 0.0 || F[2] != 0.0;
    }
    if (l) {
        l->index = malloc((n ? n : 1) * sizeof *l->index);
        l->scene = malloc((n ? n : 1) * sizeof *l->scene);
        l->f_prev = calloc(6 * (n ? n : 1), sizeof *l->f_prev);
    }
    if (!l || !l->index || !l->scene || !l->f_prev) {
        if (l) {
            free(l->index);
            free(l->scene);
            free(l->f_prev);
        }
        free(l);
        snprintf(err, errlen, "out of memory for the particle loads");
        return -1;
    }
    for (size_t i = 0; i < sc->n_particles; i++) {
        const double *F = &sc->force[3 * i];
        if (sc->fixed[i] || F[0] != 0.0 || F[1] != 0.0 || F[2] != 0.0) {
            l->scene[l->n] = (int32_t)i;
            l->index[l->n++] = (int32_t)i;
        }
    }
    *loads = l;
    return 0;
}

void sim_loads_free(jd_loads **loads) {
    if (!*loads) return;
    free((*loads)->index);
    free((*loads)->scene);
    free((*loads)->f_prev);
    free(*loads);
    *loads = NULL;
}

void sim_loads_permute(jd_loads *l, const int32_t *new_index) {
    if (!l) return;
    for (size_t k = 0; k < l->n; k++) l->index[k] = new_index[l->index[k]];
}

void sim_loads_drop_from(jd_loads *l, size_t keep) {
    if (!l) return;
    size_t w = 0;
    for (size_t k = 0; k < l->n; k++) {
        if ((size_t)l->index[k] >= keep) continue;
        l->index[w] = l->index[k];
        l->scene[w] = l->scene[k];
        memmove(&l->f_prev[6 * w], &l->f_prev[6 * k], 6 * sizeof *l->f_prev);
        w++;
    }
    l->n = w;
}

void sim_loads_apply(jd_loads *l, jd_particles *ps, const jd_run_constants *run,
                     jd_accounts *accounts, int in_setup) {
    const jd_scene *sc = run->scene;
    double work = 0.0;
    for (size_t k = 0; k < l->n; k++) {
        const size_t i = (size_t)l->index[k], p = (size_t)l->scene[k]; /* engine, scene arrays */
        double *f = ps->f + 3 * i, *t = ps->torque + 3 * i, *prev = l->f_prev + 6 * k;
        double applied[6];
        for (int d = 0; d < 3; d++) {
            f[d] += sc->force[3 * p + d];
            /* a held particle: the constraint applies minus everything else */
            applied[d] = sc->fixed[p] ? -f[d] : sc->force[3 * p + d];
            applied[3 + d] = sc->fixed[p] ? -t[d] : 0.0;
            if (sc->fixed[p]) f[d] = t[d] = 0.0;
        }
        const double *v = ps->v + 3 * i, *w = ps->omega + 3 * i;
        work += jd_load_work(prev, applied, v, w, run->dt);
        memcpy(prev, applied, sizeof applied);
    }
    if (!in_setup) accounts->wall_work += work;
}

size_t sim_loads_state(jd_loads *l, int32_t **index, int32_t **scene, double **f_prev) {
    *index = l->index;
    *scene = l->scene;
    *f_prev = l->f_prev;
    return l->n;
}

void sim_loads_set_count(jd_loads *l, size_t n) {
    if (n <= l->n) l->n = n;
}
