/*
 * domain.c — the scene's domain in the stepper (kernel/jdem_domain.h): the particles outside it
 * are deleted at a neighbour build, as LIGGGHTS deletes an atom that left a `boundary f f f`
 * box at a reneighbouring step.
 *
 * How a particle goes.  The deleted particles are renumbered to the end of the arrays by
 * sim_reorder (which re-keys the contact lists, the bonds and the loads), and the active prefix
 * shrinks.  Their list entries, bonds and loads are removed here (the entries' and the bonds'
 * dissipation booked as for any that ended).  The scene indices stay dense
 * (0 .. n - 1, in id order), because the frames and the inlets' next scene index rely on it:
 * the kept particles' scene indices close up over the deleted ones, and every holder of data by
 * scene index (the trajectory rows, the mesh walls' history) closes up with them.
 */
#include <stdio.h>
#include <stdlib.h>

#include "jdem_domain.h"
#include "mesh_walls.h"
#include "sim.h"

/* The energy particle i takes with it [J] (jdem_domain.h).  half_step: v and omega are the
 * half-step values of a step in progress (a build inside sim_step), completed to the step with
 * the force and torque the particle last carried: its weight alone in free flight, exactly. */
static double energy_of(const jd_particles *ps, const jd_run_constants *run, size_t i,
                        int half_step) {
    double v[3], w[3];
    for (int d = 0; d < 3; d++) {
        v[d] = ps->v[3 * i + d] + (half_step ? ps->dtfm[i] * ps->f[3 * i + d] : 0.0);
        w[d] = ps->omega[3 * i + d] + (half_step ? ps->dtirot[i] * ps->torque[3 * i + d] : 0.0);
    }
    return jd_lost_energy(ps->mass[i], ps->inertia[i], &ps->x[3 * i], v, w, run->g);
}

/* Deletions reported one by one on stderr; the rest are counted (the run's closing line). */
enum { JD_DOMAIN_REPORTED = 10 };

/* Scene indices: new_of_old[p] for the kept ones, in order; -1 for the deleted (gone_scene). */
static void close_up(const unsigned char *gone_scene, size_t n, int32_t *new_of_old) {
    int32_t next = 0;
    for (size_t p = 0; p < n; p++) new_of_old[p] = gone_scene[p] ? -1 : next++;
}

int sim_domain_delete(jd_sim *s, int half_step, char *err, size_t errlen) {
    const jd_scene *sc = s->run.scene;
    jd_particles *ps = &s->particles;
    const size_t n = ps->n;
    if (!sc->has_domain || n == 0) return 0;
    size_t gone = 0;
    for (size_t i = 0; i < n; i++) gone += !jd_inside_domain(sc->domain_lo, sc->domain_hi, &ps->x[3 * i]);
    if (!gone) return 0;
    int32_t *old_of_new = malloc(n * sizeof *old_of_new), *scene_map = malloc(n * sizeof *scene_map);
    unsigned char *gone_scene = calloc(n, 1);
    if (!old_of_new || !scene_map || !gone_scene) {
        free(old_of_new);
        free(scene_map);
        free(gone_scene);
        snprintf(err, errlen, "out of memory deleting the %zu particles that left the domain", gone);
        return -1;
    }
    const size_t keep = n - gone;
    double energy = 0.0;
    for (size_t i = 0, a = 0, b = keep; i < n; i++) {
        if (jd_inside_domain(sc->domain_lo, sc->domain_hi, &ps->x[3 * i])) {
            old_of_new[a++] = (int32_t)i;
            continue;
        }
        old_of_new[b++] = (int32_t)i;
        gone_scene[ps->orig[i]] = 1;
        if (sim_lost_particles(s) + (int64_t)(b - keep) <= JD_DOMAIN_REPORTED)
            fprintf(stderr, "jdem: step %lld: particle id %lld left the domain at (%.6g, %.6g, "
                    "%.6g) m, moving at (%.6g, %.6g, %.6g) m/s; deleted%s\n",
                    (long long)(s->step + (half_step ? 1 : 0)), /* the step of these positions */
                    (long long)sim_particle_id(ps, i), ps->x[3 * i],
                    ps->x[3 * i + 1], ps->x[3 * i + 2], ps->v[3 * i], ps->v[3 * i + 1],
                    ps->v[3 * i + 2],
                    sim_lost_particles(s) + (int64_t)(b - keep) == JD_DOMAIN_REPORTED
                        ? " (further deletions are counted, not reported)" : "");
        energy += energy_of(ps, &s->run, i, half_step);
    }
    int rc = sim_reorder(s, old_of_new, err, errlen);
    if (rc == 0) {
        sim_lists_drop_from(s, keep);
        energy += sim_bonds_drop_from(s->bonds, keep);
        sim_loads_drop_from(s->loads, keep);
        close_up(gone_scene, n, scene_map);
        if (s->meshes) sim_mesh_walls_close_up(s->meshes, gone_scene, n, s->run.features);
        sim_inlets_close_up(s, gone_scene, n, gone, energy);
        for (size_t i = 0; i < keep; i++) ps->orig[i] = scene_map[ps->orig[i]];
        ps->n = keep;
        sim_particle_kinds(&s->fast, ps, s->run.n_materials, s->opt.plain_loops);
    }
    free(old_of_new);
    free(scene_map);
    free(gone_scene);
    return rc;
}
