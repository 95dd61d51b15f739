/*
 * scene_doc.h — internal to the scene reader (stepper/scene*.c): typed, validating access to a
 * libyaml document tree, and the sweep machinery (case names, overrides).
 *
 * Every reader reports the first problem as "FILE:LINE: key 'a.b.c': what is wrong; valid: ..."
 * into the context's error buffer and returns -1; 0 means success.  Key paths use the same dotted
 * form as sweep overrides (sequence items by 0-based index), so a message's key can be pasted
 * into a sweep.
 */
#ifndef JDEM_SCENE_DOC_H
#define JDEM_SCENE_DOC_H

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <yaml.h>

#define SD_PATH_MAX 256

/* Deepest nesting of mappings and sequences accepted in a scene file. */
#define SD_MAX_DEPTH 64

typedef struct sd_ctx {
    const char *file;
    FILE *in;            /* the scene file while sd_load reads it */
    yaml_document_t *doc;
    char *err;
    size_t errlen;
    int no_memory;       /* the error in err is "out of memory" (not the scene's fault) */
} sd_ctx;

/* Allowed interval of a number; the "valid:" text of messages is derived from it. */
typedef struct sd_range {
    double lo, hi;       /* -INFINITY / INFINITY: unbounded */
    int lo_open, hi_open;
} sd_range;

extern const sd_range SD_ANY, SD_POSITIVE, SD_NONNEGATIVE, SD_AT_LEAST_ONE;

/* Errors.  A message quotes a scalar of the file as SD_QUOTE (its first 64 characters), so that
 * what is wrong and what would be valid always fit after it. */
#define SD_QUOTE "'%.64s'"

int sd_fail(sd_ctx *c, const yaml_node_t *at, const char *path, const char *fmt, ...)
    __attribute__((format(printf, 4, 5)));
int sd_no_memory(sd_ctx *c, const yaml_node_t *at, const char *path); /* sets no_memory */
const char *sd_kind(const yaml_node_t *n); /* "a mapping", "a sequence", ... for messages */
void sd_join(char out[SD_PATH_MAX], const char *parent, const char *key);
void sd_join_index(char out[SD_PATH_MAX], const char *parent, size_t index);

/* Loading: the first document of FILE (a second one is an error); the root must be a mapping,
 * the file a regular file nested at most SD_MAX_DEPTH levels. */
int sd_load(sd_ctx *c, const char *file, yaml_document_t *doc);

/* Tree access. */
yaml_node_t *sd_node(const sd_ctx *c, int id);
yaml_node_t *sd_get(const sd_ctx *c, const yaml_node_t *map, const char *key);
size_t sd_len(const yaml_node_t *seq);
yaml_node_t *sd_item(const sd_ctx *c, const yaml_node_t *seq, size_t i);
const char *sd_scalar(const yaml_node_t *n); /* NULL unless a scalar */
int sd_is_inf(const yaml_node_t *n);         /* 1 for the scalar .inf or +.inf (any case) */

/* Structure checks.  sd_keys: `map` must be a mapping whose keys are distinct scalars from the
 * NULL-terminated `allowed` list. */
int sd_mapping(sd_ctx *c, const yaml_node_t *n, const char *path, const char *valid);
int sd_sequence(sd_ctx *c, const yaml_node_t *n, const char *path, const char *valid);
int sd_keys(sd_ctx *c, const yaml_node_t *map, const char *path, const char *const *allowed);
int sd_missing(sd_ctx *c, const yaml_node_t *map, const char *path, const char *key,
               const char *valid);

/* Typed values of a node. */
int sd_num(sd_ctx *c, const yaml_node_t *n, const char *path, sd_range r, double *out);
int sd_int(sd_ctx *c, const yaml_node_t *n, const char *path, int64_t lo, int64_t *out);
int sd_vec(sd_ctx *c, const yaml_node_t *n, const char *path, size_t dim, double *out);
int sd_points(sd_ctx *c, const yaml_node_t *n, const char *path, size_t count, double *out);
/* Names (scene, case, material, bond type, wall, sweep axis and value): 1 to size - 1
 * characters from [A-Za-z0-9_.+-], the first from [A-Za-z0-9_].  sd_check_name checks LEN bytes
 * at S (reported at node AT); sd_name checks a scalar node and copies it into out[size]. */
int sd_check_name(sd_ctx *c, const yaml_node_t *at, const char *path, const char *s, size_t len,
                  size_t size);
int sd_name(sd_ctx *c, const yaml_node_t *n, const char *path, char *out, size_t size);
int sd_enum(sd_ctx *c, const yaml_node_t *n, const char *path, const char *const *names,
            int *out);

/* Optional / required members of a mapping: absent optional members keep *out. */
int sd_opt_num(sd_ctx *c, const yaml_node_t *map, const char *path, const char *key, sd_range r,
               double *out);
/* An optional number in r, or .inf (INFINITY); a failure says "'<text>' is not <what>; valid:
 * <valid>". */
int sd_opt_num_or_inf(sd_ctx *c, const yaml_node_t *map, const char *path, const char *key,
                      sd_range r, const char *what, const char *valid, double *out);
int sd_req_num(sd_ctx *c, const yaml_node_t *map, const char *path, const char *key, sd_range r,
               double *out);
int sd_opt_vec3(sd_ctx *c, const yaml_node_t *map, const char *path, const char *key,
                double out[3]);
int sd_req_vec3(sd_ctx *c, const yaml_node_t *map, const char *path, const char *key,
                double out[3]);
int sd_opt_enum(sd_ctx *c, const yaml_node_t *map, const char *path, const char *key,
                const char *const *names, int *out);

/* Sweep.  sd_cases: validate the root's `sweep` and list its case names (malloc'ed; one case
 * named `fallback` without sweep); the last axis varies fastest.  sd_apply_case: apply the
 * overrides of case number `index` of that list to the tree. */
int sd_cases(sd_ctx *c, const char *fallback, char ***names, int *n);
int sd_apply_case(sd_ctx *c, int index);
void sd_free_names(char **names, int n);

#endif /* JDEM_SCENE_DOC_H */
