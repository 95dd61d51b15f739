/*
 * inlet.c — the conveyor inlets (docs/mixing.md 2.1) in the stepper: the kernel's stream
 * (kernel/jdem_inlet.h) turned into particles appended to the run.
 *
 * Capacity.  The particle arrays are allocated once for every particle the run can hold: the
 * scene's plus every copy of every section that starts by the last step (or the stop rule);
 * the run uses their active prefix [0, n).  A fixed capacity keeps the pointers of the
 * per-particle block stable (the force loops, the thread shares and the huge-page block hold
 * them), costs no copy when particles arrive, and is known exactly up front because the stream
 * is a rigid motion.
 *
 * Order.  Scene index (orig) n_scene + k is the k-th inserted particle.  The trajectory holds
 * the whole capacity set, sorted by id, as a growing set (io/h5md.h): a row's id is -1 until
 * its particle is inserted (and its vectors NaN): slot[] maps a scene index to its row.  A
 * deposit-height rule may end the stream before the capacity is reached; the rows of the
 * particles never inserted stay empty.
 *
 * Cost.  Before each step the run loop compares the step with next_step (the smallest cursor
 * step over the inlets); only at a step where particles are due does it pop them, append them
 * and rebuild the neighbour list.
 *
 * Deleted particles.  A scene with a domain (domain.c) has these rows too, with or without
 * inlets: a deleted particle's row goes back to id -1, and the scene indices close up over it
 * (sim_inlets_close_up), so the next inserted particle's scene index is still the count n.
 *
 * Bonded blocks.  The kernel inserts a bonded group whole at its start step; the section's bonds
 * of the copies inserted at a step are formed right after their particles are appended
 * (form_block_bonds), unstressed, and written to /connectivity at that step.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "checkpoint.h"
#include "jdem_inlet.h"
#include "sim.h"

typedef struct inlet_run {
    jd_inlet_spec spec;
    jd_inlet_stream st;
    jd_inlet_cursor *cursor;
    int64_t copies;        /* copies that start by the last step (capacity) */
} inlet_run;

/* A trajectory row: id first, so that bsearch on an id finds it. */
typedef struct jd_row {
    int64_t id;
    int32_t species;
    double radius, mass;   /* [m], [kg] */
} jd_row;

struct jd_sim_inlets {
    size_t n_inlets;
    inlet_run *run;
    size_t n_scene, cap;   /* the scene's particles; all the run can hold */
    int64_t *id;           /* [cap] id of each scene index */
    int32_t *slot;         /* [cap] row of each scene index in the trajectory (sorted by id) */
    jd_row *rows;          /* [cap] the trajectory's rows, sorted by id */
    double *frame;         /* [5 x 3 cap] the vectors of a frame in row order */
    int64_t *frame_id;     /* [cap] the ids of a frame in row order, -1: not inserted */
    jd_inlet_particle *buf; /* the particles due at a step, with their insertion checks: */
    double *worst;          /* the largest overlap of each with a particle in the domain [-] */
    size_t *with;           /* the index of that particle */
    unsigned char *skip;    /* 1: not inserted (kernel/jdem_inlet.h "occupied place") */
    size_t buf_cap;
    int64_t next_step;     /* the smallest next_step of the streams */
    double energy_in;      /* kinetic + gravitational energy the inserted particles brought [J] */
    int64_t lost;          /* particles deleted outside the domain (domain.c) */
    double energy_lost;    /* the energy they took (kernel/jdem_domain.h) [J] */
    double seconds;        /* wall time spent inserting [s] */
    FILE *log;             /* the insertion record (sim_inlets_log), or NULL */
};

static int by_id(const void *a, const void *b) {
    const int64_t x = *(const int64_t *)a, y = *(const int64_t *)b;
    return x < y ? -1 : x > y;
}

static jd_row row_of(const jd_scene *sc, int64_t id, int32_t material, double radius) {
    return (jd_row){.id = id, .species = material, .radius = radius,
                    .mass = jd_sphere_mass(radius, sc->materials[material].density)};
}

/* The trajectory rows: every particle the run can hold, sorted by id; slot[] of each scene
 * particle. */
static void make_rows(jd_sim_inlets *in, const jd_scene *sc) {
    size_t at = 0;
    for (size_t i = 0; i < in->n_scene; i++) {
        in->id[i] = sc->id[i];
        in->rows[at++] = row_of(sc, sc->id[i], sc->material[i], sc->radius[i]);
    }
    for (size_t k = 0; k < in->n_inlets; k++) {
        const inlet_run *r = &in->run[k];
        for (int64_t c = 0; c < r->copies; c++)
            for (size_t p = 0; p < r->spec.n; p++)
                in->rows[at++] = row_of(sc, r->spec.first_id + c * (int64_t)r->spec.n + (int64_t)p,
                                        r->spec.species[p], r->spec.radius[p]);
    }
    qsort(in->rows, in->cap, sizeof *in->rows, by_id);
    for (size_t i = 0; i < in->n_scene; i++) {
        const jd_row *hit = bsearch(&sc->id[i], in->rows, in->cap, sizeof *in->rows, by_id);
        in->slot[i] = (int32_t)(hit - in->rows);
    }
}

size_t sim_inlets_capacity(const jd_scene *sc) {
    size_t cap = sc->n_particles;
    for (size_t k = 0; k < sc->n_inlets; k++) {
        jd_inlet_spec sp;
        scene_inlet_spec(sc, k, &sp);
        cap += (size_t)jd_inlet_copies_by(&sp, sp.stop_step, sc->steps) * sp.n;
    }
    return cap;
}

/* Room for `need` due particles and their checks (a step can have more than a section due:
 * copies overlap in crossing time).  On failure the old buffers stay valid. */
static int grow_due(jd_sim_inlets *in, size_t need) {
    if (need <= in->buf_cap && in->buf) return 0;
    jd_inlet_particle *buf = realloc(in->buf, need * sizeof *buf);
    if (buf) in->buf = buf;
    double *worst = realloc(in->worst, need * sizeof *worst);
    if (worst) in->worst = worst;
    size_t *with = realloc(in->with, need * sizeof *with);
    if (with) in->with = with;
    unsigned char *skip = realloc(in->skip, need * sizeof *skip);
    if (skip) in->skip = skip;
    if (!buf || !worst || !with || !skip) return -1;
    in->buf_cap = need;
    return 0;
}

int sim_inlets_init(jd_sim *s, char *err, size_t errlen) {
    const jd_scene *sc = s->run.scene;
    if (!sc->n_inlets && !sc->has_domain) return 0;
    jd_sim_inlets *in = calloc(1, sizeof *in);
    if (!in) goto oom;
    s->inlets = in;
    in->n_inlets = sc->n_inlets;
    in->n_scene = sc->n_particles;
    in->cap = sim_inlets_capacity(sc);
    in->run = calloc(sc->n_inlets ? sc->n_inlets : 1, sizeof *in->run);
    in->id = malloc((in->cap ? in->cap : 1) * sizeof *in->id);
    in->slot = malloc((in->cap ? in->cap : 1) * sizeof *in->slot);
    in->rows = malloc((in->cap ? in->cap : 1) * sizeof *in->rows);
    in->frame = malloc(JD_INLET_FRAME_VECTORS * 3 * (in->cap ? in->cap : 1) * sizeof *in->frame);
    in->frame_id = malloc((in->cap ? in->cap : 1) * sizeof *in->frame_id);
    if (!in->run || !in->id || !in->slot || !in->rows || !in->frame || !in->frame_id) goto oom;
    in->next_step = JD_INLET_NEVER;
    for (size_t k = 0; k < sc->n_inlets; k++) {
        inlet_run *r = &in->run[k];
        scene_inlet_spec(sc, k, &r->spec);
        r->copies = jd_inlet_copies_by(&r->spec, r->spec.stop_step, sc->steps);
        r->cursor = malloc(r->spec.n * sizeof *r->cursor);
        if (!r->cursor) goto oom;
        jd_inlet_stream_init(&r->spec, &r->st, r->cursor);
        in->next_step = r->st.next_step < in->next_step ? r->st.next_step : in->next_step;
        if (r->spec.n > in->buf_cap) in->buf_cap = r->spec.n;
    }
    if (grow_due(in, in->buf_cap ? in->buf_cap : 1) != 0) goto oom;
    make_rows(in, sc);
    s->particles.ids = in->id;
    return 0;
oom:
    snprintf(err, errlen, "out of memory for the inlets");
    return -1;
}

void sim_inlets_free(jd_sim *s) {
    jd_sim_inlets *in = s->inlets;
    if (!in) return;
    for (size_t k = 0; in->run && k < in->n_inlets; k++) free(in->run[k].cursor);
    free(in->run);
    free(in->id);
    free(in->slot);
    free(in->rows);
    free(in->frame);
    free(in->frame_id);
    free(in->buf);
    free(in->worst);
    free(in->with);
    free(in->skip);
    free(in);
    s->inlets = NULL;
}

void sim_inlets_log(jd_sim *s, FILE *log) {
    if (s->inlets) s->inlets->log = log;
}

/* One inserted particle at index n, which is also its scene index (n_scene + the particles
 * inserted before it): its state, its constants, and the energy it brings.  Its force is its
 * weight, the force an ordinary particle alone would carry into the next step's first half
 * kick (after sim_finish_step every force holds the weight, also when the kicks add it). */
static void append(jd_sim *s, const jd_inlet_particle *p) {
    jd_sim_inlets *in = s->inlets;
    const size_t i = s->particles.n++;
    sim_particle_constants(&s->particles, &s->run, i, p->species, p->radius);
    s->particles.orig[i] = (int32_t)i;
    in->id[i] = p->id;
    const jd_row *hit = bsearch(&p->id, in->rows, in->cap, sizeof *in->rows, by_id);
    in->slot[i] = (int32_t)(hit - in->rows);
    for (int d = 0; d < 3; d++) {
        s->particles.x[3 * i + d] = p->position[d];
        s->particles.v[3 * i + d] = p->velocity[d];
        s->particles.omega[3 * i + d] = 0.0;
        s->particles.f[3 * i + d] = s->particles.mass[i] * s->run.g[d];
        s->particles.torque[3 * i + d] = 0.0;
    }
    in->energy_in += 0.5 * s->particles.mass[i] * jd_dot(p->velocity, p->velocity) -
                     s->particles.mass[i] * jd_dot(s->run.g, p->position);
    if (in->log) {
        char line[JD_INLET_RECORD_LINE_MAX];
        jd_inlet_record_line(p, line, sizeof line);
        fputs(line, in->log);
    }
}

/* The deposit-height rule (kernel/jdem_inlet.h) at its steps, on the state after this step's
 * insertions. */
static void check_height(jd_sim *s, size_t k) {
    inlet_run *r = &s->inlets->run[k];
    const jd_inlet *def = &s->run.scene->inlets[k];
    if (def->stop != JD_INLET_STOP_HEIGHT || !jd_inlet_height_due(s->step, def->every)) return;
    sim_finish_step(s); /* the speeds at this step */
    const jd_particles *ps = &s->particles;
    const double top = jd_inlet_deposit_top(ps->n, ps->x, ps->v, ps->radius, def->below_speed);
    jd_inlet_height_stop(&r->st, s->step, top, def->height);
}

/* Engine index of the particle with id `id` among the particles [n0, n1) just appended (their
 * ids increase: the stream's insertion order), or -1. */
static long appended_index(const jd_sim_inlets *in, size_t n0, size_t n1, int64_t id) {
    size_t lo = n0, hi = n1;
    while (lo < hi) {
        const size_t mid = lo + (hi - lo) / 2;
        if (in->id[mid] < id) lo = mid + 1; else hi = mid;
    }
    return lo < n1 && in->id[lo] == id ? (long)lo : -1;
}

/* The bonds of the groups inlet k inserted at this step, the particles [n0, n1): a group is
 * inserted whole (kernel/jdem_inlet.h), so a section bond (i, j) of copy c forms exactly when
 * (c, i) is among them.  Copies in increasing order, each copy's bonds in the section's (i, j)
 * order: the bonds of a step in increasing (id_a, id_b).  Indices [n0, n1) are still the append
 * order (the neighbour build that may renumber comes after). */
static int form_block_bonds(jd_sim *s, size_t k, size_t n0, size_t n1) {
    const jd_sim_inlets *in = s->inlets;
    const jd_inlet *def = &s->run.scene->inlets[k];
    const jd_inlet_spec *sp = &in->run[k].spec;
    if (!def->n_bonds || !s->bonds || n0 == n1) return 0;
    const int64_t n = (int64_t)sp->n;
    for (int64_t c = (in->id[n0] - sp->first_id) / n, last = (in->id[n1 - 1] - sp->first_id) / n;
         c <= last; c++)
        for (size_t b = 0; b < def->n_bonds; b++) {
            int64_t ids[2];
            jd_inlet_bond_ids(sp, c, (size_t)def->bond_pair[2 * b], (size_t)def->bond_pair[2 * b + 1], ids);
            const long i = appended_index(in, n0, n1, ids[0]);
            if (i < 0) continue; /* its group was inserted at another step */
            const long j = appended_index(in, n0, n1, ids[1]);
            if (j < 0 || sim_bonds_form(s->bonds, &s->particles, (int32_t)i, (int32_t)j,
                                        def->bond_type[b], s->step))
                return -1;
        }
    return 0;
}

/* Every particle of inlet r due at `step` into in->buf[0, *due), in pop order. */
static int pop_due(jd_sim_inlets *in, inlet_run *r, int64_t step, size_t *due) {
    size_t got;
    while (r->st.next_step == step) {
        if (*due == in->buf_cap && grow_due(in, 2 * in->buf_cap) != 0) return -1;
        got = jd_inlet_pop(&r->spec, &r->st, step, in->buf + *due, in->buf_cap - *due);
        if (got == 0) break;
        *due += got;
    }
    return 0;
}

/* The insertion check (kernel/jdem_inlet.h "Insertion into an occupied place") of inlet k's
 * due particles against the particles in the domain: in->skip[q] set, the first skips
 * reported, the count booked in the stream. */
static void skip_occupied(jd_sim *s, size_t k, size_t due) {
    jd_sim_inlets *in = s->inlets;
    inlet_run *r = &in->run[k];
    const jd_particles *ps = &s->particles;
    jd_inlet_worst_overlaps(in->buf, due, ps->n, ps->x, ps->radius, in->worst, in->with);
    const size_t skipped = jd_inlet_skip_groups(&r->spec, in->buf, due, in->worst, in->skip);
    for (size_t q = 0; q < due && skipped; q++) {
        if (!in->skip[q]) continue;
        const int64_t nth = sim_skipped_particles(s) + 1;
        if (nth <= JD_INLET_REPORTED) {
            char why[256];
            jd_inlet_skip_reason(why, sizeof why, in->worst[q],
                                 in->with[q] == SIZE_MAX ? -1 : sim_particle_id(ps, in->with[q]),
                                 r->spec.max_insert_overlap, nth);
            fprintf(stderr, "jdem: step %lld: inlet '%s' skips particle id %lld: %s\n",
                    (long long)s->step, s->run.scene->inlets[k].name, (long long)in->buf[q].id, why);
        }
        jd_inlet_book_skipped(&r->st, 1);
    }
}

static int insert_due(jd_sim *s, char *err, size_t errlen) {
    jd_sim_inlets *in = s->inlets;
    if (s->step != in->next_step) return 0;
    const double t0 = sim_clock();
    sim_finish_step(s); /* v at this step, so that the new particles join the state of it */
    size_t added = 0;
    in->next_step = JD_INLET_NEVER;
    for (size_t k = 0; k < in->n_inlets; k++) {
        inlet_run *r = &in->run[k];
        const size_t n0 = s->particles.n;
        size_t due = 0;
        if (pop_due(in, r, s->step, &due) != 0) {
            snprintf(err, errlen, "out of memory for the particles due at step %lld",
                     (long long)s->step);
            return -1;
        }
        skip_occupied(s, k, due);
        for (size_t q = 0; q < due && s->particles.n < in->cap; q++)
            if (!in->skip[q]) append(s, &in->buf[q]);
        added += s->particles.n - n0;
        if (form_block_bonds(s, k, n0, s->particles.n) != 0) {
            snprintf(err, errlen, "step %lld: a bond of inlet '%s' joins a particle not inserted "
                     "with its block, or memory ran out", (long long)s->step,
                     s->run.scene->inlets[k].name);
            return -1;
        }
        in->next_step = r->st.next_step < in->next_step ? r->st.next_step : in->next_step;
    }
    int rc = 0;
    if (added) {
        sim_particle_kinds(&s->fast, &s->particles, s->run.n_materials, s->opt.plain_loops);
        rc = sim_domain_delete(s, 0, err, errlen) || sim_neighbour_build(s, err, errlen);
    }
    in->seconds += sim_clock() - t0;
    return rc;
}

int sim_inlets_step(jd_sim *s, char *err, size_t errlen) {
    if (!s->inlets->n_inlets) return 0;
    const int rc = insert_due(s, err, errlen);
    for (size_t k = 0; rc == 0 && k < s->inlets->n_inlets; k++) check_height(s, k);
    return rc;
}

double sim_inlets_pending_particle_steps(const jd_sim *s, int64_t last) {
    if (!s->inlets) return 0.0;
    double sum = 0.0;
    for (size_t k = 0; k < s->inlets->n_inlets; k++) {
        const inlet_run *r = &s->inlets->run[k];
        sum += jd_inlet_pending_particle_steps(
            &r->spec, r->st.cursor, jd_inlet_copies_by(&r->spec, r->st.stop_step, last), last);
    }
    return sum;
}

int64_t sim_inlets_inserted(const jd_sim *s) {
    return s->inlets ? (int64_t)s->particles.n + s->inlets->lost - (int64_t)s->inlets->n_scene : 0;
}

double sim_inlets_seconds(const jd_sim *s) { return s->inlets ? s->inlets->seconds : 0.0; }

double sim_inlets_energy(const jd_sim *s) { return s->inlets ? s->inlets->energy_in : 0.0; }

int64_t sim_skipped_particles(const jd_sim *s) {
    int64_t n = 0;
    for (size_t k = 0; s->inlets && k < s->inlets->n_inlets; k++) n += s->inlets->run[k].st.skipped;
    return n;
}

int64_t sim_lost_particles(const jd_sim *s) { return s->inlets ? s->inlets->lost : 0; }

double sim_lost_energy(const jd_sim *s) { return s->inlets ? s->inlets->energy_lost : 0.0; }

void sim_inlets_close_up(jd_sim *s, const unsigned char *gone_scene, size_t n, size_t gone,
                         double energy) {
    jd_sim_inlets *in = s->inlets;
    size_t w = 0;
    for (size_t p = 0; p < n; p++) {
        if (gone_scene[p]) continue;
        in->id[w] = in->id[p];
        in->slot[w] = in->slot[p];
        w++;
    }
    in->lost += (int64_t)gone;
    in->energy_lost += energy;
}

/* The trajectory's particle set: every row the run can hold. */
int sim_inlets_particles(const jd_sim *s, int64_t *id, int32_t *species, double *radius,
                         double *mass) {
    const jd_sim_inlets *in = s->inlets;
    for (size_t k = 0; k < in->cap; k++) {
        id[k] = in->rows[k].id;
        species[k] = in->rows[k].species;
        radius[k] = in->rows[k].radius;
        mass[k] = in->rows[k].mass;
    }
    return 0;
}

size_t sim_inlets_rows(const jd_sim *s) { return s->inlets ? s->inlets->cap : s->particles.n; }

double *sim_inlets_frame_rows(const jd_sim *s, int k, const double *scene_ordered) {
    const jd_sim_inlets *in = s->inlets;
    double *out = in->frame + (size_t)k * 3 * in->cap;
    for (size_t r = 0; r < 3 * in->cap; r++) out[r] = NAN;
    for (size_t j = 0; j < s->particles.n; j++)
        memcpy(&out[3 * (size_t)in->slot[j]], &scene_ordered[3 * j], 3 * sizeof *out);
    return out;
}

const int64_t *sim_inlets_frame_ids(const jd_sim *s) {
    const jd_sim_inlets *in = s->inlets;
    for (size_t r = 0; r < in->cap; r++) in->frame_id[r] = -1;
    for (size_t j = 0; j < s->particles.n; j++) in->frame_id[in->slot[j]] = in->id[j];
    return in->frame_id;
}

void sim_inlets_state(jd_sim *s, jd_inlet_state_view *v) {
    jd_sim_inlets *in = s->inlets;
    *v = (jd_inlet_state_view){.n_inlets = in->n_inlets, .next_step = &in->next_step,
                               .energy_in = &in->energy_in, .seconds = &in->seconds,
                               .lost = &in->lost, .energy_lost = &in->energy_lost,
                               .id = in->id, .slot = in->slot};
}

jd_inlet_stream *sim_inlets_stream(jd_sim *s, size_t k, size_t *n) {
    inlet_run *r = &s->inlets->run[k];
    *n = r->spec.n;
    return &r->st;
}
