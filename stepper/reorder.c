/*
 * reorder.c — spatial sorting of the particles (sim.h, "Particle order").
 *
 * sim_neighbour_build renumbers the particles into the order of their neighbour cells before
 * every build, so that a contact loop walking the list (sorted by i) reads particles j that lie
 * close to i in memory too, and the integration loops stream through memory in space order.
 * The contact lists built before the renumbering still carry the history that the new lists
 * inherit (neighbour.c, carry_over): their entries are re-keyed to the new indices here and
 * re-sorted by (i, j).  A pair whose ends swap order (new i > new j) has its history turned
 * around: the vector entries that change sign when a and b swap (jd_contact_state_newton,
 * jd_rolling_state_newton, the kernel's own list) are negated, exactly as LIGGGHTS does when
 * it stores a contact at the other atom.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "sim.h"

/* a[k] = a[old_of_new[k]] for vectors of `width` doubles per particle (scratch: width n). */
static void gather_doubles(double *a, size_t width, const int32_t *old_of_new, size_t n,
                           double *scratch) {
    for (size_t k = 0; k < n; k++)
        for (size_t d = 0; d < width; d++) scratch[width * k + d] = a[width * (size_t)old_of_new[k] + d];
    memcpy(a, scratch, width * n * sizeof *a);
}

static void gather_ints(int32_t *a, const int32_t *old_of_new, size_t n, int32_t *scratch) {
    for (size_t k = 0; k < n; k++) scratch[k] = a[old_of_new[k]];
    memcpy(a, scratch, n * sizeof *a);
}

static void turn_around(jd_contact_list *l, size_t c) {
    double *v = l->hist + (size_t)l->hw * c;
    for (int k = 0; k < l->hw; k++)
        if (jd_contact_state_newton[k]) v[k] = -v[k];
    double *w = l->rhist + (size_t)l->rw * c;
    for (int k = 0; k < l->rw; k++)
        if (jd_rolling_state_newton[k]) w[k] = -w[k];
}

/* Re-key list l to the new indices (j too when `pairs`), turn around swapped pairs, and sort it
 * by (i, j) into `out` (a counting sort by i, then insertion sort of each i's few entries by j).
 * Per-pair constants are not moved: the list is rebuilt right after (neighbour.c). */
static int rekey(jd_contact_list *l, int pairs, const int32_t *new_of_old, size_t n,
                 jd_contact_list *out) {
    const size_t m = l->n;
    int32_t *start = calloc(n + 1, sizeof *start), *order = malloc((m ? m : 1) * sizeof *order);
    if (!start || !order) {
        free(start);
        free(order);
        return -1;
    }
    for (size_t c = 0; c < m; c++) {
        int32_t i = new_of_old[l->i[c]];
        if (pairs) {
            int32_t j = new_of_old[l->j[c]];
            if (i > j) {
                const int32_t t = i;
                i = j;
                j = t;
                turn_around(l, c);
            }
            l->j[c] = j;
        }
        l->i[c] = i;
        start[i + 1]++;
    }
    for (size_t k = 0; k < n; k++) start[k + 1] += start[k];
    for (size_t c = 0; c < m; c++) order[start[l->i[c]]++] = (int32_t)c;
    /* start[k] is now the end of segment k; segment k begins at start[k - 1] (0 for k = 0) */
    for (size_t k = 0; k < n; k++) {
        const int32_t b = k ? start[k - 1] : 0, e = start[k];
        for (int32_t a = b + 1; a < e; a++) {
            const int32_t v = order[a];
            int32_t q = a;
            for (; q > b && l->j[order[q - 1]] > l->j[v]; q--) order[q] = order[q - 1];
            order[q] = v;
        }
    }
    for (size_t p = 0; p < m; p++) {
        const int32_t c = order[p];
        out->i[p] = l->i[c];
        out->j[p] = l->j[c];
        const size_t hw = (size_t)l->hw, rw = (size_t)l->rw;
        memcpy(out->hist + hw * p, l->hist + hw * (size_t)c, hw * sizeof *out->hist);
        if (rw) memcpy(out->rhist + rw * p, l->rhist + rw * (size_t)c, rw * sizeof *out->rhist);
    }
    out->n = out->n_touch = m; /* one sorted run */
    free(start);
    free(order);
    return 0;
}

/* List l of n particles re-keyed and sorted through spare, which then takes l's old buffers;
 * kind: the run's (sim_list_kind), which the record lengths alone do not tell (MEPA's contact
 * record is as long with and without the energy accounts, its rolling record is not). */
static int reorder_list(jd_contact_list *l, jd_contact_list *spare, int pairs,
                        const int32_t *new_of_old, size_t n, unsigned kind) {
    if (l->n == 0) return 0;
    if (sim_list_reserve(spare, l->n, kind) != 0 ||
        rekey(l, pairs, new_of_old, n, spare) != 0)
        return -1;
    const jd_contact_list t = *l;
    *l = *spare;
    *spare = t;
    return 0;
}

int sim_reorder(jd_sim *s, const int32_t *old_of_new, char *err, size_t errlen) {
    jd_particles *ps = &s->particles;
    jd_neighbour_lists *lists = &s->lists;
    const size_t n = ps->n;
    int32_t *new_of_old = malloc((n ? n : 1) * sizeof *new_of_old);
    if (!new_of_old) goto oom;
    for (size_t k = 0; k < n; k++) new_of_old[old_of_new[k]] = (int32_t)k;
    /* the lists first: they are the only step that can fail, and the arrays stay untouched */
    const unsigned kind = sim_list_kind(s->run.features);
    if (reorder_list(&lists->pairs, &lists->spare, 1, new_of_old, n, kind) != 0 ||
        reorder_list(&lists->wall_pairs, &lists->wall_spare, 0, new_of_old, n, kind) != 0) {
        free(new_of_old);
        goto oom;
    }
    double *const vec[] = {ps->x, ps->v, ps->omega, ps->f, ps->torque, lists->x_build};
    for (size_t k = 0; k < sizeof vec / sizeof *vec; k++)
        gather_doubles(vec[k], 3, old_of_new, n, ps->scratch);
    double *const per[] = {ps->radius, ps->mass, ps->inertia, ps->kp, ps->kw, ps->dtfm, ps->dtirot,
                           lists->half_skin};
    for (size_t k = 0; k < sizeof per / sizeof *per; k++)
        gather_doubles(per[k], 1, old_of_new, n, ps->scratch);
    int32_t *iscratch = (int32_t *)ps->scratch; /* 3n doubles hold n int32 */
    gather_ints(ps->species, old_of_new, n, iscratch);
    gather_ints(ps->orig, old_of_new, n, iscratch);
    ps->sorted = 1;
    sim_bonds_permute(s->bonds, new_of_old, n);
    sim_loads_permute(s->loads, new_of_old);
    free(new_of_old);
    return 0;
oom:
    snprintf(err, errlen, "out of memory renumbering %zu particles", n);
    return -1;
}

static void to_scene(double *a, const int32_t *orig, size_t n, double *scratch) {
    for (size_t i = 0; i < n; i++)
        for (int d = 0; d < 3; d++) scratch[3 * (size_t)orig[i] + d] = a[3 * i + d];
    memcpy(a, scratch, 3 * n * sizeof *a);
}

void sim_vectors_to_scene_order(jd_particles *ps) {
    if (!ps->sorted) return;
    double *const vec[] = {ps->x, ps->v, ps->omega, ps->f, ps->torque};
    for (size_t k = 0; k < sizeof vec / sizeof *vec; k++) to_scene(vec[k], ps->orig, ps->n, ps->scratch);
}

void sim_vectors_to_sim_order(jd_particles *ps) {
    if (!ps->sorted) return;
    double *const vec[] = {ps->x, ps->v, ps->omega, ps->f, ps->torque};
    for (size_t k = 0; k < sizeof vec / sizeof *vec; k++)
        gather_doubles(vec[k], 3, ps->orig, ps->n, ps->scratch);
}

void sim_scalars_in_scene_order(const jd_particles *ps, const double *a, double *out) {
    for (size_t i = 0; i < ps->n; i++) out[ps->orig[i]] = a[i];
}

