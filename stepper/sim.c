/*
 * sim.c — set-up of a run from a resolved scene, the run loop with its output schedule, and
 * tear-down.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "checkpoint.h"
#include "geometry.h"
#include "h5md.h"
#include "h5md_internal.h"
#include "hugepages.h"
#include "jdem_laws.h"
#include "mesh_walls.h"
#include "sim.h"

#if defined(__SANITIZE_ADDRESS__)
#include <sanitizer/asan_interface.h>
#else
#define ASAN_POISON_MEMORY_REGION(p, n) ((void)(p), (void)(n))
#define ASAN_UNPOISON_MEMORY_REGION(p, n) ((void)(p), (void)(n))
#endif

/* The scene's interaction tables, as the kernel's rulebook reads them (jdem_laws.h): nm x nm
 * restitution, friction and rolling friction, row-major, the materials' Young's moduli and
 * Poisson's ratios, and MEPA's inputs (*mepa: the materials' loading, unloading and cohesive
 * stiffnesses and the scene's exponent and depth); nm each, what a material does not give is 0;
 * in one block (free the first). */
static double *interaction_tables(const jd_scene *sc, double **friction, double **rolling,
                                  double **youngs, double **poisson, jd_mepa_inputs *mepa) {
    const size_t nm = sc->n_materials, nn = nm * nm;
    double *e = malloc((3 * nn + 5 * nm + 1) * sizeof *e);
    if (!e) return NULL;
    *friction = e + nn;
    *rolling = e + 2 * nn;
    *youngs = e + 3 * nn;
    *poisson = *youngs + nm;
    double *k1 = *poisson + nm, *k2 = k1 + nm, *kadh = k2 + nm;
    for (size_t a = 0; a < nm; a++) {
        const jd_material *m = &sc->materials[a];
        (*youngs)[a] = m->youngs_modulus;
        (*poisson)[a] = m->poisson_ratio;
        k1[a] = m->loading_stiffness;
        k2[a] = m->unloading_stiffness;
        kadh[a] = m->cohesive_stiffness;
    }
    *mepa = (jd_mepa_inputs){.k1 = k1, .k2 = k2, .kadh = kadh, .n = sc->mepa_exponent,
                             .depth = sc->mepa_plastic_depth};
    for (size_t k = 0; k < nn; k++) {
        e[k] = sc->interactions[k].restitution;
        (*friction)[k] = sc->interactions[k].friction;
        (*rolling)[k] = sc->interactions[k].rolling_friction;
    }
    return e;
}

/* Interaction coefficients for every ordered material pair (jd_pair_coeffs_table), and the laws
 * some interaction that can occur in this scene needs (particle materials against particle and
 * wall materials: jd_law_set_select).  --all-laws: the general loop, every law evaluated. */
static int init_laws(jd_sim *s) {
    const jd_scene *sc = s->run.scene;
    const size_t nm = sc->n_materials, nn = nm * nm;
    double *mu = NULL, *eta = NULL, *E = NULL, *nu = NULL;
    jd_mepa_inputs mepa;
    double *e = interaction_tables(sc, &mu, &eta, &E, &nu, &mepa);
    unsigned char *used = calloc(2 * (nm ? nm : 1), 1), *wall_used = used + nm;
    s->run.n_materials = nm;
    s->run.coeffs = calloc(nn ? nn : 1, sizeof *s->run.coeffs);
    const int rc = (e && used && s->run.coeffs) ? 0 : -1;
    if (rc == 0) {
        jd_pair_coeffs_table(nm, e, mu, eta, E, nu, sc->damping_map, sc->mu_r, sc->xi_limit,
                             sc->normal_law == JD_NORMAL_MEPA ? &mepa : NULL, s->run.coeffs);
        for (size_t i = 0; i < sc->n_particles; i++) used[sc->material[i]] = 1;
        for (size_t k = 0; k < sc->n_inlets; k++)
            for (size_t p = 0; p < sc->inlets[k].n; p++) used[sc->inlets[k].material[p]] = 1;
        for (size_t w = 0; w < sc->n_walls; w++) wall_used[sc->walls[w].material] = 1;
        const unsigned mindlin = sc->tangential_rule == JD_KT_MINDLIN ? JD_F_MINDLIN : 0u;
        const unsigned mepa_bit = sc->normal_law == JD_NORMAL_MEPA ? JD_F_MEPA : 0u;
        s->run.features = s->opt.all_laws
                          ? JD_F_DAMPING | JD_F_FRICTION | JD_F_ROLLING | JD_F_MU_R | mindlin |
                                mepa_bit | (sc->energy ? JD_F_ENERGY : 0u)
                          : jd_law_set_select(nm, e, mu, eta, used, wall_used, sc->mu_r,
                                              sc->tangential_rule, sc->normal_law, sc->energy);
    }
    free(e);
    free(used);
    return rc;
}

/* How alike the particles are (sim.h: pair_row, alike), which lets the pair loop read the
 * coefficients, or also the pair constants and radii, once instead of per pair. */
void sim_particle_kinds(jd_fast_paths *fast, const jd_particles *ps, size_t n_materials,
                        int plain) {
    fast->pair_row = ps->n ? ps->species[0] * (int32_t)(n_materials + 1) : -1;
    fast->alike = ps->n > 0;
    for (size_t i = 1; i < ps->n; i++) {
        if (ps->species[i] != ps->species[0]) fast->pair_row = -1;
        if (ps->species[i] != ps->species[0] || ps->radius[i] != ps->radius[0]) fast->alike = 0;
    }
    if (fast->alike) { /* the constants of any pair: those of particle 0 with itself */
        fast->r_alike = ps->radius[0];
        sim_pair_constants(ps, 0, 0, &fast->pc_alike, &fast->pcr_alike);
    }
    fast->uniform_mass = ps->n > 0 && !plain; /* plain: the reference path */
    for (size_t i = 1; i < ps->n && fast->uniform_mass; i++)
        fast->uniform_mass = ps->mass[i] == ps->mass[0] && ps->dtfm[i] == ps->dtfm[0] &&
                          ps->dtirot[i] == ps->dtirot[0];
}

/* The next `bytes` of the per-particle block (alloc_particle_arrays) at offset *at: 64-byte
 * aligned and followed by a gap of at least 64 bytes, which AddressSanitizer builds mark
 * unaddressable, so that an overrun of one array is still reported rather than landing in the
 * next.  With block NULL only the offset advances. */
static void *slice(char *block, size_t *at, size_t bytes) {
    enum { LINE = 64 };
    const size_t len = (bytes + LINE - 1) / LINE * LINE + LINE;
    char *p = block ? block + *at : NULL;
    if (p) ASAN_POISON_MEMORY_REGION(p + bytes, len - bytes);
    *at += len;
    return p;
}

/* The per-particle arrays of n particles as slices of block (NULL: none); returns the bytes
 * they take.  The five arrays the pair loop reads and writes come first. */
static size_t carve(jd_sim *s, size_t n, char *block) {
    size_t at = 0;
    s->particles.x = slice(block, &at, 3 * n * sizeof *s->particles.x);
    s->particles.v = slice(block, &at, 3 * n * sizeof *s->particles.v);
    s->particles.omega = slice(block, &at, 3 * n * sizeof *s->particles.omega);
    s->particles.f = slice(block, &at, 3 * n * sizeof *s->particles.f);
    s->particles.torque = slice(block, &at, 3 * n * sizeof *s->particles.torque);
    s->particles.dtfm = slice(block, &at, n * sizeof *s->particles.dtfm);
    s->particles.dtirot = slice(block, &at, n * sizeof *s->particles.dtirot);
    s->particles.radius = slice(block, &at, n * sizeof *s->particles.radius);
    s->particles.mass = slice(block, &at, n * sizeof *s->particles.mass);
    s->particles.inertia = slice(block, &at, n * sizeof *s->particles.inertia);
    s->particles.kp = slice(block, &at, n * sizeof *s->particles.kp);
    s->particles.kw = slice(block, &at, n * sizeof *s->particles.kw);
    s->lists.x_build = slice(block, &at, 3 * n * sizeof *s->lists.x_build);
    s->lists.half_skin = slice(block, &at, n * sizeof *s->lists.half_skin);
    s->particles.scratch = slice(block, &at, 3 * n * sizeof *s->particles.scratch);
    s->particles.species = slice(block, &at, n * sizeof *s->particles.species);
    s->particles.orig = slice(block, &at, n * sizeof *s->particles.orig);
    s->lists.cell_of = slice(block, &at, n * sizeof *s->lists.cell_of);
    s->lists.cell_items = slice(block, &at, n * sizeof *s->lists.cell_items);
    s->lists.moved = slice(block, &at, n * sizeof *s->lists.moved);
    s->lists.in_moved = slice(block, &at, n * sizeof *s->lists.in_moved);
    return at;
}

/* The per-particle arrays, zeroed, in one block on huge pages (hugepages.h).  Returns 0, or
 * -1 when there is no memory for them. */
static int alloc_particle_arrays(jd_sim *s, size_t n) {
    const size_t bytes = carve(s, n, NULL);
    char *block = jd_huge_alloc(bytes);
    if (!block) return -1;
    s->particle_block = block;
    s->particle_block_bytes = bytes;
    carve(s, n, block);
    return 0;
}

void sim_particle_constants(jd_particles *ps, const jd_run_constants *run, size_t i,
                            int32_t material, double r) {
    const jd_scene *sc = run->scene;
    const jd_material *m = &sc->materials[material];
    const double dtfrotate = 0.5 * run->dt / 0.4; /* fix nve/sphere: dtfrotate, then dtirotate */
    ps->species[i] = material;
    ps->radius[i] = r;
    ps->mass[i] = jd_sphere_mass(r, m->density);
    ps->inertia[i] = jd_sphere_inertia(ps->mass[i], r);
    ps->kp[i] = jd_hertz_prefactor(m->youngs_modulus, m->poisson_ratio, r);
    ps->kw[i] = jd_kn_wall(sc->wall_rule, m->youngs_modulus, m->poisson_ratio, r);
    ps->dtfm[i] = 0.5 * run->dt / ps->mass[i];
    ps->dtirot[i] = dtfrotate / (r * r * ps->mass[i]);
}

static int init_particles(jd_sim *s, char *err, size_t errlen) {
    const jd_scene *sc = s->run.scene;
    const size_t n = sc->n_particles, cap = sim_inlets_capacity(sc), n1 = cap ? cap : 1;
    if (alloc_particle_arrays(s, n1) != 0) goto oom;
    memcpy(s->particles.x, sc->position, 3 * n * sizeof(double));
    memcpy(s->particles.v, sc->velocity, 3 * n * sizeof(double));
    memcpy(s->particles.omega, sc->angular_velocity, 3 * n * sizeof(double));
    double rmax = 0.0;
    for (size_t i = 0; i < n; i++) {
        const jd_material *m = &sc->materials[sc->material[i]];
        if (!m->has_elastic) {
            snprintf(err, errlen, "particle %lld: material '%s' has no elastic properties",
                     (long long)sc->id[i], m->name);
            return -1;
        }
        s->particles.orig[i] = (int32_t)i;
        sim_particle_constants(&s->particles, &s->run, i, sc->material[i], sc->radius[i]);
        rmax = fmax(rmax, sc->radius[i]);
    }
    for (size_t k = 0; k < sc->n_inlets; k++)
        for (size_t p = 0; p < sc->inlets[k].n; p++) rmax = fmax(rmax, sc->inlets[k].radius[p]);
    /* Skin 0.1 x the largest diameter: the list then holds ~(1.1)^3 = 1.33x the touching pairs
     * of a dense packing, and a rebuild is due only after some particle moved 5 % of a
     * diameter (~100 steps at typical granular speeds and time steps). */
    s->lists.skin = 0.2 * rmax;
    s->lists.skin_steps = sc->skin_steps;
    return 0;
oom:
    snprintf(err, errlen, "out of memory for %zu particles", n1);
    return -1;
}

/* Save the contact history of a list (its first n entries) into state and roll (n entries
 * each), or put it back keeping the energy reference of the evaluation in between
 * (jd_contact_keep_reference). */
static void save_history(const jd_contact_list *l, jd_contact_state *state, jd_rolling_state *roll) {
    for (size_t c = 0; c < l->n; c++) sim_hist_get(l, c, &state[c], &roll[c]);
}

static void restore_history(jd_contact_list *l, const jd_contact_state *state,
                            const jd_rolling_state *roll) {
    for (size_t c = 0; c < l->n; c++) {
        jd_contact_state evaluated, kept = state[c];
        jd_rolling_state r_evaluated, r_kept = roll[c];
        sim_hist_get(l, c, &evaluated, &r_evaluated);
        jd_contact_keep_reference(&kept, &evaluated, l->rw ? &r_kept : NULL, l->rw ? &r_evaluated : NULL);
        sim_hist_set(l, c, &kept, l->rw ? &r_kept : NULL);
    }
}

/* LIGGGHTS `setup`: the forces of step 0, evaluated without advancing any contact history
 * (LIGGGHTS' shearupdate = 0, which the plugin follows), so that a scene starting with bodies in
 * contact counts its first spring increment and its first step of dissipation once; only the
 * energy reference of that evaluation is kept. */
static int setup_forces(jd_sim *s, char *err, size_t errlen) {
    jd_contact_list *lists[2] = {&s->lists.pairs, &s->lists.wall_pairs};
    jd_contact_state *state[2];
    jd_rolling_state *roll[2];
    int ok = 1;
    for (int k = 0; k < 2; k++) {
        state[k] = malloc((lists[k]->n + 1) * sizeof *state[k]);
        roll[k] = malloc((lists[k]->n + 1) * sizeof *roll[k]);
        ok = ok && state[k] && roll[k];
    }
    if (ok) {
        for (int k = 0; k < 2; k++) save_history(lists[k], state[k], roll[k]);
        s->in_setup = 1;
        sim_compute_forces(s);
        s->in_setup = 0;
        for (int k = 0; k < 2; k++) restore_history(lists[k], state[k], roll[k]);
        if (s->meshes && s->meshes->error[0]) {
            snprintf(err, errlen, "%s", s->meshes->error);
            ok = 0;
        }
    } else {
        snprintf(err, errlen, "out of memory");
    }
    for (int k = 0; k < 2; k++) {
        free(state[k]);
        free(roll[k]);
    }
    return ok ? 0 : -1;
}

static int setup(jd_sim *s, char *err, size_t errlen) {
    if (init_particles(s, err, errlen) != 0) return -1;
    if (init_laws(s) != 0) {
        snprintf(err, errlen, "out of memory");
        return -1;
    }
    sim_particle_kinds(&s->fast, &s->particles, s->run.n_materials, s->opt.plain_loops);
    if (sim_forces_init(&s->threads) != 0) {
        snprintf(err, errlen, "out of memory for the force buffers of %d threads", s->threads.n);
        return -1;
    }
    if (sim_walls_init(&s->walls, &s->run, err, errlen) != 0 ||
        sim_mesh_walls_init(&s->meshes, &s->run, err, errlen) != 0)
        return -1;
    if (sim_bonds_init(&s->bonds, &s->particles, s->run.scene,
                       sim_inlets_capacity(s->run.scene), err, errlen) != 0 ||
        sim_loads_init(&s->loads, s->run.scene, err, errlen) != 0 ||
        sim_inlets_init(s, err, errlen) != 0)
        return -1;
    s->fast.weight_in_kick = !s->loads && !s->opt.plain_loops &&
                             (s->run.g[0] != 0.0 || s->run.g[1] != 0.0 || s->run.g[2] != 0.0);
    if (sim_neighbour_build(s, err, errlen) != 0) return -1;
    return setup_forces(s, err, errlen);
}

int sim_init(jd_sim *s, const jd_scene *scene, const jd_sim_options *opt, int threads, char *err,
             size_t errlen) {
    memset(s, 0, sizeof *s);
    s->run.scene = scene;
    s->particles.n = scene->n_particles;
    s->particles.ids = scene->id;
    s->run.dt = scene->dt;
    if (opt) s->opt = *opt;
    s->threads.n = threads > 1 ? threads : 1;
    s->frame_step = -1;
    memcpy(s->run.g, scene->gravity, sizeof s->run.g);
    s->run.max_overlap = scene->watchdog.enabled ? scene->watchdog.max_overlap_fraction : INFINITY;
    if (setup(s, err, errlen) == 0) {
        memset(&s->accounts.timing, 0, sizeof s->accounts.timing); /* the time loop's parts only */
        return 0;
    }
    sim_free(s);
    return -1;
}

void sim_free(jd_sim *s) {
    if (s->particle_block) ASAN_UNPOISON_MEMORY_REGION(s->particle_block, s->particle_block_bytes);
    jd_huge_free(s->particle_block, s->particle_block_bytes);
    sim_forces_free(&s->threads);
    free(s->run.coeffs);
    sim_walls_free(&s->walls);
    sim_mesh_walls_free(s->meshes);
    free(s->lists.cell_start);
    free(s->lists.keys);
    sim_neighbour_parts_free(&s->lists);
    sim_contact_list_free(&s->lists.pairs);
    sim_contact_list_free(&s->lists.wall_pairs);
    sim_contact_list_free(&s->lists.spare);
    sim_contact_list_free(&s->lists.wall_spare);
    sim_bonds_free(&s->bonds);
    sim_loads_free(&s->loads);
    sim_inlets_free(s);
    memset(s, 0, sizeof *s);
}

static size_t list_bytes(const jd_contact_list *l) {
    const size_t entry = 2 * sizeof(int32_t) + (size_t)(l->hw + l->rw) * sizeof(double);
    return l->cap * entry;
}

size_t sim_memory_bytes(const jd_sim *s) {
    const size_t per_particle = 6 * 3 * sizeof(double) /* x v omega f torque x_build */ +
                                sizeof(double) /* half_skin */ +
                                3 * sizeof(double) /* scratch */ + 7 * sizeof(double) /* constants */ +
                                5 * sizeof(int32_t) /* species orig cell_of cell_items moved */ +
                                sizeof(uint8_t) /* in_moved */;
    const jd_thread_layout *th = &s->threads;
    const jd_neighbour_lists *l = &s->lists;
    size_t overflow = 0;
    for (int t = 0; th->shares && t < th->n; t++) overflow += 6 * th->shares[t].cap * sizeof(double);
    return s->particles.n * per_particle + overflow + sim_bonds_memory_bytes(s->bonds, s->particles.n) +
           l->cell_cap * sizeof(int32_t) + l->keys_cap * sizeof(int64_t) + list_bytes(&l->pairs) +
           list_bytes(&l->wall_pairs) + list_bytes(&l->spare) + list_bytes(&l->wall_spare) +
           s->walls.n * sizeof *s->walls.wall +
           s->run.n_materials * s->run.n_materials * sizeof *s->run.coeffs;
}

static int check_finite(const jd_particles *ps, int64_t step, char *err, size_t errlen) {
    for (size_t k = 0; k < 3 * ps->n; k++) {
        if (!isfinite(ps->x[k]) || !isfinite(ps->v[k]) || !isfinite(ps->omega[k])) {
            snprintf(err, errlen, "particle %lld has a non-finite state at step %lld (diverged)",
                     sim_particle_id(ps, k / 3), (long long)step);
            return -1;
        }
    }
    return 0;
}

/* Frames are in scene order: the vectors are put into it for the write and back after. */
static int write_frame(jd_sim *s, jd_h5md *h, char *err, size_t errlen) {
    if (check_finite(&s->particles, s->step, err, errlen) != 0) return -1;
    if (!h) return 0;
    for (size_t k = 0; s->meshes && k < s->meshes->n; k++)
        if (sim_mesh_walls_moving(s->meshes, k) &&
            jd_h5md_move_mesh(h, s->run.scene->n_walls + k, sim_mesh_walls_corners(s->meshes, k), err, errlen))
            return JD_RUN_OUTPUT;
    jd_particles *ps = &s->particles;
    sim_vectors_to_scene_order(ps);
    jd_h5md_frame fr = {.step = s->step, .time = (double)s->step * s->run.dt, .position = ps->x,
                        .velocity = ps->v, .angular_velocity = ps->omega, .force = ps->f,
                        .torque = ps->torque};
    jd_h5md_particles rows = {0};
    if (s->inlets) { /* the rows of every particle the run can hold, id -1 until inserted */
        const double *const vec[JD_INLET_FRAME_VECTORS] = {ps->x, ps->v, ps->omega, ps->f, ps->torque};
        const double **dst[JD_INLET_FRAME_VECTORS] = {&fr.position, &fr.velocity,
                                                      &fr.angular_velocity, &fr.force, &fr.torque};
        for (int k = 0; k < JD_INLET_FRAME_VECTORS; k++) *dst[k] = sim_inlets_frame_rows(s, k, vec[k]);
        rows = (jd_h5md_particles){.n = sim_inlets_rows(s), .id = sim_inlets_frame_ids(s)};
        fr.rows = &rows;
    }
    const int rc = jd_h5md_write_frame(h, &fr, err, errlen);
    sim_vectors_to_sim_order(ps);
    return rc ? JD_RUN_OUTPUT : 0;
}

/* One observable sample: written when there is output, and always seen by the watchdog. */
static int sample_observables(jd_sim *s, jd_h5md *h, char *err, size_t errlen) {
    jd_observables o;
    double val[JD_N_OBSERVABLES];
    sim_observables(&s->particles, &s->run, &s->lists, &s->walls, &s->accounts, &o);
    if (s->bonds) sim_bonds_observables(s->bonds, s->particles.n, &o.bond);
    if (s->meshes) sim_mesh_walls_observables(s->meshes, &o);
    sim_observables_values(&o, val);
    for (int k = 0; h && k < JD_N_OBSERVABLES; k++)
        if ((s->run.scene->energy || !jd_observable_is_energy[k]) &&
            jd_h5md_write_observable(h, jd_observable_names[k], s->step, (double)s->step * s->run.dt,
                                     val[k], err, errlen) != 0)
            return JD_RUN_OUTPUT;
    const double t = (double)s->step * s->run.dt;
    if (h && s->run.scene->n_inlets &&
        (jd_h5md_write_observable(h, jd_obs_inlet_energy, s->step, t, sim_inlets_energy(s), err,
                                  errlen) != 0 ||
         jd_h5md_write_observable(h, jd_obs_skipped_particles, s->step, t,
                                  (double)sim_skipped_particles(s), err, errlen) != 0))
        return JD_RUN_OUTPUT;
    if (h && s->run.scene->has_domain &&
        (jd_h5md_write_observable(h, jd_obs_lost_particles, s->step, t,
                                  (double)sim_lost_particles(s), err, errlen) != 0 ||
         jd_h5md_write_observable(h, jd_obs_lost_energy, s->step, t, sim_lost_energy(s), err,
                                  errlen) != 0))
        return JD_RUN_OUTPUT;
    if (h && s->walls.forces && sim_walls_write_observables(&s->walls, &s->run, s->step, h, err, errlen) != 0)
        return JD_RUN_OUTPUT;
    if (h && s->meshes &&
        sim_mesh_walls_write_observables(s->meshes, &s->run, s->step, h, err, errlen) != 0)
        return JD_RUN_OUTPUT;
    if (s->bonds) {
        double bv[JD_N_BOND_OBSERVABLES];
        sim_bond_observables_values(&o.bond, bv);
        for (int k = 0; h && k < JD_N_BOND_OBSERVABLES; k++)
            if ((s->run.scene->energy || !jd_bond_observable_is_energy[k]) &&
                jd_h5md_write_observable(h, jd_bond_observable_names[k], s->step,
                                         (double)s->step * s->run.dt, bv[k], err, errlen) != 0)
                return JD_RUN_OUTPUT;
    }
    return sim_watchdog_energy(&s->watch, &s->particles, &s->run, s->step,
                               sim_inlets_energy(s) - sim_lost_energy(s), &o, err, errlen);
}

static int due(int64_t step, int64_t every, int64_t last) {
    return step == 0 || step == last || (every > 0 && step % every == 0);
}

/* A run stopped early (watchdog, signal) ends its trajectory at the step reached, so that the
 * file shows the state that stopped it; write_frame refuses a non-finite state (NaN frames would
 * only break the readers), and the stop message stays in err. */
static void write_stop_frame(jd_sim *s, jd_h5md *h) {
    char ignored[256];
    if (s->frame_step != s->step && write_frame(s, h, ignored, sizeof ignored) == 0)
        s->frame_step = s->step;
}

/* A checkpoint when one is due: at every_steps, after every_seconds, or before a stop (the
 * signal's flag is set).  Never twice at one step; 0 or JD_RUN_OUTPUT with err. */
static int checkpoint_if_due(jd_sim *s, jd_h5md *h, jd_checkpointer *ck, const jd_progress *p,
                             char *err, size_t errlen) {
    if (!ck || !ck->path || s->step == ck->last_step) return 0; /* no checkpoint asked for */
    const double now = sim_clock();
    const int due = (s->stop && *s->stop) ||
                    (s->step > 0 && ck->every_steps > 0 && s->step % ck->every_steps == 0) ||
                    (ck->every_seconds > 0.0 && now - ck->t_last >= ck->every_seconds);
    if (!due) return 0;
    /* the trajectory on disk holds everything up to the checkpoint: a resume reads it back */
    if (h && jd_h5md_flush(h) != 0) {
        snprintf(err, errlen, "cannot flush the trajectory before the checkpoint of step %lld",
                 (long long)s->step);
        return JD_RUN_OUTPUT;
    }
    if (jd_checkpoint_write(s, ck, now - p->t_start, p->particle_steps, err, errlen) != 0)
        return JD_RUN_OUTPUT;
    ck->last_step = s->step;
    ck->t_last = sim_clock();
    return 0;
}

int sim_run(jd_sim *s, jd_h5md *h, int show_progress, char *err, size_t errlen) {
    return sim_run_checkpointed(s, h, show_progress, NULL, err, errlen);
}

static double pending_particle_steps(const void *s, int64_t last) {
    return sim_inlets_pending_particle_steps(s, last);
}

int sim_run_checkpointed(jd_sim *s, jd_h5md *h, int show_progress, jd_checkpointer *ck,
                         char *err, size_t errlen) {
    const jd_scene *sc = s->run.scene;
    const int64_t last = sc->steps;
    /* a resumed run: the output of its first step is in the trajectory already */
    const int64_t written = ck ? ck->resumed_step : -1;
    jd_progress p;
    progress_start(&p, show_progress, last);
    if (s->inlets) {
        p.pending = pending_particle_steps;
        p.ctx = s;
    }
    if (written >= 0) { /* the rate and ETA count the time before the resume */
        p.t_start -= ck->elapsed;
        p.particle_steps = ck->particle_steps;
    }
    const double t_loop = sim_clock();
    int rc = 0;
    for (;;) {
        /* the bonds formed and broken by the last step, also when the watchdog stops here */
        if (s->bonds && (rc = sim_bonds_output(s->bonds, s->step, h, err, errlen)) != 0) break;
        if ((rc = sim_watchdog_step(&s->watch, &s->particles, &s->run, s->step, err, errlen)) != 0)
            break;
        if (s->inlets && (rc = sim_inlets_step(s, err, errlen)) != 0) break;
        /* the bonds of blocks inserted at this step: in the trajectory before a checkpoint */
        if (s->bonds && s->bonds->n_formed && (rc = sim_bonds_output(s->bonds, s->step, h, err, errlen)) != 0)
            break;
        const double t0 = sim_clock();
        if (s->step != written && due(s->step, sc->output_every, last)) {
            if ((rc = write_frame(s, h, err, errlen)) != 0) break;
            s->frame_step = s->step;
        }
        if (s->step != written && due(s->step, sc->observables_every, last) &&
            (rc = sample_observables(s, h, err, errlen)) != 0)
            break;
        s->accounts.timing.output += sim_clock() - t0;
        if (s->step >= last) break;
        if ((rc = checkpoint_if_due(s, h, ck, &p, err, errlen)) != 0) break;
        if (s->stop && *s->stop) {
            snprintf(err, errlen, "stopped at step %lld", (long long)s->step);
            rc = JD_RUN_STOPPED;
            break;
        }
        const int seen = due(s->step + 1, sc->output_every, last) ||
                         due(s->step + 1, sc->observables_every, last);
        if ((rc = sim_step(s, seen, err, errlen)) != 0) break;
        progress_update(&p, s->step, (double)s->step * s->run.dt, s->particles.n);
    }
    sim_finish_step(s); /* a run stopped between samples: its stop frame, and the caller */
    s->accounts.timing.loop += sim_clock() - t_loop;
    progress_finish(&p);
    if (rc == JD_RUN_TRIPPED || rc == JD_RUN_STOPPED) write_stop_frame(s, h);
    return rc;
}
