/*
 * mesh_walls.c — STL mesh walls in the stepper (mesh_walls.h): set-up, motion, candidates,
 * the serial force loop, the observables.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "h5md.h"
#include "mesh_walls.h"

static int nonzero3(const double v[3]) { return v[0] != 0.0 || v[1] != 0.0 || v[2] != 0.0; }

/* The wall's velocity at the corners of a moving, conveyor or spinning mesh. */
static void corner_velocities(jd_sim_mesh *m, const jd_mesh_wall *in) {
    if (m->motion.kind != JD_MESH_STILL)
        jd_mesh_motion_velocity(&m->motion, 3 * m->topo.ntri, (const double(*)[3])m->corner,
                                (double(*)[3])m->vnode);
    else if (in->spinning)
        for (size_t t = 0; t < m->topo.ntri; t++)
            jd_mesh_spin_velocity(in->spin_origin, in->spin_axis, in->spin_omega,
                                  (const double(*)[3])m->corner[t], m->vnode[t]);
    else
        for (size_t t = 0; t < m->topo.ntri; t++)
            jd_mesh_conveyor_velocity(in->surface_velocity, (const double(*)[3])m->corner[t], m->vnode[t]);
}

/* The corners, motion and topology of scene wall `in` into m (the scene reader has run the
 * same build). */
static int mesh_init(jd_sim_mesh *m, const jd_mesh_wall *in, size_t stride, char *err, size_t errlen) {
    const size_t n = in->ntri;
    const int moving = in->motion.kind != JD_MESH_STILL;
    m->motion = in->motion;
    m->corner = malloc(n * sizeof *m->corner);
    const int surface = nonzero3(in->surface_velocity) || in->spinning;
    if (moving || surface) m->vnode = malloc(n * sizeof *m->vnode);
    if (moving) m->corner_at_build = malloc(n * sizeof *m->corner_at_build);
    if (!m->corner || (moving && (!m->vnode || !m->corner_at_build)) ||
        (surface && !m->vnode)) {
        snprintf(err, errlen, "out of memory for the corners of mesh wall '%s'", in->name);
        return -1;
    }
    memcpy(m->corner, in->corner, n * sizeof *m->corner);
    jd_mesh_storage *st = &m->storage;
    st->vertex = malloc(3 * n * sizeof *st->vertex);
    st->tri_vertex = malloc(n * sizeof *st->tri_vertex);
    st->tri_edge = malloc(n * sizeof *st->tri_edge);
    st->edge_vertex = malloc(3 * n * sizeof *st->edge_vertex);
    st->edge_valence = malloc(3 * n * sizeof *st->edge_valence);
    st->vertex_valence = malloc(3 * n * sizeof *st->vertex_valence);
    st->scratch = malloc(3 * n * sizeof *st->scratch);
    m->material = in->material;
    m->hist.stride = stride;
    size_t bad = 0;
    if (!st->vertex || !st->tri_vertex || !st->tri_edge || !st->edge_vertex || !st->edge_valence ||
        !st->vertex_valence || !st->scratch) {
        snprintf(err, errlen, "out of memory for the topology of mesh wall '%s'", in->name);
        return -1;
    }
    if (jd_mesh_build(n, (const double(*)[3][3])m->corner, st, &m->topo, &bad) != JD_MESH_OK) {
        snprintf(err, errlen, "mesh wall '%s': triangle %zu is degenerate", in->name, bad);
        return -1;
    }
    if (m->vnode) corner_velocities(m, in);
    return 0;
}

int sim_mesh_walls_init(jd_mesh_walls **out, const jd_run_constants *run, char *err, size_t errlen) {
    const jd_scene *sc = run->scene;
    *out = NULL;
    if (!sc->n_mesh_walls) return 0;
    jd_mesh_walls *mw = calloc(1, sizeof *mw);
    const unsigned F = run->features;
    const size_t stride = 3 + (size_t)jd_contact_record_len(F) + (size_t)jd_rolling_record_len(F);
    if (mw) {
        mw->mesh = calloc(sc->n_mesh_walls, sizeof *mw->mesh);
        mw->next = calloc(JD_MESH_SLOTS * stride, sizeof *mw->next);
    }
    if (!mw || !mw->mesh || !mw->next) {
        snprintf(err, errlen, "out of memory for the mesh walls");
        sim_mesh_walls_free(mw);
        return -1;
    }
    mw->built_at = -1;
    mw->features = F;
    for (size_t k = 0; k < sc->n_mesh_walls; k++) {
        mw->n = k + 1;
        if (mesh_init(&mw->mesh[k], &sc->mesh_walls[k], stride, err, errlen) != 0) {
            sim_mesh_walls_free(mw);
            return -1;
        }
    }
    *out = mw;
    return 0;
}

void sim_mesh_walls_free(jd_mesh_walls *mw) {
    if (!mw) return;
    for (size_t k = 0; k < mw->n; k++) {
        jd_mesh_storage *st = &mw->mesh[k].storage;
        free(st->vertex);
        free(st->tri_vertex);
        free(st->tri_edge);
        free(st->edge_vertex);
        free(st->edge_valence);
        free(st->vertex_valence);
        free(st->scratch);
        free(mw->mesh[k].hist.slots);
        free(mw->mesh[k].corner);
        free(mw->mesh[k].vnode);
        free(mw->mesh[k].corner_at_build);
    }
    free(mw->mesh);
    free(mw->next);
    free(mw->cand_start);
    free(mw->cand_tri);
    free(mw->closest);
    free(mw->is_contact);
    sim_mesh_cells_free(&mw->cells);
    free(mw);
}

/* Room in h for scene indices below n (new ones empty). */
static int history_reserve(jd_mesh_history *h, size_t n) {
    if (n <= h->n) return 0;
    const size_t per = JD_MESH_SLOTS * h->stride;
    double *p = realloc(h->slots, n * per * sizeof *p);
    if (!p) return -1;
    memset(p + h->n * per, 0, (n - h->n) * per * sizeof *p);
    h->slots = p;
    h->n = n;
    return 0;
}

/* Particle with scene index o loses its history with a mesh: the dissipation is booked. */
static void history_drop(jd_mesh_walls *mw, jd_mesh_history *h, size_t o, unsigned F) {
    double *slot = h->slots + o * JD_MESH_SLOTS * h->stride;
    const int hw = jd_contact_record_len(F), rw = jd_rolling_record_len(F);
    for (int c = 0; c < JD_MESH_SLOTS; c++) {
        jd_contact_state st;
        const double *r = slot + (size_t)c * h->stride + 3;
        jd_record_load(r, hw, r + hw, rw, &st, NULL);
        jd_contact_harvest(&st, 1.0, &mw->e_damp_dropped, &mw->e_fric_dropped);
    }
    memset(slot, 0, JD_MESH_SLOTS * h->stride * sizeof *slot);
}

void sim_mesh_walls_close_up(jd_mesh_walls *mw, const unsigned char *gone_scene, size_t n,
                             unsigned F) {
    for (size_t k = 0; k < mw->n; k++) {
        jd_mesh_history *h = &mw->mesh[k].hist;
        const size_t per = JD_MESH_SLOTS * h->stride, top = n < h->n ? n : h->n;
        size_t w = 0;
        for (size_t o = 0; o < top; o++) {
            if (gone_scene[o]) {
                history_drop(mw, h, o, F);
                continue;
            }
            if (w != o) memcpy(h->slots + w * per, h->slots + o * per, per * sizeof *h->slots);
            w++;
        }
        if (top > w) memset(h->slots + w * per, 0, (top - w) * per * sizeof *h->slots);
    }
}

int sim_mesh_history_resize(jd_mesh_history *h, size_t n) {
    free(h->slots);
    h->slots = NULL;
    h->n = 0;
    return history_reserve(h, n);
}

int sim_mesh_candidates_reserve(jd_mesh_walls *mw, size_t n_particles, size_t n_candidates) {
    free(mw->cand_start);
    mw->cand_start = malloc(mw->n * (n_particles + 1) * sizeof *mw->cand_start);
    if (n_candidates > mw->cand_cap) {
        int32_t *p = realloc(mw->cand_tri, n_candidates * sizeof *p);
        if (!p) return -1;
        mw->cand_tri = p;
        mw->cand_cap = n_candidates;
    }
    return mw->cand_start ? 0 : -1;
}

/* Room for a sphere's evaluation over `widest` candidates. */
static int scratch_reserve(jd_mesh_walls *mw, size_t widest) {
    if (widest <= mw->scratch_cap) return 0;
    free(mw->closest);
    free(mw->is_contact);
    mw->closest = malloc(widest * sizeof *mw->closest);
    mw->is_contact = malloc(widest);
    if (!mw->closest || !mw->is_contact) return -1;
    mw->scratch_cap = widest;
    return 0;
}

static int push_candidate(jd_mesh_walls *mw, size_t at, int32_t t) {
    if (at == mw->cand_cap) {
        const size_t cap = mw->cand_cap ? 2 * mw->cand_cap : 1024;
        int32_t *p = realloc(mw->cand_tri, cap * sizeof *p);
        if (!p) return -1;
        mw->cand_tri = p;
        mw->cand_cap = cap;
    }
    mw->cand_tri[at] = t;
    return 0;
}

/* Particle i's candidates of mesh m from its position x [m] and reach [m] appended at *at:
 * the grid's triangles near x within reach (every triangle with allpairs), ascending. */
static int particle_candidates(jd_mesh_walls *mw, const jd_sim_mesh *m, const double *x, double reach,
                               int allpairs, size_t *at) {
    const long near = allpairs ? (long)m->topo.ntri : sim_mesh_cells_near(&mw->cells, x, reach);
    if (near < 0) return -1;
    for (long e = 0; e < near; e++) {
        const int32_t t = allpairs ? (int32_t)e : mw->cells.found[e];
        jd_mesh_closest c;
        jd_mesh_closest_feature(&m->topo, t, x, &c);
        if ((allpairs || c.dist2 < reach * reach) && push_candidate(mw, (*at)++, t) != 0) return -1;
    }
    return 0;
}

/* Every triangle within R + skin/2 + its half skin of each particle's position at the last
 * neighbour build, ascending per particle and mesh; particles left without candidates lose
 * their history (they cannot touch the mesh before the next build). */
static int build_candidates(jd_mesh_walls *mw, const jd_sim *s) {
    const jd_particles *ps = &s->particles;
    const size_t np = ps->n;
    free(mw->cand_start);
    mw->cand_start = malloc((mw->n * (np + 1)) * sizeof *mw->cand_start);
    if (!mw->cand_start) return -1;
    size_t at = 0, widest = 1, n_orig = 0;
    double reach_max = 0.0; /* the largest radius + wall margin */
    for (size_t i = 0; i < np; i++) {
        if ((size_t)ps->orig[i] + 1 > n_orig) n_orig = (size_t)ps->orig[i] + 1;
        reach_max = fmax(reach_max, ps->radius[i] + sim_wall_margin(&s->lists, i));
    }
    for (size_t k = 0; k < mw->n; k++) {
        jd_sim_mesh *m = &mw->mesh[k];
        if (history_reserve(&m->hist, n_orig) != 0) return -1;
        size_t *start = mw->cand_start + k * (np + 1);
        if (m->corner_at_build) memcpy(m->corner_at_build, m->corner, m->topo.ntri * sizeof *m->corner);
        if (!s->opt.allpairs &&
            sim_mesh_cells_build(&mw->cells, m->topo.ntri, (const double(*)[3][3])m->corner,
                                 reach_max) != 0)
            return -1;
        for (size_t i = 0; i < np; i++) {
            start[i] = at;
            if (particle_candidates(mw, m, s->lists.x_build + 3 * i,
                                    ps->radius[i] + sim_wall_margin(&s->lists, i),
                                    s->opt.allpairs, &at) != 0)
                return -1;
            if (at == start[i]) history_drop(mw, &m->hist, (size_t)ps->orig[i], s->run.features);
            if (at - start[i] > widest) widest = at - start[i];
        }
        start[np] = at;
    }
    if (scratch_reserve(mw, widest) != 0) return -1;
    mw->built_at = s->lists.n_builds;
    mw->n_particles = np;
    mw->moved_far = 0;
    return 0;
}

void sim_mesh_walls_move(jd_mesh_walls *mw, double dt, double skin) {
    for (size_t k = 0; k < mw->n; k++) {
        jd_sim_mesh *m = &mw->mesh[k];
        if (m->motion.kind == JD_MESH_STILL) continue;
        const size_t nc = 3 * m->topo.ntri;
        jd_mesh_motion_step(&m->motion, dt, nc, (double(*)[3])m->corner);
        size_t bad = 0;
        if (jd_mesh_build(m->topo.ntri, (const double(*)[3][3])m->corner, &m->storage, &m->topo, &bad) !=
                JD_MESH_OK && !mw->error[0])
            snprintf(mw->error, sizeof mw->error, "mesh wall %zu: triangle %zu became degenerate "
                     "as it moved", k, bad);
        corner_velocities(m, NULL);
        const double *now = &m->corner[0][0][0], *then = &m->corner_at_build[0][0][0];
        for (size_t c = 0; c < nc && !mw->moved_far; c++) {
            double d2 = 0.0;
            for (int d = 0; d < 3; d++) d2 += (now[3 * c + d] - then[3 * c + d]) * (now[3 * c + d] - then[3 * c + d]);
            mw->moved_far = d2 > 0.25 * skin * skin;
        }
    }
}

int sim_mesh_walls_restored(jd_mesh_walls *mw, char *err, size_t errlen) {
    size_t widest = 1;
    for (size_t k = 0; k < mw->n; k++) {
        jd_sim_mesh *m = &mw->mesh[k];
        const size_t *start = mw->cand_start + k * (mw->n_particles + 1);
        for (size_t i = 0; mw->built_at >= 0 && i < mw->n_particles; i++)
            if (start[i + 1] - start[i] > widest) widest = start[i + 1] - start[i];
        if (m->motion.kind == JD_MESH_STILL) continue;
        size_t bad = 0;
        if (jd_mesh_build(m->topo.ntri, (const double(*)[3][3])m->corner, &m->storage, &m->topo, &bad) !=
            JD_MESH_OK) {
            snprintf(err, errlen, "mesh wall %zu: triangle %zu of the checkpoint is degenerate", k, bad);
            return -1;
        }
        corner_velocities(m, NULL);
    }
    if (scratch_reserve(mw, widest) != 0) {
        snprintf(err, errlen, "out of memory for the mesh walls' scratch");
        return -1;
    }
    return 0;
}

int sim_mesh_walls_moving(const jd_mesh_walls *mw, size_t k) {
    return mw->mesh[k].motion.kind != JD_MESH_STILL;
}

const double (*sim_mesh_walls_corners(const jd_mesh_walls *mw, size_t k))[3][3] {
    return (const double(*)[3][3])mw->mesh[k].corner;
}

/* The old slots no contact continues: their dissipation is booked before they are cleared. */
static void drop_ended(jd_mesh_walls *mw, const double *slots, size_t stride, const jd_mesh_sphere *sc,
                       unsigned F) {
    const int hw = jd_contact_record_len(F), rw = jd_rolling_record_len(F);
    for (int j = 0; j < JD_MESH_SLOTS; j++) {
        int kept = 0;
        for (size_t c = 0; c < sc->n; c++) kept |= sc->from[c] == j;
        if (kept) continue;
        jd_contact_state st;
        const double *r = slots + (size_t)j * stride + 3;
        jd_record_load(r, hw, r + hw, rw, &st, NULL);
        jd_contact_harvest(&st, 1.0, &mw->e_damp_dropped, &mw->e_fric_dropped);
    }
}

/* Particle i against mesh k (candidates tri[0, n)): the kernel's contacts, the wall law on
 * each (in the contacts' order, as fix wall/jiang mesh), the history kept unless in set-up
 * (then only the normals and the energy reference, as the plugin's set-up evaluation). */
static void sphere_forces(jd_sim *s, jd_mesh_walls *mw, size_t k, size_t i, size_t n,
                          const int32_t *tri, double *work) {
    jd_sim_mesh *m = &mw->mesh[k];
    jd_particles *ps = &s->particles;
    const jd_run_constants *run = &s->run;
    const unsigned F = run->features;
    const size_t stride = m->hist.stride;
    const int hw = jd_contact_record_len(F), rw = jd_rolling_record_len(F);
    double *slots = m->hist.slots + (size_t)ps->orig[i] * JD_MESH_SLOTS * stride;
    const double *x = ps->x + 3 * i, R = ps->radius[i];
    jd_mesh_sphere sc;
    if (jd_mesh_sphere_contacts(&m->topo, n, tri, x, R, slots, stride, mw->closest, mw->is_contact,
                                &sc) == JD_MESH_TOO_MANY && !mw->error[0])
        snprintf(mw->error, sizeof mw->error, "particle %lld touches more than %d faces of mesh "
                 "wall '%s' at once at step %lld", sim_particle_id(ps, i), JD_MESH_SLOTS,
                 run->scene->mesh_walls[k].name, (long long)s->step);
    if (!s->in_setup) drop_ended(mw, slots, stride, &sc, F);
    jd_mesh_history_next(slots, stride, &sc, mw->next);
    const jd_pair_coeffs co =
        jd_wall_coeffs(&run->coeffs[(size_t)ps->species[i] * run->n_materials + (size_t)m->material]);
    for (size_t c = 0; c < sc.n; c++) {
        jd_contact_geom *g = &sc.geom[c];
        if (jd_overlap_excessive(g->delta, R, INFINITY, run->max_overlap))
            sim_watchdog_overlap(&s->watch.overlap_trip, (int32_t)i,
                                 -1 - (int32_t)(s->walls.n + k), g->delta, R);
        jd_geom_wall_material(F, g, ps->kw[i], ps->mass[i], ps->inertia[i]);
        jd_kinematics kin;
        memset(&kin, 0, sizeof kin); /* wb = 0; vb = 0 unless the mesh moves */
        for (int d = 0; d < 3; d++) {
            kin.va[d] = ps->v[3 * i + d];
            kin.wa[d] = ps->omega[3 * i + d];
        }
        if (m->vnode)
            jd_mesh_point_velocity(&m->topo, sc.feature[c], (const double(*)[3])m->vnode[sc.feature[c]->tri], kin.vb);
        double *rec = mw->next + c * stride + 3;
        jd_contact_state st, kept;
        jd_rolling_state rs, rs_kept;
        jd_record_load(rec, hw, rec + hw, rw, &st, &rs);
        kept = st;
        rs_kept = rs;
        jd_contact_result out;
        const int carries = jd_contact(F, &co, g, &kin, run->dt, &st, (F & JD_F_ROLLING) ? &rs : NULL, &out);
        if (s->in_setup) jd_contact_keep_reference(&kept, &st, &rs_kept, &rs);
        jd_record_store(rec, hw, rec + hw, rw, s->in_setup ? &kept : &st, s->in_setup ? &rs_kept : &rs);
        if ((F & JD_F_ENERGY) && !s->in_setup) *work += jd_wall_work(kept.f_prev, out.f, kin.vb, run->dt);
        if (!carries) continue;
        for (int d = 0; d < 3; d++) {
            ps->f[3 * i + d] -= out.f[d];
            ps->torque[3 * i + d] += out.ta[d];
            m->force[d] += out.f[d];
        }
    }
    memcpy(slots, mw->next, JD_MESH_SLOTS * stride * sizeof *slots);
}

void sim_mesh_walls_forces(jd_sim *s) {
    jd_mesh_walls *mw = s->meshes;
    if ((mw->built_at != s->lists.n_builds || mw->moved_far) && build_candidates(mw, s) != 0) {
        snprintf(mw->error, sizeof mw->error, "out of memory for the mesh walls' candidates");
        return;
    }
    double work = 0.0;
    const size_t np = mw->n_particles;
    for (size_t k = 0; k < mw->n; k++) {
        memset(mw->mesh[k].force, 0, sizeof mw->mesh[k].force);
        const size_t *start = mw->cand_start + k * (np + 1);
        for (size_t i = 0; i < np; i++)
            if (start[i + 1] > start[i])
                sphere_forces(s, mw, k, i, start[i + 1] - start[i], mw->cand_tri + start[i], &work);
    }
    s->accounts.wall_work += work;
}

void sim_mesh_walls_observables(const jd_mesh_walls *mw, jd_observables *o) {
    o->damping_dissipation += mw->e_damp_dropped;
    o->friction_dissipation += mw->e_fric_dropped;
    for (size_t k = 0; k < mw->n; k++) {
        const jd_mesh_history *h = &mw->mesh[k].hist;
        for (size_t s = 0; s < h->n * JD_MESH_SLOTS; s++) {
            const double *slot = h->slots + s * h->stride;
            if (slot[0] == 0.0 && slot[1] == 0.0 && slot[2] == 0.0) continue;
            jd_contact_state st;
            jd_record_load(slot + 3, jd_contact_record_len(mw->features), NULL, 0, &st, NULL);
            o->elastic_energy += jd_contact_elastic_energy(&st);
            jd_contact_harvest(&st, 1.0, &o->damping_dissipation, &o->friction_dissipation);
            if (st.flags != (double)JD_S_ENDED) o->wall_contacts += 1.0;
        }
    }
}

int sim_mesh_walls_write_observables(const jd_mesh_walls *mw, const jd_run_constants *run,
                                     int64_t step, struct jd_h5md *h, char *err, size_t errlen) {
    for (size_t k = 0; k < mw->n; k++)
        for (int d = 0; d < 3; d++) {
            char name[2 * JD_NAME_MAX + 32];
            snprintf(name, sizeof name, "%s/%s/%s", jd_obs_wall_force, run->scene->mesh_walls[k].name,
                     jd_obs_axes[d]);
            if (jd_h5md_write_observable(h, name, step, (double)step * run->dt, mw->mesh[k].force[d],
                                         err, errlen))
                return -1;
        }
    return 0;
}
