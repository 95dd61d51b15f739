/*
 * main.c — the `jdem` command line (docs/scenes.md).
 *
 * Exit status by failure class (the `exit status` paragraph of the help below): 0 success,
 * 2 bad input, 3 I/O failure, 4 the simulation failed (watchdog, diverged), 5 out of memory,
 * 1 internal error, 128 + N stopped by signal N.  A failed or stopped run never leaves a file
 * under the final output name: the writer works on OUT.part and renames it only at a
 * successful close; a stopped run closes OUT.part properly, so it stays readable.
 */
#include <errno.h>
#include <math.h>
#include <unistd.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "checkpoint.h"
#include "h5md.h"
#include "h5md_resume.h"
#include "scene.h"
#include "sim.h"

#include "source_commit.h" /* JDEM_SOURCE_COMMIT (Makefile) */

#ifndef JDEM_VERSION
#define JDEM_VERSION "unknown"
#endif
/* The version a trajectory names as its creator's: the release and the source commit. */
#define JDEM_BUILD JDEM_VERSION "+" JDEM_SOURCE_COMMIT

enum { EXIT_INTERNAL = 1, EXIT_INPUT = 2, EXIT_IO = 3, EXIT_FAILED_RUN = 4, EXIT_NO_MEMORY = 5 };

static const char usage_text[] =
    "usage: jdem COMMAND SCENE [OPTIONS]\n"
    "\n"
    "jdem, a discrete element engine for granular materials (the contact laws of Jiang 2021).\n"
    "A scene file (YAML, see docs/scenes.md) describes materials, particles, walls, gravity,\n"
    "time step and output; a sweep turns it into several cases.\n"
    "\n"
    "commands:\n"
    "  cases SCENE              list the case names of SCENE, one per line\n"
    "  run SCENE                run one case and write its trajectory (H5MD)\n"
    "  resolve SCENE            print the case as YAML with every default explicit and every\n"
    "                           generator expanded (the input of the LIGGGHTS deck generator)\n"
    "  --help, -h               print this help\n"
    "  --version                print the version\n"
    "\n"
    "options:\n"
    "  --case NAME              the case to run or resolve (required when SCENE has several)\n"
    "  -o, --output OUT.h5      trajectory file (run; default out/SCENE_NAME/CASE.jdem.h5,\n"
    "                           directories are created).  Written as OUT.h5.part and renamed\n"
    "                           when the run completes, so OUT.h5 is never a truncated file\n"
    "  --force                  run even if the time step is unsafe (run)\n"
    "  --quiet                  no summary and no progress line on stderr (run)\n"
    "  --threads N              OpenMP threads of the force and integration loops (run;\n"
    "                           default: OMP_NUM_THREADS if set, else 1).  A run is\n"
    "                           reproducible bit for bit for a given N; different N differ\n"
    "                           by round-off (the order in which contact forces are summed)\n"
    "  --timing                 print where the time loop's wall time went (neighbour\n"
    "                           search, pair forces, wall forces, integration, output) and\n"
    "                           the whole loop's, on stderr at the end of the run, also with\n"
    "                           --quiet (run)\n"
    "  --no-sort                keep the scene's particle order instead of renumbering the\n"
    "                           particles in cell order at each neighbour build (run; a\n"
    "                           reference for the sorted path, results agree to round-off)\n"
    "  --all-laws               evaluate every contact law even where the scene's\n"
    "                           coefficients switch it off (run; the general force loop, a\n"
    "                           reference for the scene-specialised ones: same trajectory)\n"
    "  --inlet-record FILE      write every particle an inlet inserts as a CSV line\n"
    "                           id,step,x,y,z,vx,vy,vz (17 digits: exact) to FILE (run)\n"
    "  --plain-loops            evaluate one contact at a time instead of in SIMD batches,\n"
    "                           gravity in a pass of its own, the integration constants per\n"
    "                           particle and the rebuild check at every step (run; the\n"
    "                           reference for the fast paths: same trajectory)\n"
    "  --checkpoint FILE        write checkpoints to FILE (run; default OUT with .h5 replaced\n"
    "                           by .ckpt.h5); with this option or the two below a checkpoint\n"
    "                           is also written when SIGINT or SIGTERM stops the run\n"
    "  --checkpoint-every N     a checkpoint every N steps (run)\n"
    "  --checkpoint-seconds T   a checkpoint every T seconds of wall time (run)\n"
    "  --resume FILE            continue the run from checkpoint FILE (run; the same scene,\n"
    "                           case, -o, --threads and reference options): the result equals\n"
    "                           the uninterrupted run's bit for bit, and OUT.h5.part of the\n"
    "                           stopped run is continued (docs/output.md \"Resumed runs\")\n"
    "\n"
    "time-step guard (run): dt must not exceed 20 % of the Rayleigh time step of the smallest\n"
    "sphere, nor 1/50 of the shortest Hertz contact time at time.max_impact_speed, nor the\n"
    "Verlet stability limit of a sphere with time.coordination_number contacts, nor (with\n"
    "bonds) 1/20 of the period of the fastest bond mode; otherwise the run is refused (exit\n"
    "status 2) unless --force is given.\n"
    "\n"
    "environment:\n"
    "  JDEM_NEIGHBOUR=allpairs  debugging aid: evaluate every particle pair and every\n"
    "                           particle-wall pair each step (O(N^2)) instead of the Verlet\n"
    "                           list, never renumbered; with --no-sort the results must equal\n"
    "                           the default path's bit for bit\n"
    "\n"
    "watchdog (run, scene key watchdog:): a non-finite state, an overlap beyond\n"
    "max_overlap_fraction of the smaller radius, or a jump of the total energy beyond\n"
    "max_energy_jump between observable samples stops the run (exit status 4).\n"
    "\n"
    "signals (run): SIGINT or SIGTERM stops the run at the next step (a second one at once);\n"
    "the frame of that step is written and the trajectory closed, as OUT.h5.part; with\n"
    "checkpoints a checkpoint of that step is written first.  A signal\n"
    "during set-up stops the run before anything is written; one during the final write lets\n"
    "the complete run finish (exit status 0).\n"
    "\n"
    "exit status:\n"
    "  0        success (cases: every case is valid; run: OUT.h5 is complete)\n"
    "  1        internal error (a bug in jdem)\n"
    "  2        bad input: command line, scene file (including unsafe names), unsafe time step\n"
    "  3        I/O failure: the output cannot be created or written (disk full, read-only,\n"
    "           in use by another run)\n"
    "  4        the simulation failed: the watchdog stopped it or its state diverged\n"
    "  5        out of memory\n"
    "  128 + N  stopped by signal N (130 SIGINT, 143 SIGTERM)\n";

typedef struct cli {
    const char *command, *scene, *case_name, *output, *inlet_record;
    int force, quiet, timing, no_sort, all_laws, plain_loops, threads;
    const char *checkpoint, *resume; /* --checkpoint FILE, --resume FILE */
    long long checkpoint_every;      /* steps, 0: none */
    double checkpoint_seconds;       /* wall seconds, 0: none */
} cli;

/* A whole number of steps >= 1 (0: not one). */
static long long step_count(const char *s) {
    char *end;
    errno = 0;
    const long long v = strtoll(s, &end, 10);
    return *s && !*end && errno == 0 && v >= 1 ? v : 0;
}

/* A positive finite number of seconds (0: not one). */
static double seconds_value(const char *s) {
    char *end;
    errno = 0;
    const double v = strtod(s, &end);
    return *s && !*end && errno == 0 && isfinite(v) && v > 0.0 ? v : 0.0;
}

/* A positive thread count from s (option or environment), or 0. */
static int thread_count(const char *s) {
    char *end;
    errno = 0;
    const long v = s ? strtol(s, &end, 10) : 0;
    return s && *s && !*end && errno == 0 && v >= 1 && v <= 1024 ? (int)v : 0;
}

static int usage_error(const char *msg, const char *arg) {
    fprintf(stderr, "jdem: %s%s%s\n", msg, arg ? ": " : "", arg ? arg : "");
    fprintf(stderr, "Try 'jdem --help'.\n");
    return EXIT_INPUT;
}

/* Returns 0, or an exit status. */
static int parse(int argc, char **argv, cli *c) {
    memset(c, 0, sizeof *c);
    for (int k = 1; k < argc; k++) {
        const char *a = argv[k];
        const int has_value = k + 1 < argc;
        if (!strcmp(a, "--case")) {
            if (!has_value) return usage_error("--case needs a value", NULL);
            c->case_name = argv[++k];
        } else if (!strcmp(a, "-o") || !strcmp(a, "--output")) {
            if (!has_value) return usage_error("-o needs a value", NULL);
            c->output = argv[++k];
        } else if (!strcmp(a, "--inlet-record")) {
            if (!has_value) return usage_error("--inlet-record needs a value", NULL);
            c->inlet_record = argv[++k];
        } else if (!strcmp(a, "--checkpoint") || !strcmp(a, "--resume")) {
            if (!has_value) return usage_error(a[2] == 'c' ? "--checkpoint needs a value"
                                                           : "--resume needs a value", NULL);
            *(a[2] == 'c' ? &c->checkpoint : &c->resume) = argv[++k];
        } else if (!strcmp(a, "--checkpoint-every")) {
            if (!has_value) return usage_error("--checkpoint-every needs a value", NULL);
            if (!(c->checkpoint_every = step_count(argv[++k])))
                return usage_error("--checkpoint-every needs a whole number of steps >= 1", argv[k]);
        } else if (!strcmp(a, "--checkpoint-seconds")) {
            if (!has_value) return usage_error("--checkpoint-seconds needs a value", NULL);
            if (!(c->checkpoint_seconds = seconds_value(argv[++k])))
                return usage_error("--checkpoint-seconds needs a number of seconds > 0", argv[k]);
        } else if (!strcmp(a, "--force")) {
            c->force = 1;
        } else if (!strcmp(a, "--quiet")) {
            c->quiet = 1;
        } else if (!strcmp(a, "--timing")) {
            c->timing = 1;
        } else if (!strcmp(a, "--no-sort")) {
            c->no_sort = 1;
        } else if (!strcmp(a, "--all-laws")) {
            c->all_laws = 1;
        } else if (!strcmp(a, "--plain-loops")) {
            c->plain_loops = 1;
        } else if (!strcmp(a, "--threads")) {
            if (!has_value) return usage_error("--threads needs a value", NULL);
            if (!(c->threads = thread_count(argv[++k])))
                return usage_error("--threads needs a whole number from 1 to 1024", argv[k]);
        } else if (a[0] == '-' && a[1] != '\0') {
            return usage_error("unknown option", a);
        } else if (!c->command) {
            c->command = a;
        } else if (!c->scene) {
            c->scene = a;
        } else {
            return usage_error("unexpected argument", a);
        }
    }
    if (!c->command) return usage_error("missing command", NULL);
    if (strcmp(c->command, "cases") && strcmp(c->command, "run") && strcmp(c->command, "resolve"))
        return usage_error("unknown command", c->command);
    if (!c->scene) return usage_error("missing SCENE", NULL);
    if (strcmp(c->command, "run") &&
        (c->output || c->force || c->quiet || c->timing || c->no_sort || c->all_laws ||
         c->plain_loops || c->threads || c->inlet_record || c->checkpoint || c->resume ||
         c->checkpoint_every || c->checkpoint_seconds))
        return usage_error("-o, --force, --quiet, --threads, --timing, --no-sort, --all-laws, "
                           "--plain-loops, --inlet-record, --checkpoint, --checkpoint-every, "
                           "--checkpoint-seconds and --resume apply to 'run' only", NULL);
    if (!c->threads && getenv("OMP_NUM_THREADS")) {
        if (!(c->threads = thread_count(getenv("OMP_NUM_THREADS"))))
            return usage_error("OMP_NUM_THREADS must be a whole number from 1 to 1024",
                               getenv("OMP_NUM_THREADS"));
    }
    if (!strcmp(c->command, "cases") && c->case_name)
        return usage_error("--case does not apply to 'cases'", NULL);
    return 0;
}

/* The exit status of a failed scene_list_cases / scene_load, after printing its message. */
static int scene_failure(int rc, const char *err) {
    fprintf(stderr, "jdem: %s\n", err);
    return rc == SCENE_NO_MEMORY ? EXIT_NO_MEMORY : EXIT_INPUT;
}

/* The names are printed only once every case has loaded: a scene that cannot run is refused
 * here, not at the run of its first bad case. */
static int cmd_cases(const cli *c) {
    char err[1024];
    char **names = NULL;
    const int n = scene_list_cases(c->scene, &names, err, sizeof err);
    if (n < 0) return scene_failure(n, err);
    int rc = 0;
    for (int k = 0; k < n && !rc; k++) {
        jd_scene sc;
        const int loaded = scene_load(c->scene, names[k], &sc, err, sizeof err);
        if (loaded != 0) rc = scene_failure(loaded, err);
        else scene_free(&sc);
    }
    for (int k = 0; k < n && !rc; k++) printf("%s\n", names[k]);
    scene_free_names(names, n);
    return rc;
}

static int load(const cli *c, jd_scene *sc) {
    char err[1024];
    const int rc = scene_load(c->scene, c->case_name, sc, err, sizeof err);
    return rc ? scene_failure(rc, err) : 0;
}

static int cmd_resolve(const cli *c) {
    jd_scene sc;
    int rc = load(c, &sc);
    if (rc) return rc;
    if (scene_emit_yaml(&sc, stdout) != 0 || fflush(stdout) != 0) {
        fprintf(stderr, "jdem: cannot write the resolved scene\n");
        rc = EXIT_IO;
    }
    scene_free(&sc);
    return rc;
}

/* mkdir -p of the directory part of path. */
static int make_parent_dirs(const char *path, char *err, size_t errlen) {
    char buf[4096];
    if (snprintf(buf, sizeof buf, "%s", path) >= (int)sizeof buf) {
        snprintf(err, errlen, "output path too long");
        return -1;
    }
    for (char *p = buf + 1; *p; p++) {
        if (*p != '/') continue;
        *p = '\0';
        if (mkdir(buf, 0777) != 0 && errno != EEXIST) {
            snprintf(err, errlen, "cannot create directory %.900s: %s", buf, strerror(errno));
            return -1;
        }
        *p = '/';
    }
    return 0;
}

/* The guard's verdict (kernel/jdem_guard.h); prints the summary.  Returns 0 to go ahead, else an
 * exit status. */
static int check_time_step(const jd_scene *sc, const cli *c) {
    jd_guard_input in;
    jd_guard_species *species;
    jd_guard_result g;
    if (sim_guard(sc, &in, &species, &g) != 0) {
        fprintf(stderr, "jdem: out of memory in the time-step guard\n");
        return EXIT_NO_MEMORY;
    }
    free(species);
    if (!c->quiet) {
        char how[64] = "";
        if (sc->dt_auto) snprintf(how, sizeof how, " (auto: %g x the guard's safe dt)", JD_DT_AUTO_FACTOR);
        fprintf(stderr, "jdem: dt = %.6g s%s; 20 %% Rayleigh bound = %.6g s; shortest contact time = %.6g s",
                sc->dt, how, g.rayleigh_bound, g.contact_time);
        if (isfinite(g.contact_time))
            fprintf(stderr, " at %.6g m/s (%.1f steps per contact); Verlet limit at coordination "
                    "number %g = %.6g s", sc->max_impact_speed, g.contact_time / sc->dt,
                    sc->coordination_number, g.coordination_bound);
        else
            fprintf(stderr, " (no impact to resolve)");
        if (isfinite(g.bond_bound))
            fprintf(stderr, "; 1/20 of the fastest bond period = %.6g s", g.bond_bound);
        fprintf(stderr, "; largest safe dt = %.9g s\n", g.safe_dt);
    }
    if (!g.violated) return 0;
    char msg[512];
    if (!c->force) {
        jd_guard_refusal(&in, &g, "Use --force to run anyway.", msg, sizeof msg);
        fprintf(stderr, "jdem: %s\n", msg);
        return EXIT_INPUT;
    }
    jd_guard_warning(&in, &g, "--force", msg, sizeof msg);
    fprintf(stderr, "jdem: %s\n", msg);
    return 0;
}

/* Set by SIGINT/SIGTERM, read by the run loop (jd_sim.stop): the handler does no I/O. */
static volatile sig_atomic_t stop_signal;

static void on_stop_signal(int sig) { stop_signal = sig; }

/* SA_RESETHAND: a second signal takes the default action, for a run that does not get to its
 * next step.  SA_RESTART: HDF5's writes are not cut short by the first one.  Installed before
 * the scene is read, so that no signal finds OUT.part created but not yet watched. */
static void catch_stop_signals(void) {
    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_stop_signal;
    sigemptyset(&sa.sa_mask);
    sa.sa_flags = SA_RESETHAND | SA_RESTART;
    sigaction(SIGINT, &sa, NULL);
    sigaction(SIGTERM, &sa, NULL);
    /* a file-size limit (ulimit -f) fails the write (EFBIG), reported like a full disk,
     * instead of killing the run before it can report */
    signal(SIGXFSZ, SIG_IGN);
}

static const char *stop_signal_text(void) {
    return stop_signal == SIGINT ? "interrupted (SIGINT)" : "terminated (SIGTERM)";
}

/* A signal before the trajectory is created: stop with nothing written. */
static int stopped_in_setup(void) {
    fprintf(stderr, "jdem: %s during set-up; nothing was written\n", stop_signal_text());
    return 128 + stop_signal;
}

/* The engine reports every allocation failure as "out of memory ..." (sim.c, neighbour.c,
 * reorder.c, bonds.c); its other set-up failures come from the scene (a loads file, walls). */
static int setup_failure(const char *err) {
    return strstr(err, "out of memory") ? EXIT_NO_MEMORY : EXIT_INPUT;
}

/* The exit status of a run that did not complete, after its message.  The file was closed
 * with ok = 0: readable, and kept as OUT.part, never under the name of a complete run. */
static int report_unfinished(int rc, const jd_sim *sim, const char *err, const char *out,
                             int kept) {
    if (rc == JD_RUN_STOPPED) {
        fprintf(stderr, "jdem: %s at step %lld; the trajectory up to step %lld is kept, closed, "
                "as %s.part\n", stop_signal_text(), (long long)sim->step,
                (long long)sim->frame_step, out);
        return 128 + stop_signal;
    }
    if (rc == JD_RUN_TRIPPED) {
        fprintf(stderr, "jdem: %s; the trajectory up to step %lld is kept, closed, as %s.part "
                "(the run failed)\n", err, (long long)sim->frame_step, out);
        return EXIT_FAILED_RUN;
    }
    if (kept)
        fprintf(stderr, "jdem: %s; the partial trajectory is in %s.part\n", err, out);
    else
        fprintf(stderr, "jdem: %s; nothing could be kept\n", err);
    if (rc == JD_RUN_OUTPUT) return EXIT_IO;
    return strstr(err, "out of memory") ? EXIT_NO_MEMORY : EXIT_FAILED_RUN;
}

/* One line per part of the time loop, and a machine-readable summary line (scripts/bench.py). */
static void print_timing(const jd_sim *s) {
    const jd_timing *t = &s->accounts.timing;
    const double total = t->neighbour + t->pairs + t->walls + t->integration + t->output;
    const struct {
        const char *name;
        double v;
    } part[] = {{"neighbour search", t->neighbour}, {"pair forces", t->pairs},
                {"wall forces", t->walls}, {"integration", t->integration}, {"output", t->output}};
    fprintf(stderr, "jdem: timing of %lld steps, %zu particles, %d thread(s), %lld neighbour builds "
            "(%lld of this process's partial):\n", (long long)s->step, s->particles.n, s->threads.n,
            (long long)s->lists.n_builds, (long long)s->lists.n_partial);
    char laws[96];
    fprintf(stderr, "jdem:   law set %s\n", jd_law_set_describe(s->run.features, laws, sizeof laws));
    for (size_t k = 0; k < sizeof part / sizeof *part; k++)
        fprintf(stderr, "jdem:   %-17s %10.4f s  %5.1f %%\n", part[k].name, part[k].v,
                total > 0.0 ? 100.0 * part[k].v / total : 0.0);
    fprintf(stderr, "jdem:   time loop         %10.4f s  (the parts above and the per-step checks)\n",
            t->loop);
    fprintf(stderr, "jdem:   engine memory %.1f MB (%.0f bytes per particle; the scene and the "
            "libraries come on top)\n", (double)sim_memory_bytes(s) / 1e6,
            s->particles.n ? (double)sim_memory_bytes(s) / (double)s->particles.n : 0.0);
    fprintf(stderr, "jdem-timing: neighbour=%.6f pairs=%.6f walls=%.6f integration=%.6f output=%.6f "
            "loop=%.6f steps=%lld builds=%lld threads=%d pair_entries=%zu wall_entries=%zu "
            "engine_bytes=%zu partial_builds=%lld\n",
            t->neighbour, t->pairs, t->walls, t->integration, t->output, t->loop, (long long)s->step,
            (long long)s->lists.n_builds, s->threads.n, s->lists.pairs.n, s->lists.wall_pairs.n,
            sim_memory_bytes(s), (long long)s->lists.n_partial);
    const int64_t inserted = sim_inlets_inserted(s);
    if (inserted > 0)
        fprintf(stderr, "jdem-inlets: inserted=%lld seconds=%.6f ns_per_particle=%.1f\n",
                (long long)inserted, sim_inlets_seconds(s),
                1e9 * sim_inlets_seconds(s) / (double)inserted);
}

/* The output path: -o, or out/SCENE_NAME/CASE.jdem.h5.  The names are checked by the scene
 * reader (no '/', never "." or ".."), so the default path stays inside out/. */
static int output_path(const cli *c, const jd_scene *sc, char *out, size_t size) {
    const int k = c->output ? snprintf(out, size, "%s", c->output)
                            : snprintf(out, size, "out/%s/%s.jdem.h5", sc->name, sc->case_name);
    if (k < 0 || (size_t)k >= size - sizeof ".part") {
        fprintf(stderr, "jdem: the output path is too long; valid: at most %zu characters\n",
                size - sizeof ".part" - 1);
        return EXIT_INPUT;
    }
    return 0;
}

/* The trajectory's particle set in scene order (the engine may have renumbered the particles;
 * with inlets every particle the run can hold).  Arrays of *n entries in one block (free id). */
static int output_particles(const jd_scene *sc, const jd_sim *sim, jd_h5md_particles *p) {
    const size_t n = sim_inlets_rows(sim), n1 = n ? n : 1;
    int64_t *id = malloc(n1 * sizeof *id);
    int32_t *species = malloc(n1 * sizeof *species);
    double *radius = malloc(2 * n1 * sizeof *radius);
    *p = (jd_h5md_particles){.n = n, .id = id, .species = species, .radius = radius,
                             .mass = radius ? radius + n1 : NULL, .growing = sim->inlets != NULL};
    if (!id || !species || !radius) return -1;
    if (sim->inlets) return sim_inlets_particles(sim, id, species, radius, radius + n1);
    memcpy(id, sc->id, n * sizeof *id);
    memcpy(species, sc->material, n * sizeof *species);
    memcpy(radius, sc->radius, n * sizeof *radius);
    sim_scalars_in_scene_order(&sim->particles, sim->particles.mass, radius + n1);
    return 0;
}

static void free_output_particles(jd_h5md_particles *p) {
    free((void *)p->id);
    free((void *)p->species);
    free((void *)p->radius);
}

/* The scene's walls into the trajectory (/jdem/walls), as they stand at time 0: the plane and
 * cylinder walls in scene order, then the mesh walls in scene order (a moving one again at every
 * frame, sim.c). */
static int output_walls(const jd_scene *sc, jd_h5md *h, char *err, size_t errlen) {
    const size_t n = sc->n_walls + sc->n_mesh_walls;
    jd_h5md_wall *w = calloc(n ? n : 1, sizeof *w);
    if (!w) {
        snprintf(err, errlen, "out of memory for the walls' output");
        return -1;
    }
    for (size_t k = 0; k < sc->n_walls; k++) {
        const jd_wall *s = &sc->walls[k];
        w[k] = (jd_h5md_wall){.name = s->name, .type = s->type, .radius = s->radius,
                              .inside = s->inside};
        memcpy(w[k].corners, s->corners, sizeof w[k].corners);
        memcpy(w[k].axis, s->axis, sizeof w[k].axis);
        memcpy(w[k].velocity, s->velocity, sizeof w[k].velocity);
    }
    for (size_t k = 0; k < sc->n_mesh_walls; k++) {
        const jd_mesh_wall *m = &sc->mesh_walls[k];
        w[sc->n_walls + k] = (jd_h5md_wall){.name = m->name, .type = 2, .n_triangles = m->ntri,
                                            .triangles = (const double(*)[3][3])m->corner,
                                            .moved = m->motion.kind != JD_MESH_STILL};
    }
    const int rc = jd_h5md_set_walls(h, n, w, err, errlen);
    free(w);
    return rc;
}

/* Open the trajectory of a set-up run; NULL after reporting, with the exit status in *rc. */
static jd_h5md *create_output(const jd_scene *sc, const jd_sim *sim, const char *out, int *rc) {
    char err[1024] = "";
    char *yaml = scene_yaml_string(sc);
    jd_h5md_particles parts;
    const int parts_ok = output_particles(sc, sim, &parts) == 0;
    jd_h5md *h = NULL;
    *rc = EXIT_NO_MEMORY;
    if (!yaml || !parts_ok) {
        fprintf(stderr, "jdem: out of memory preparing the output\n");
    } else {
        const jd_h5md_meta meta = {.creator = "jdem", .creator_version = JDEM_BUILD,
                                   .scene_name = sc->name, .case_name = sc->case_name,
                                   .scene_yaml = yaml, .dt = sc->dt};
        if (!(h = jd_h5md_create(out, &meta, &parts, err, sizeof err)) ||
            output_walls(sc, h, err, sizeof err) != 0) {
            fprintf(stderr, "jdem: %s\n", err);
            *rc = EXIT_IO;
            if (h) jd_h5md_close(h, 0, err, sizeof err);
            h = NULL;
        }
    }
    free(yaml);
    free_output_particles(&parts);
    return h;
}

/* The checkpointer of the run: where and when it writes (path NULL: never), and the state of
 * --resume restored into sim.  Returns 0 or an exit status. */
static int setup_checkpoints(const cli *c, const jd_scene *sc, jd_sim *sim, const char *out,
                             jd_checkpointer *ck, char *path, size_t len) {
    char *yaml = scene_yaml_string(sc);
    if (!yaml) {
        fprintf(stderr, "jdem: out of memory for the scene's identity\n");
        return EXIT_NO_MEMORY;
    }
    const uint64_t hash = jd_checkpoint_scene_hash(yaml);
    free(yaml);
    const int writes = c->checkpoint || c->checkpoint_every || c->checkpoint_seconds;
    const size_t stem = strlen(out) > 3 && !strcmp(out + strlen(out) - 3, ".h5") ? strlen(out) - 3
                                                                                 : strlen(out);
    const int k = c->checkpoint ? snprintf(path, len, "%s", c->checkpoint)
                                : snprintf(path, len, "%.*s.ckpt.h5", (int)stem, out);
    if (k < 0 || (size_t)k >= len - sizeof ".tmp") {
        fprintf(stderr, "jdem: the checkpoint path is too long\n");
        return EXIT_INPUT;
    }
    jd_checkpointer_init(ck, writes ? path : NULL, c->checkpoint_every, c->checkpoint_seconds,
                         hash, sc->name, sc->case_name);
    if (!c->resume) return 0;
    char err[1024];
    const int rc = jd_checkpoint_read(sim, ck, c->resume, err, sizeof err);
    if (rc != 0) {
        fprintf(stderr, "jdem: %s\n", err);
        return rc == JD_CHECKPOINT_NO_MEMORY ? EXIT_NO_MEMORY : EXIT_INPUT;
    }
    if (!c->quiet)
        fprintf(stderr, "jdem: resuming from %s at step %lld\n", c->resume, (long long)sim->step);
    return 0;
}

/* The trajectory of a resumed run: the stopped run's prefix moved aside, a fresh OUT.part
 * with that prefix copied in (io/h5md_resume.h).  NULL after reporting, with *rc. */
static jd_h5md *resume_output(const jd_scene *sc, const jd_sim *sim, const char *out, int *rc) {
    char src[4200], err[1024] = "";
    if (jd_h5md_resume_source(out, sim->frame_step, src, sizeof src, err, sizeof err)) {
        fprintf(stderr, "jdem: %s\n", err);
        *rc = EXIT_INPUT;
        return NULL;
    }
    jd_h5md *h = create_output(sc, sim, out, rc);
    if (h && jd_h5md_resume_copy(src, h, sim->frame_step, sim->step, err, sizeof err)) {
        fprintf(stderr, "jdem: %s\n", err);
        jd_h5md_close(h, 0, err, sizeof err);
        *rc = EXIT_IO;
        return NULL;
    }
    if (h) unlink(src); /* its prefix is in OUT.part now, flushed */
    return h;
}

/* Run the set-up sim into h and close it; returns the exit status. */
static int run_and_close(const cli *c, jd_sim *sim, jd_h5md *h, const char *out,
                         jd_checkpointer *ck) {
    char err[1024] = "";
    sim->stop = &stop_signal;
    const int run_rc = sim_run_checkpointed(sim, h, !c->quiet, ck, err, sizeof err);
    if (c->timing) print_timing(sim);
    if (run_rc != 0) {
        char err2[1024];
        int kept = 1;
        if (jd_h5md_close(h, 0, err2, sizeof err2) != 0) {
            fprintf(stderr, "jdem: closing %s.part failed: %s\n", out, err2);
            kept = strstr(err2, "nothing could be kept") == NULL; /* the writer removed it */
        }
        const int status = report_unfinished(run_rc, sim, err, out, kept);
        if (run_rc == JD_RUN_STOPPED && ck->path && ck->last_step == sim->step)
            fprintf(stderr, "jdem: checkpoint of step %lld written to %s; continue with --resume "
                    "%s\n", (long long)sim->step, ck->path, ck->path);
        return status;
    }
    if (jd_h5md_close(h, 1, err, sizeof err) != 0) {
        fprintf(stderr, "jdem: %s\n", err);
        return EXIT_IO;
    }
    if (!c->quiet)
        fprintf(stderr, "jdem: wrote %s (%lld steps, %lld neighbour builds)\n", out,
                (long long)sim->step, (long long)sim->lists.n_builds);
    if (sim_lost_particles(sim) > 0) /* never silent: the deposit is short of them */
        fprintf(stderr, "jdem: %lld particles left the domain and were deleted (they took %.6g J; "
                "observables lost_particles, lost_energy)\n", (long long)sim_lost_particles(sim),
                sim_lost_energy(sim));
    if (sim_skipped_particles(sim) > 0) /* never silent: the stream is short of them */
        fprintf(stderr, "jdem: the inlets skipped %lld particles whose place was occupied "
                "(observable skipped_particles)\n", (long long)sim_skipped_particles(sim));
    if (ck->path) unlink(ck->path); /* a complete run has nothing to resume */
    return 0;
}

static int cmd_run(const cli *c) {
    catch_stop_signals();
    jd_scene sc;
    int rc = load(c, &sc);
    if (rc) return rc;
    char out[4096], err[1024] = "";
    jd_sim sim;
    const jd_sim_options opt = {
        .allpairs = getenv("JDEM_NEIGHBOUR") && !strcmp(getenv("JDEM_NEIGHBOUR"), "allpairs"),
        .no_sort = c->no_sort, .all_laws = c->all_laws, .plain_loops = c->plain_loops};
    if ((rc = check_time_step(&sc, c)) || (rc = output_path(c, &sc, out, sizeof out))) {
        scene_free(&sc);
        return rc;
    }
    if (make_parent_dirs(out, err, sizeof err) != 0) {
        fprintf(stderr, "jdem: %s\n", err);
        rc = EXIT_IO;
    } else if (sim_init(&sim, &sc, &opt, c->threads ? c->threads : 1, err, sizeof err) != 0) {
        fprintf(stderr, "jdem: %s\n", err);
        rc = setup_failure(err);
    } else {
        jd_h5md *h = NULL;
        jd_checkpointer ck;
        char ck_path[4200];
        rc = setup_checkpoints(c, &sc, &sim, out, &ck, ck_path, sizeof ck_path);
        FILE *record = c->inlet_record ? fopen(c->inlet_record, "w") : NULL;
        if (rc) {
            /* reported */
        } else if (c->inlet_record && !record) {
            fprintf(stderr, "jdem: %s: %s\n", c->inlet_record, strerror(errno));
            rc = EXIT_IO;
        } else if (stop_signal) {
            rc = stopped_in_setup();
        } else if ((h = c->resume ? resume_output(&sc, &sim, out, &rc)
                                  : create_output(&sc, &sim, out, &rc))) {
            if (record) fprintf(record, "id,step,x,y,z,vx,vy,vz\n");
            sim_inlets_log(&sim, record);
            rc = run_and_close(c, &sim, h, out, &ck);
        }
        if (record && fclose(record) != 0 && rc == 0) {
            fprintf(stderr, "jdem: %s: %s\n", c->inlet_record, strerror(errno));
            rc = EXIT_IO;
        }
        sim_free(&sim);
    }
    scene_free(&sc);
    return rc;
}

int main(int argc, char **argv) {
    for (int k = 1; k < argc; k++) {
        if (!strcmp(argv[k], "--help") || !strcmp(argv[k], "-h")) {
            fputs(usage_text, stdout);
            return 0;
        }
        if (!strcmp(argv[k], "--version")) {
            printf("jdem %s\n", JDEM_BUILD);
            return 0;
        }
    }
    cli c;
    const int rc = parse(argc, argv, &c);
    if (rc) return rc;
    if (!strcmp(c.command, "cases")) return cmd_cases(&c);
    if (!strcmp(c.command, "resolve")) return cmd_resolve(&c);
    return cmd_run(&c);
}
