/*
 * scene_check.c — engine test of the scene reader (stepper/scene*.c).
 *
 *   bad/NAME.yaml   must fail to load with exactly the message in bad/NAME.expect (the message's
 *                   "DIR/bad/" prefix removed, so the file starts "NAME.yaml:LINE: ...");
 *   good/NAME.yaml  every case must load, resolve to YAML, load back with identical values and
 *                   resolve to identical text; a few scenes have value checks of their own.
 *
 * One line per check, "PASS name" or "FAIL name: detail"; exit status 1 if anything failed.
 *
 * Build and run from the repository root:
 *   gcc -std=c11 -O2 -g -Wall -Wextra -Werror -D_POSIX_C_SOURCE=200809L -Ikernel -Iio -Istepper \
 *       $(pkg-config --cflags yaml-0.1) tests/engine/scene_check.c stepper/scene*.c \
 *       -o build/scene_check $(pkg-config --libs yaml-0.1) -lm
 *   build/scene_check tests/scenes
 * (add -fsanitize=address,undefined -fno-omit-frame-pointer for the sanitizer run)
 */
#include <dirent.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "scene.h"

static int failures;

static void pass(const char *name) { printf("PASS %s\n", name); }

static void fail(const char *name, const char *fmt, const char *detail) {
    printf("FAIL %s: ", name);
    printf(fmt, detail);
    printf("\n");
    failures++;
}

/* Sorted *.yaml names of a directory (free with scene_free_names). */
static int list_yaml(const char *dir, char ***out) {
    DIR *d = opendir(dir);
    if (!d) return -1;
    char **names = NULL;
    int n = 0;
    for (struct dirent *e; (e = readdir(d)) != NULL;) {
        size_t len = strlen(e->d_name);
        if (len < 6 || strcmp(e->d_name + len - 5, ".yaml") != 0) continue;
        char **grown = realloc(names, (size_t)(n + 1) * sizeof *names);
        if (!grown) break;
        names = grown;
        names[n++] = strdup(e->d_name);
    }
    closedir(d);
    for (int i = 1; i < n; i++) /* insertion sort: a few dozen names */
        for (int j = i; j > 0 && strcmp(names[j - 1], names[j]) > 0; j--) {
            char *t = names[j];
            names[j] = names[j - 1];
            names[j - 1] = t;
        }
    *out = names;
    return n;
}

static char *read_text(const char *path) {
    FILE *f = fopen(path, "rb");
    if (!f) return NULL;
    char *buf = calloc(1, 65536);
    size_t n = buf ? fread(buf, 1, 65535, f) : 0;
    fclose(f);
    while (buf && n > 0 && (buf[n - 1] == '\n' || buf[n - 1] == '\r')) buf[--n] = '\0';
    return buf;
}

/* The first error of any case of a bad scene, or "" when every case loads. */
static void first_error(const char *path, char *err, size_t errlen) {
    char **cases;
    int n = scene_list_cases(path, &cases, err, errlen);
    if (n < 0) return;
    err[0] = '\0';
    for (int i = 0; i < n && !err[0]; i++) {
        jd_scene s;
        if (scene_load(path, cases[i], &s, err, errlen) == 0) scene_free(&s);
    }
    scene_free_names(cases, n);
}

static void check_bad(const char *dir) {
    char bad[1024], **names = NULL; /* stays NULL when the directory cannot be read */
    snprintf(bad, sizeof bad, "%s/bad", dir);
    int n = list_yaml(bad, &names);
    if (n < 15) fail("bad scenes", "%s", "fewer than 15 files in bad/");
    for (int i = 0; i < n; i++) {
        char path[2048], expect_path[2048], err[2048], name[512];
        snprintf(path, sizeof path, "%s/%s", bad, names[i]);
        snprintf(expect_path, sizeof expect_path, "%.*s.expect", (int)(strlen(path) - 5), path);
        snprintf(name, sizeof name, "bad/%s", names[i]);
        first_error(path, err, sizeof err);
        const char *msg = err;
        if (strncmp(msg, bad, strlen(bad)) == 0 && msg[strlen(bad)] == '/') msg += strlen(bad) + 1;
        char *expect = read_text(expect_path);
        if (!err[0])
            fail(name, "%s", "loaded without error");
        else if (!expect)
            fail(name, "no .expect file; message: %s", msg);
        else if (strcmp(msg, expect) != 0)
            fail(name, "message differs: %s", msg);
        else
            pass(name);
        free(expect);
    }
    scene_free_names(names, n);
}

/* ---------------------------------------------------------------------------------------- */
/* Round trip                                                                                */

#define SAME(field)                                                              \
    do {                                                                         \
        if (memcmp(&a->field, &b->field, sizeof a->field) != 0) return #field;   \
    } while (0)
#define SAME_ARRAY(ptr, count)                                                   \
    do {                                                                         \
        if ((count) > 0 && memcmp(a->ptr, b->ptr, (count) * sizeof *a->ptr) != 0) return #ptr; \
    } while (0)

static const char *diff_material(const jd_material *x, const jd_material *y) {
    if (strcmp(x->name, y->name) != 0) return "materials.name";
    if (x->has_elastic != y->has_elastic) return "materials.has_elastic";
    if (x->has_mepa != y->has_mepa) return "materials.has_mepa";
    const double u[] = {x->youngs_modulus,    x->poisson_ratio,       x->density,
                        x->restitution,       x->friction,            x->rolling_friction,
                        x->loading_stiffness, x->unloading_stiffness, x->cohesive_stiffness};
    const double v[] = {y->youngs_modulus,    y->poisson_ratio,       y->density,
                        y->restitution,       y->friction,            y->rolling_friction,
                        y->loading_stiffness, y->unloading_stiffness, y->cohesive_stiffness};
    return memcmp(u, v, sizeof u) ? "materials values" : NULL;
}

static const char *diff_wall(const jd_wall *a, const jd_wall *b) {
    if (strcmp(a->name, b->name) != 0) return "walls.name";
    SAME(type);
    SAME(material);
    SAME(velocity);
    SAME(corners);
    SAME(normal);
    SAME(axis);
    SAME(radius);
    SAME(inside);
    return NULL;
}

/* The first field in which two inlets differ, or NULL. */
static const char *diff_inlet(const jd_inlet *a, const jd_inlet *b) {
    if (strcmp(a->name, b->name)) return "inlets.name";
    SAME(n);
    SAME_ARRAY(rel, 3 * a->n);
    SAME_ARRAY(radius, a->n);
    SAME_ARRAY(material, a->n);
    SAME(origin);
    SAME(velocity);
    SAME(plane_point);
    SAME(plane_normal);
    SAME(period);
    SAME(offset);
    SAME(first_id);
    SAME(stop);
    SAME(sections);
    SAME(stop_time);
    SAME(height);
    SAME(below_speed);
    SAME(every);
    SAME(n_bonds);
    SAME_ARRAY(bond_pair, 2 * a->n_bonds);
    SAME_ARRAY(bond_type, a->n_bonds);
    SAME(n_groups);
    SAME_ARRAY(group_first, a->n_groups ? a->n_groups + 1 : 0);
    SAME_ARRAY(group_member, a->n_groups ? a->group_first[a->n_groups] : 0);
    SAME_ARRAY(group_of, a->n_groups ? a->n : 0);
    return NULL;
}

/* The first field in which two scenes differ (the path excepted), or NULL. */
static const char *diff_scenes(const jd_scene *a, const jd_scene *b) {
    if (strcmp(a->name, b->name) || strcmp(a->case_name, b->case_name)) return "name";
    if (strcmp(a->description, b->description)) return "description";
    SAME(dt);
    SAME(steps);
    SAME(max_impact_speed);
    SAME(output_every);
    SAME(observables_every);
    SAME(gravity);
    SAME(wall_rule);
    SAME(damping_map);
    SAME(xi_limit);
    SAME(mu_r);
    SAME(tangential_rule);
    SAME(normal_law);
    SAME(mepa_exponent);
    SAME(mepa_plastic_depth);
    SAME(watchdog.enabled);
    SAME(watchdog.max_overlap_fraction);
    SAME(watchdog.max_energy_jump);
    SAME(skin_steps);
    SAME(n_materials);
    SAME(n_particles);
    SAME(n_walls);
    for (size_t i = 0; i < a->n_materials; i++) {
        const char *d = diff_material(&a->materials[i], &b->materials[i]);
        if (d) return d;
    }
    SAME_ARRAY(interactions, a->n_materials * a->n_materials);
    SAME_ARRAY(id, a->n_particles);
    SAME_ARRAY(material, a->n_particles);
    SAME_ARRAY(radius, a->n_particles);
    SAME_ARRAY(position, 3 * a->n_particles);
    SAME_ARRAY(velocity, 3 * a->n_particles);
    SAME_ARRAY(angular_velocity, 3 * a->n_particles);
    SAME_ARRAY(fixed, a->n_particles);
    SAME_ARRAY(force, 3 * a->n_particles);
    SAME(has_loads);
    SAME(n_bond_types);
    for (size_t i = 0; i < a->n_bond_types; i++) {
        if (strcmp(a->bond_types[i].name, b->bond_types[i].name)) return "bond_types.name";
        SAME(bond_types[i].p);
    }
    SAME(n_bonds);
    SAME_ARRAY(bond_ids, 2 * a->n_bonds);
    SAME_ARRAY(bond_type, a->n_bonds);
    SAME(n_bond_rules);
    for (size_t r = 0; r < a->n_bond_rules; r++) {
        SAME(bond_rules[r].type);
        SAME(bond_rules[r].step);
        SAME(bond_rules[r].id_range);
        SAME(bond_rules[r].max_gap);
        if (memcmp(a->bond_rules[r].materials, b->bond_rules[r].materials, a->n_materials))
            return "bond_rules.materials";
    }
    for (size_t i = 0; i < a->n_walls; i++) {
        const char *d = diff_wall(&a->walls[i], &b->walls[i]);
        if (d) return d;
    }
    SAME(n_inlets);
    for (size_t k = 0; k < a->n_inlets; k++) {
        const char *d = diff_inlet(&a->inlets[k], &b->inlets[k]);
        if (d) return d;
    }
    return NULL;
}

/* Emit s, load the text back, compare values and the re-emitted text. */
static void round_trip(const char *name, const jd_scene *s, const char *tmpdir) {
    char path[1024], err[2048];
    snprintf(path, sizeof path, "%s/resolved.yaml", tmpdir);
    char *text = scene_yaml_string(s);
    FILE *f = fopen(path, "w");
    if (!text || !f || scene_emit_yaml(s, f) != 0) {
        fail(name, "%s", "cannot emit the scene");
        if (f) fclose(f);
        free(text);
        return;
    }
    fclose(f);
    char *file_text = read_text(path);
    jd_scene back;
    if (!file_text || strncmp(file_text, text, strlen(file_text)) != 0) {
        fail(name, "%s", "scene_emit_yaml and scene_yaml_string differ");
    } else if (scene_load(path, NULL, &back, err, sizeof err) != 0) {
        fail(name, "the resolved scene does not load: %s", err);
    } else {
        const char *d = diff_scenes(s, &back);
        char *again = scene_yaml_string(&back);
        if (d)
            fail(name, "round trip changes %s", d);
        else if (!again || strcmp(again, text) != 0)
            fail(name, "%s", "re-emitted text differs");
        else
            pass(name);
        free(again);
        scene_free(&back);
    }
    unlink(path);
    free(file_text);
    free(text);
}

/* ---------------------------------------------------------------------------------------- */
/* Value checks of particular good scenes                                                    */

static const char *check_two_spheres(const jd_scene *s) {
    if (s->n_particles != 2 || s->id[0] != 1 || s->id[1] != 2) return "ids";
    if (s->steps != 12000) return "steps from end_time";
    /* |v1 - v2| = 20 and no gravity */
    if (s->max_impact_speed != 20.0) return "default max_impact_speed";
    if (strcmp(s->case_name, "two_spheres") != 0) return "case name";
    if (s->output_every != 100 || s->observables_every != 100) return "output defaults";
    if (s->skin_steps != 20) return "default neighbour.skin_steps";
    return NULL;
}

static const char *check_sweep(const jd_scene *s) {
    int soft = strstr(s->case_name, "soft") != NULL;
    if (s->materials[0].youngs_modulus != (soft ? 1.0e9 : 4.8e10)) return "override of E";
    if (soft && s->materials[0].friction != 0.5) return "override adding a key";
    int fast = strstr(s->case_name, "fast") != NULL;
    if (s->velocity[0] != (fast ? 2.0 : 1.0)) return "override of a sequence item";
    if (s->max_impact_speed != 3.5) return "given max_impact_speed";
    return NULL;
}

static const char *check_lattice(const jd_scene *s) {
    if (s->n_particles != 1 + 4 * 4 * 3) return "particle count";
    if (s->id[0] != 4 || s->id[1] != 5 || s->id[s->n_particles - 1] != 52) return "ids";
    size_t small = 0;
    for (size_t i = 1; i < s->n_particles; i++) small += s->radius[i] == 0.001;
    if (small != 12) return "radius mixture (25% of 48)";
    if (s->walls[0].normal[2] != 1.0 || s->walls[1].inside != 1) return "walls";
    if (s->interactions[0 * 2 + 1].friction != 0.3 || s->interactions[1 * 2 + 0].friction != 0.3)
        return "interaction matrix";
    if (s->wall_rule != 1 || s->damping_map != 1 || s->xi_limit != 1 || s->mu_r != 0.5)
        return "model";
    if (s->skin_steps != 7) return "neighbour.skin_steps";
    /* particle speeds 0 and 2 against walls at rest, plus sqrt(2 |g| H); H is between 0.021375
     * and 0.022625 m whatever the jitter (bounding box from the lattice to the top sphere). */
    if (!(s->max_impact_speed >= 2.0 + sqrt(2.0 * 9.81 * 0.021375) &&
          s->max_impact_speed <= 2.0 + sqrt(2.0 * 9.81 * 0.022625)))
        return "max_impact_speed";
    return NULL;
}

/* Counts in closed form: a simple-cubic n x m x k block has 3nmk - nm - mk - nk face bonds; the
 * FCC cluster of diameter 6.9 r is a centre sphere with its 12 neighbours (a cuboctahedron: 12
 * spokes + 24 edges); the step-0 rule bonds the two touching explicit spheres (ids 1, 2) and not
 * the distant one; the later rule stays a rule with its step = ceil(time/dt). */
static const char *check_bonds(const jd_scene *s) {
    if (s->n_particles != 3 + 12 + 13) return "particle count";
    if (s->n_bonds != 1 + 20 + 36) return "bond count";
    if (s->bond_ids[0] != 1 || s->bond_ids[1] != 2) return "step-0 rule bond";
    for (size_t k = 1; k < s->n_bonds; k++)
        if (s->bond_ids[2 * k] < s->bond_ids[2 * k - 2] ||
            (s->bond_ids[2 * k] == s->bond_ids[2 * k - 2] &&
             s->bond_ids[2 * k + 1] <= s->bond_ids[2 * k - 1]))
            return "bonds sorted by ids";
    if (s->n_bond_rules != 1 || s->bond_rules[0].step != 3) return "later rule";
    if (s->bond_rules[0].id_range[0] != 1 || s->bond_rules[0].id_range[1] != 28)
        return "default id_range";
    if (!isinf(s->bond_types[0].p.tau_c) || s->bond_types[0].p.bending != 1) return "bond type";
    if (!s->fixed[0] || s->force[3 * 2 + 2] != -0.5 || !s->has_loads) return "loads";
    return NULL;
}

static void check_values(const char *file, const jd_scene *s) {
    static const struct {
        const char *file;
        const char *(*check)(const jd_scene *);
    } checks[] = {{"two_spheres.yaml", check_two_spheres},
                  {"sweep.yaml", check_sweep},
                  {"lattice_box.yaml", check_lattice},
                  {"bonds.yaml", check_bonds}};
    for (size_t i = 0; i < sizeof checks / sizeof checks[0]; i++) {
        if (strcmp(file, checks[i].file) != 0) continue;
        char name[512];
        snprintf(name, sizeof name, "values good/%s %s", file, s->case_name);
        const char *d = checks[i].check(s);
        if (d)
            fail(name, "%s", d);
        else
            pass(name);
    }
}

static void check_good_file(const char *dir, const char *file, const char *tmpdir) {
    char path[2048], err[2048], name[512];
    snprintf(path, sizeof path, "%s/good/%s", dir, file);
    char **cases;
    int n = scene_list_cases(path, &cases, err, sizeof err);
    snprintf(name, sizeof name, "cases good/%s", file);
    if (n < 1) {
        fail(name, "%s", err);
        return;
    }
    pass(name);
    for (int i = 0; i < n; i++) {
        jd_scene s, again;
        snprintf(name, sizeof name, "round-trip good/%s %s", file, cases[i]);
        if (scene_load(path, cases[i], &s, err, sizeof err) != 0) {
            fail(name, "%s", err);
            continue;
        }
        round_trip(name, &s, tmpdir);
        check_values(file, &s);
        snprintf(name, sizeof name, "reproducible good/%s %s", file, cases[i]);
        if (scene_load(path, cases[i], &again, err, sizeof err) != 0 || diff_scenes(&s, &again))
            fail(name, "%s", "a second load differs");
        else
            pass(name);
        scene_free(&again);
        scene_free(&s);
    }
    scene_free_names(cases, n);
}

static void check_good(const char *dir) {
    char good[1024], tmpdir[] = "/tmp/scene_check.XXXXXX", **names = NULL;
    snprintf(good, sizeof good, "%s/good", dir);
    if (!mkdtemp(tmpdir)) {
        fail("good scenes", "%s", "cannot create a temporary directory");
        return;
    }
    int n = list_yaml(good, &names);
    if (n < 2) fail("good scenes", "%s", "fewer than 2 files in good/");
    for (int i = 0; i < n; i++) check_good_file(dir, names[i], tmpdir);
    scene_free_names(names, n);
    rmdir(tmpdir);
}

int main(int argc, char **argv) {
    const char *dir = argc > 1 ? argv[1] : "tests/scenes";
    check_bad(dir);
    check_good(dir);
    printf("%s: %d failure%s\n", failures ? "FAIL" : "PASS", failures, failures == 1 ? "" : "s");
    return failures ? 1 : 0;
}
