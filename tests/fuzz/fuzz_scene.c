/*
 * fuzz_scene.c — libFuzzer harness of the scene reader (stepper/scene*.c).  `make fuzz` builds it
 * with clang -fsanitize=fuzzer,address,undefined and runs it for FUZZ_SECONDS.
 *
 * Properties checked on every input:
 *   - the reader never crashes, leaks or hits undefined behaviour (the sanitizers);
 *   - a refused input always comes with a message (the reader's contract: first error, named);
 *   - a case that loads resolves to YAML that loads back and resolves to the same text (the
 *     `jdem resolve` contract the LIGGGHTS deck generator relies on);
 *   - every name of a loaded case (scene, case, materials, bond types, walls) is safe to put in
 *     a path or a LIGGGHTS deck: [A-Za-z0-9_.+-], the first not '.', '+' or '-'.
 *
 * The reader takes a path (it names the file in every message), so each input is written to one
 * temporary file on tmpfs, reused for the whole run: cheaper than any change to the reader.
 */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "scene.h"

/* Cases loaded per input: a sweep multiplies them, and more cases of one input add little. */
#define MAX_CASES 4

static char input_path[64], resolved_path[64];

static void make_temp(char *path, size_t size) {
    snprintf(path, size, "/dev/shm/jdem-fuzz-XXXXXX");
    int fd = mkstemp(path);
    if (fd < 0) {
        snprintf(path, size, "/tmp/jdem-fuzz-XXXXXX");
        fd = mkstemp(path);
    }
    if (fd < 0) abort();
    close(fd);
}

static void remove_temps(void) {
    unlink(input_path);
    unlink(resolved_path);
}

int LLVMFuzzerInitialize(int *argc, char ***argv) {
    (void)argc;
    (void)argv;
    make_temp(input_path, sizeof input_path);
    make_temp(resolved_path, sizeof resolved_path);
    atexit(remove_temps);
    return 0;
}

static void write_file(const char *path, const void *data, size_t size) {
    FILE *f = fopen(path, "wb");
    if (!f || fwrite(data, 1, size, f) != size || fclose(f) != 0) abort();
}

/* A loaded case must survive `jdem resolve` -> load -> resolve unchanged. */
static void check_round_trip(const jd_scene *s) {
    char *text = scene_yaml_string(s);
    if (!text) abort();
    write_file(resolved_path, text, strlen(text));
    jd_scene back;
    char err[1024];
    if (scene_load(resolved_path, NULL, &back, err, sizeof err) != 0) {
        fprintf(stderr, "resolved scene does not load back: %s\n--\n%s", err, text);
        abort();
    }
    char *again = scene_yaml_string(&back);
    if (!again || strcmp(text, again) != 0) {
        fprintf(stderr, "resolve is not a fixed point:\n--\n%s--\n%s", text, again);
        abort();
    }
    free(again);
    free(text);
    scene_free(&back);
}

static void require_safe_name(const char *what, const char *name) {
    int ok = name[0] != '\0' && !strchr(".+-", name[0]);
    for (const char *p = name; ok && *p; p++)
        ok = (*p >= 'A' && *p <= 'Z') || (*p >= 'a' && *p <= 'z') || (*p >= '0' && *p <= '9') ||
             strchr("_.+-", *p);
    if (!ok) {
        fprintf(stderr, "a loaded %s name is not safe: '%s'\n", what, name);
        abort();
    }
}

static void check_names(const jd_scene *s) {
    require_safe_name("scene", s->name);
    require_safe_name("case", s->case_name);
    for (size_t k = 0; k < s->n_materials; k++) require_safe_name("material", s->materials[k].name);
    for (size_t k = 0; k < s->n_bond_types; k++)
        require_safe_name("bond type", s->bond_types[k].name);
    for (size_t k = 0; k < s->n_walls; k++) require_safe_name("wall", s->walls[k].name);
}

static void require_message(const char *err) {
    if (err[0] == '\0') {
        fprintf(stderr, "refused without a message\n");
        abort();
    }
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
    write_file(input_path, data, size);
    char err[1024] = "";
    char **names;
    int n = scene_list_cases(input_path, &names, err, sizeof err);
    if (n < 0) {
        require_message(err);
        return 0;
    }
    for (int i = 0; i < n && i < MAX_CASES; i++) {
        jd_scene s;
        err[0] = '\0';
        if (scene_load(input_path, names[i], &s, err, sizeof err) != 0) {
            require_message(err);
            continue;
        }
        check_names(&s);
        check_round_trip(&s);
        scene_free(&s);
    }
    scene_free_names(names, n);
    return 0;
}
