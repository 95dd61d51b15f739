/*
 * checkpoint_state.c — the run's state as the checkpoint holds it, part by part (the table in
 * docs/architecture.md "What a checkpoint stores").  One traversal for both directions
 * (checkpoint_io.h).  Contact lists are stored entry by entry in their order, with their
 * history records as the kernel lays them out (jdem_laws.h: hw + rw doubles per entry, the
 * counts stored and checked), so any further list of the same kind (jd_contact_list) takes one
 * ck_list call.
 */
#include <stdint.h>
#include <stdio.h>

#include "checkpoint_io.h"
#include "jdem_inlet.h"
#include "mesh_walls.h"

_Static_assert(sizeof(jd_energy_terms) % sizeof(double) == 0, "jd_energy_terms is all doubles");
_Static_assert(sizeof(jd_inlet_cursor) == 2 * sizeof(int64_t), "a cursor is two int64");

#define NAME(buf, ...) (snprintf(buf, sizeof buf, __VA_ARGS__), buf)

static void ck_doubles(ck_io *io, const char *name, size_t count, double *v) {
    ck_array(io, name, H5T_NATIVE_DOUBLE, count, v);
}

static void ck_int32s(ck_io *io, const char *name, size_t count, int32_t *v) {
    ck_array(io, name, H5T_NATIVE_INT32, count, v);
}

/* A contact list: its entries in order, the split of its two sorted runs, the history records.
 * Reading: the list gets room first (sim_list_reserve sets the record layout of kind). */
static void ck_list(ck_io *io, const char *name, jd_contact_list *l, unsigned kind) {
    char p[128];
    size_t n = l->n, n_touch = l->n_touch;
    int hw = l->hw, rw = l->rw;
    ck_count(io, NAME(p, "%s/n", name), &n, SIZE_MAX / 64);
    ck_count(io, NAME(p, "%s/n_touch", name), &n_touch, n);
    ck_int(io, NAME(p, "%s/history_doubles", name), &hw);
    ck_int(io, NAME(p, "%s/rolling_history_doubles", name), &rw);
    if (io->failed) return;
    if (io->reading) {
        if (sim_list_reserve(l, n ? n : 1, kind) != 0) {
            io->no_memory = 1;
            ck_fail(io, "out of memory restoring the contact list '%s' (%zu entries)", name, n);
            return;
        }
        if (n && (hw != l->hw || rw != l->rw)) {
            ck_fail(io, "checkpoint '%s' keeps %d + %d history doubles per entry of '%s', this "
                    "run's law set %d + %d", io->path, hw, rw, name, l->hw, l->rw);
            return;
        }
        l->n = n;
        l->n_touch = n_touch;
    }
    ck_int32s(io, NAME(p, "%s/i", name), n, l->i);
    ck_int32s(io, NAME(p, "%s/j", name), n, l->j);
    /* the stored layout: an empty list may never have been given one */
    ck_doubles(io, NAME(p, "%s/history", name), n * (size_t)hw, l->hist);
    if (rw) ck_doubles(io, NAME(p, "%s/rolling_history", name), n * (size_t)rw, l->rhist);
}

/* Every per-particle array, state and constants (the constants of inserted particles and the
 * renumbering make them differ from the scene's). */
static void ck_particles(ck_io *io, jd_particles *ps, size_t capacity) {
    size_t n = ps->n;
    ck_count(io, "particles/n", &n, capacity);
    if (io->reading && !io->failed) ps->n = n;
    ck_int(io, "particles/sorted", &ps->sorted);
    struct { const char *name; double *a; size_t width; } vec[] = {
        {"x", ps->x, 3}, {"v", ps->v, 3}, {"omega", ps->omega, 3}, {"f", ps->f, 3},
        {"torque", ps->torque, 3}, {"radius", ps->radius, 1}, {"mass", ps->mass, 1},
        {"inertia", ps->inertia, 1}, {"kp", ps->kp, 1}, {"kw", ps->kw, 1},
        {"dtfm", ps->dtfm, 1}, {"dtirot", ps->dtirot, 1}};
    char p[64];
    for (size_t k = 0; k < sizeof vec / sizeof *vec; k++)
        ck_doubles(io, NAME(p, "particles/%s", vec[k].name), vec[k].width * n, vec[k].a);
    ck_int32s(io, "particles/orig", n, ps->orig);
    ck_int32s(io, "particles/species", n, ps->species);
}

static void ck_lists(ck_io *io, jd_neighbour_lists *l, unsigned features, size_t n) {
    const unsigned kind = sim_list_kind(features);
    ck_list(io, "lists/pairs", &l->pairs, kind);
    ck_list(io, "lists/wall_pairs", &l->wall_pairs, kind);
    ck_doubles(io, "lists/x_build", 3 * n, l->x_build);
    ck_doubles(io, "lists/half_skin", n, l->half_skin);
    ck_double(io, "lists/drift_bound", &l->drift_bound);
    ck_int64(io, "lists/n_builds", &l->n_builds);
}

/* What moves with a wall and what its servo has measured; the shape's constants come along
 * (they are few) so that the wall is whole in the file. */
static void ck_walls(ck_io *io, jd_walls *walls) {
    size_t n = walls->n;
    ck_count(io, "walls/n", &n, walls->n);
    if (io->reading && !io->failed && n != walls->n)
        ck_fail(io, "checkpoint '%s' has %zu walls, the scene %zu", io->path, n, walls->n);
    char p[64];
    for (size_t k = 0; k < walls->n && !io->failed; k++) {
        jd_sim_wall *w = &walls->wall[k];
        ck_doubles(io, NAME(p, "walls/%zu/velocity", k), 3, w->v);
        ck_doubles(io, NAME(p, "walls/%zu/plane_corners", k), 12, &w->plane.p[0][0]);
        ck_doubles(io, NAME(p, "walls/%zu/plane_normal", k), 3, w->plane.n);
        ck_doubles(io, NAME(p, "walls/%zu/axis_start", k), 3, w->cyl.a0);
        ck_doubles(io, NAME(p, "walls/%zu/axis_end", k), 3, w->cyl.a1);
        ck_double(io, NAME(p, "walls/%zu/cylinder_radius", k), &w->cyl.rc);
        ck_doubles(io, NAME(p, "walls/%zu/displacement", k), 3, w->disp);
        ck_doubles(io, NAME(p, "walls/%zu/force", k), 3, w->force);
        ck_int64(io, NAME(p, "walls/%zu/servo_held", k), &w->state.held);
        ck_int(io, NAME(p, "walls/%zu/servo_done", k), &w->state.done);
        ck_double(io, NAME(p, "walls/%zu/servo_stress", k), &w->stress);
        ck_double(io, NAME(p, "walls/%zu/servo_speed", k), &w->speed);
        ck_double(io, NAME(p, "walls/%zu/servo_position", k), &w->position);
    }
    ck_doubles(io, "walls/stress_tensor", 9, walls->stress_tensor);
}

static void ck_accounts_and_watch(ck_io *io, jd_accounts *a, jd_watch *w) {
    ck_double(io, "accounts/damping_dropped", &a->e_damp_dropped);
    ck_double(io, "accounts/friction_dropped", &a->e_fric_dropped);
    ck_double(io, "accounts/wall_work", &a->wall_work);
    ck_double(io, "watch/overlap_trip_fraction", &w->overlap_trip.fraction);
    ck_int32s(io, "watch/overlap_trip_i", 1, &w->overlap_trip.i);
    ck_int32s(io, "watch/overlap_trip_j", 1, &w->overlap_trip.j);
    ck_int(io, "watch/nonfinite", &w->nonfinite);
    ck_int(io, "watch/has_energy_ref", &w->has_energy_ref);
    ck_doubles(io, "watch/energy_ref", sizeof w->energy_ref / sizeof(double),
               (double *)&w->energy_ref);
    ck_int64(io, "watch/energy_ref_step", &w->energy_ref_step);
}

static void ck_bonds(ck_io *io, jd_bonds *b, size_t n_particles) {
    if (!io->reading && (b->n_formed || b->n_events)) {
        ck_fail(io, "internal error: a checkpoint with bond output not yet written");
        return;
    }
    size_t n = b->n;
    int sw = b->sw;
    ck_count(io, "bonds/n", &n, SIZE_MAX / 256);
    ck_int(io, "bonds/state_doubles", &sw);
    if (io->failed) return;
    if (io->reading) {
        if (sw != b->sw) {
            ck_fail(io, "checkpoint '%s' keeps %d doubles per bond, this run %d", io->path, sw, b->sw);
            return;
        }
        if (sim_bonds_reserve(b, n) != 0) {
            io->no_memory = 1;
            ck_fail(io, "out of memory restoring %zu bonds", n);
            return;
        }
        b->n = n;
        /* the set-up's records of its bonds were written before the checkpoint was: the
         * prefix copied from the stopped run holds them */
        b->n_formed = b->n_events = 0;
    }
    ck_int32s(io, "bonds/i", n, b->i);
    ck_int32s(io, "bonds/j", n, b->j);
    ck_int32s(io, "bonds/type", n, b->type);
    ck_doubles(io, "bonds/state", n * (size_t)b->sw, b->state);
    ck_count(io, "bonds/next_rule", &b->next_rule, SIZE_MAX);
    ck_array(io, "bonds/ever", H5T_NATIVE_UINT8, n_particles, b->ever);
    ck_array(io, "bonds/broken", H5T_NATIVE_INT64, 3, b->n_broken);
    ck_double(io, "bonds/damping_dropped", &b->e_damp_dropped);
    ck_double(io, "bonds/breakage_dropped", &b->e_break_dropped);
}

static void ck_loads(ck_io *io, jd_loads *l, int has_domain) {
    int32_t *index, *scene;
    double *f_prev;
    const size_t have = sim_loads_state(l, &index, &scene, &f_prev);
    size_t n = have;
    ck_count(io, "loads/n", &n, have); /* fewer when the domain deleted some */
    if (io->reading && !io->failed) sim_loads_set_count(l, n);
    ck_int32s(io, "loads/index", n, index);
    if (has_domain) ck_int32s(io, "loads/scene", n, scene); /* which ones are left */
    ck_doubles(io, "loads/previous_force", 6 * n, f_prev);
}

/* The offsets ascend from 0 to total, mesh after mesh, and each mesh's triangles exist. */
static int candidates_valid(const jd_mesh_walls *mw, size_t np, size_t total) {
    size_t prev = 0;
    for (size_t k = 0; k < mw->n; k++) {
        const size_t *start = mw->cand_start + k * (np + 1);
        const int32_t ntri = (int32_t)mw->mesh[k].topo.ntri;
        for (size_t i = 0; i <= np; i++) {
            if (start[i] < prev || start[i] > total) return 0;
            prev = start[i];
        }
        for (size_t c = start[0]; c < start[np]; c++)
            if (mw->cand_tri[c] < 0 || mw->cand_tri[c] >= ntri) return 0;
    }
    return prev == total;
}

/* The candidate lists as they are (mesh-major offsets, then the triangles), checked for
 * order and range on reading. */
static void ck_mesh_candidates(ck_io *io, jd_mesh_walls *mw, size_t capacity) {
    _Static_assert(sizeof(size_t) == sizeof(uint64_t), "offsets are stored as uint64");
    ck_int64(io, "meshes/candidates_built_at", &mw->built_at);
    ck_int(io, "meshes/candidates_stale", &mw->moved_far);
    size_t np = mw->n_particles;
    ck_count(io, "meshes/candidates_particles", &np, capacity);
    if (io->failed || mw->built_at < 0) return;
    const size_t n_off = mw->n * (np + 1);
    size_t total = io->reading ? 0 : mw->cand_start[n_off - 1];
    ck_count(io, "meshes/candidates", &total, SIZE_MAX / 64);
    if (io->failed) return;
    if (io->reading) {
        if (sim_mesh_candidates_reserve(mw, np, total) != 0) {
            io->no_memory = 1;
            ck_fail(io, "out of memory restoring %zu mesh candidates", total);
            return;
        }
        mw->n_particles = np;
    }
    ck_array(io, "meshes/candidates_start", H5T_NATIVE_UINT64, n_off, mw->cand_start);
    ck_int32s(io, "meshes/candidates_triangle", total, mw->cand_tri);
    if (io->reading && !io->failed && !candidates_valid(mw, np, total))
        ck_fail(io, "checkpoint '%s' is damaged: the mesh candidates are out of order or range; "
                "valid: a checkpoint written completely by jdem run", io->path);
}

/* Per mesh wall its corners (a moving mesh's moved incrementally, as LIGGGHTS moves them), the
 * corners at the candidates' build, the last force, and every particle's history slots. */
static void ck_meshes(ck_io *io, jd_mesh_walls *mw, size_t capacity) {
    size_t n = mw->n;
    ck_count(io, "meshes/n", &n, mw->n);
    if (io->reading && !io->failed && n != mw->n)
        ck_fail(io, "checkpoint '%s' has %zu mesh walls, the scene %zu", io->path, n, mw->n);
    char p[64];
    for (size_t k = 0; k < mw->n && !io->failed; k++) {
        jd_sim_mesh *m = &mw->mesh[k];
        size_t ntri = m->topo.ntri, stride = m->hist.stride, nh = m->hist.n;
        ck_count(io, NAME(p, "meshes/%zu/triangles", k), &ntri, m->topo.ntri);
        ck_count(io, NAME(p, "meshes/%zu/history_doubles", k), &stride, m->hist.stride);
        if (io->reading && !io->failed && (ntri != m->topo.ntri || stride != m->hist.stride))
            ck_fail(io, "checkpoint '%s': mesh wall %zu has %zu triangles and %zu history "
                    "doubles per slot, this run %zu and %zu", io->path, k, ntri, stride,
                    m->topo.ntri, m->hist.stride);
        ck_doubles(io, NAME(p, "meshes/%zu/corners", k), 9 * ntri, &m->corner[0][0][0]);
        if (m->corner_at_build)
            ck_doubles(io, NAME(p, "meshes/%zu/corners_at_build", k), 9 * ntri, &m->corner_at_build[0][0][0]);
        ck_doubles(io, NAME(p, "meshes/%zu/force", k), 3, m->force);
        ck_count(io, NAME(p, "meshes/%zu/history_particles", k), &nh, capacity);
        if (io->failed) return;
        if (io->reading && sim_mesh_history_resize(&m->hist, nh) != 0) {
            io->no_memory = 1;
            ck_fail(io, "out of memory restoring the history of mesh wall %zu", k);
            return;
        }
        ck_doubles(io, NAME(p, "meshes/%zu/history", k), nh * JD_MESH_SLOTS * stride, m->hist.slots);
    }
    ck_double(io, "meshes/damping_dropped", &mw->e_damp_dropped);
    ck_double(io, "meshes/friction_dropped", &mw->e_fric_dropped);
    ck_mesh_candidates(io, mw, capacity);
}

/* The streams' cursors and counters, the ids and trajectory rows of the particles inserted. */
static void ck_inlets(ck_io *io, jd_sim *s) {
    jd_inlet_state_view v;
    sim_inlets_state(s, &v);
    ck_int64(io, "inlets/next_step", v.next_step);
    ck_double(io, "inlets/energy_in", v.energy_in);
    ck_double(io, "inlets/seconds", v.seconds);
    if (s->run.scene->has_domain) {
        ck_int64(io, "domain/lost", v.lost);
        ck_double(io, "domain/energy_lost", v.energy_lost);
    }
    ck_array(io, "inlets/id", H5T_NATIVE_INT64, s->particles.n, v.id);
    ck_int32s(io, "inlets/slot", s->particles.n, v.slot);
    char p[64];
    for (size_t k = 0; k < v.n_inlets && !io->failed; k++) {
        size_t nc;
        jd_inlet_stream *st = sim_inlets_stream(s, k, &nc);
        ck_int64(io, NAME(p, "inlets/%zu/started", k), &st->started);
        ck_int64(io, NAME(p, "inlets/%zu/stop_step", k), &st->stop_step);
        ck_int64(io, NAME(p, "inlets/%zu/next_step", k), &st->next_step);
        ck_int64(io, NAME(p, "inlets/%zu/inserted", k), &st->inserted);
        ck_int64(io, NAME(p, "inlets/%zu/skipped", k), &st->skipped);
        ck_array(io, NAME(p, "inlets/%zu/cursors", k), H5T_NATIVE_INT64, 2 * nc, st->cursor);
    }
}

void ck_state(ck_io *io, jd_sim *s) {
    ck_int64(io, "run/step", &s->step);
    ck_int64(io, "run/frame_step", &s->frame_step);
    ck_int(io, "run/kick_pending", &s->kick_pending);
    ck_particles(io, &s->particles, sim_inlets_capacity(s->run.scene));
    ck_lists(io, &s->lists, s->run.features, s->particles.n);
    ck_walls(io, &s->walls);
    ck_accounts_and_watch(io, &s->accounts, &s->watch);
    if (s->bonds) ck_bonds(io, s->bonds, s->particles.n);
    if (s->loads) ck_loads(io, s->loads, s->run.scene->has_domain);
    if (s->inlets) ck_inlets(io, s);
    if (s->meshes) ck_meshes(io, s->meshes, sim_inlets_capacity(s->run.scene));
}
