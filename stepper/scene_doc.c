/*
 * scene_doc.c — validating access to a libyaml document tree and the sweep machinery.
 * See scene_doc.h.  Scalars are untyped strings in libyaml's document API, so the typing rules
 * live here: a number is a plain (unquoted) scalar that strtod consumes completely.
 */
#include "scene_doc.h"

#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>

#include "scene.h"

const sd_range SD_ANY = {-INFINITY, INFINITY, 1, 1};
const sd_range SD_POSITIVE = {0.0, INFINITY, 1, 1};
const sd_range SD_NONNEGATIVE = {0.0, INFINITY, 0, 1};
const sd_range SD_AT_LEAST_ONE = {1.0, INFINITY, 0, 1};

#define SD_MAX_CASES 100000

/* ---------------------------------------------------------------------------------------- */
/* Messages                                                                                  */

static size_t line_of(const yaml_node_t *n) { return n ? n->start_mark.line + 1 : 1; }

int sd_fail(sd_ctx *c, const yaml_node_t *at, const char *path, const char *fmt, ...) {
    int k;
    if (path && *path)
        k = snprintf(c->err, c->errlen, "%s:%zu: key '%s': ", c->file, line_of(at), path);
    else
        k = snprintf(c->err, c->errlen, "%s:%zu: ", c->file, line_of(at));
    if (k >= 0 && (size_t)k < c->errlen) {
        va_list ap;
        va_start(ap, fmt);
        vsnprintf(c->err + k, c->errlen - (size_t)k, fmt, ap);
        va_end(ap);
    }
    return -1;
}

int sd_no_memory(sd_ctx *c, const yaml_node_t *at, const char *path) {
    c->no_memory = 1;
    if (!at) {
        snprintf(c->err, c->errlen, "%s: out of memory reading the scene", c->file);
        return -1;
    }
    return sd_fail(c, at, path, "out of memory reading the scene");
}

const char *sd_kind(const yaml_node_t *n) {
    if (!n) return "nothing";
    if (n->type == YAML_MAPPING_NODE) return "a mapping";
    if (n->type == YAML_SEQUENCE_NODE) return "a sequence";
    if (n->data.scalar.length == 0) return "an empty value";
    if (n->data.scalar.style != YAML_PLAIN_SCALAR_STYLE) return "a quoted string";
    return "a scalar";
}

/* Append s to out[0..used), truncating at SD_PATH_MAX; memmove because callers may join a
 * path onto itself. */
static size_t path_append(char out[SD_PATH_MAX], size_t used, const char *s) {
    size_t len = strnlen(s, SD_PATH_MAX);
    if (used + len >= SD_PATH_MAX) len = SD_PATH_MAX - 1 - used;
    memmove(out + used, s, len);
    out[used + len] = '\0';
    return used + len;
}

void sd_join(char out[SD_PATH_MAX], const char *parent, const char *key) {
    size_t used = 0;
    if (parent && *parent) used = path_append(out, path_append(out, 0, parent), ".");
    path_append(out, used, key);
}

void sd_join_index(char out[SD_PATH_MAX], const char *parent, size_t index) {
    char key[32];
    snprintf(key, sizeof key, "%zu", index);
    sd_join(out, parent, key);
}

/* "a, b, c" from a NULL-terminated list. */
static void join_names(char *out, size_t size, const char *const *names) {
    size_t used = 0;
    out[0] = '\0';
    for (size_t i = 0; names[i] && used < size; i++) {
        int k = snprintf(out + used, size - used, "%s%s", i ? ", " : "", names[i]);
        if (k < 0) break;
        used += (size_t)k;
    }
}

static void range_text(sd_range r, char *out, size_t size) {
    if (isinf(r.lo) && isinf(r.hi))
        snprintf(out, size, "a finite number");
    else if (isinf(r.hi))
        snprintf(out, size, "a number %s %g", r.lo_open ? ">" : ">=", r.lo);
    else if (isinf(r.lo))
        snprintf(out, size, "a number %s %g", r.hi_open ? "<" : "<=", r.hi);
    else
        snprintf(out, size, "a number in %c%g, %g%c", r.lo_open ? '(' : '[', r.lo, r.hi,
                 r.hi_open ? ')' : ']');
}

/* ---------------------------------------------------------------------------------------- */
/* Loading                                                                                   */

static int parser_fail(sd_ctx *c, const yaml_parser_t *p) {
    /* libyaml names every input error; some of its allocation failures (e.g. a tag or anchor
     * copy in the loader) fail without setting the error at all */
    if (p->error == YAML_MEMORY_ERROR || p->error == YAML_NO_ERROR)
        return sd_no_memory(c, NULL, NULL);
    if (p->error == YAML_READER_ERROR && ferror(c->in))
        return snprintf(c->err, c->errlen, "%s: cannot read: %s", c->file, strerror(errno)), -1;
    snprintf(c->err, c->errlen, "%s:%zu: invalid YAML: %s%s%s; valid: a YAML document", c->file,
             p->problem_mark.line + 1, p->problem ? p->problem : "parse error",
             p->context ? " " : "", p->context ? p->context : "");
    return -1;
}

/* A second document in the stream is almost certainly a mistake (a stray "---"). */
static int check_single_document(sd_ctx *c, yaml_parser_t *p) {
    yaml_document_t extra;
    if (!yaml_parser_load(p, &extra)) return parser_fail(c, p);
    yaml_node_t *root = yaml_document_get_root_node(&extra);
    int rc = 0;
    if (root)
        rc = sd_fail(c, root, NULL, "more than one YAML document; valid: one scene per file");
    yaml_document_delete(&extra);
    return rc;
}

/* libyaml's scanner takes time quadratic in the nesting depth (0.5 MB of brackets: a minute),
 * and no scene nests deeper than a few levels: a pass over the event stream refuses a deeper
 * file before the tree is built, in time linear in its size. */
static int check_depth(sd_ctx *c) {
    yaml_parser_t p;
    if (!yaml_parser_initialize(&p)) return sd_no_memory(c, NULL, NULL);
    yaml_parser_set_input_file(&p, c->in);
    int depth = 0, rc = 0;
    for (yaml_event_type_t type = YAML_NO_EVENT; rc == 0 && type != YAML_STREAM_END_EVENT;) {
        yaml_event_t e;
        if (!yaml_parser_parse(&p, &e)) {
            rc = parser_fail(c, &p);
            break;
        }
        type = e.type;
        if (type == YAML_MAPPING_START_EVENT || type == YAML_SEQUENCE_START_EVENT) depth++;
        if (type == YAML_MAPPING_END_EVENT || type == YAML_SEQUENCE_END_EVENT) depth--;
        if (depth > SD_MAX_DEPTH)
            rc = sd_fail(c, &(yaml_node_t){.start_mark = e.start_mark}, NULL, "nested more than "
                         "%d levels deep; valid: at most %d nested mappings and sequences",
                         SD_MAX_DEPTH, SD_MAX_DEPTH);
        yaml_event_delete(&e);
    }
    yaml_parser_delete(&p);
    return rc;
}

/* The scene file, open for reading: a regular file (a directory or a device is refused). */
static int open_scene(sd_ctx *c, const char *file) {
    struct stat st;
    if (!(c->in = fopen(file, "rb")))
        return snprintf(c->err, c->errlen, "%s: cannot open: %s", file, strerror(errno)), -1;
    if (fstat(fileno(c->in), &st) != 0 || !S_ISREG(st.st_mode)) {
        fclose(c->in);
        c->in = NULL;
        return snprintf(c->err, c->errlen, "%s: cannot read: not a regular file; valid: a YAML "
                        "file", file), -1;
    }
    return 0;
}

int sd_load(sd_ctx *c, const char *file, yaml_document_t *doc) {
    c->file = file;
    c->doc = NULL;
    if (open_scene(c, file)) return -1;
    yaml_parser_t p;
    int ready = check_depth(c) == 0;
    if (ready && fseek(c->in, 0, SEEK_SET) != 0)
        ready = snprintf(c->err, c->errlen, "%s: cannot read: %s", file, strerror(errno)) < 0;
    if (ready && !yaml_parser_initialize(&p)) ready = sd_no_memory(c, NULL, NULL) == 0;
    if (!ready) {
        fclose(c->in);
        c->in = NULL;
        return -1;
    }
    yaml_parser_set_input_file(&p, c->in);
    int rc = -1;
    if (!yaml_parser_load(&p, doc)) {
        parser_fail(c, &p);
    } else {
        c->doc = doc;
        yaml_node_t *root = yaml_document_get_root_node(doc);
        if (!root)
            sd_fail(c, NULL, NULL, "empty file; valid: a scene mapping (jdem_scene: 1, ...)");
        else if (root->type != YAML_MAPPING_NODE)
            sd_fail(c, root, NULL, "expected a mapping at the top level, got %s; valid: a scene "
                    "mapping (jdem_scene: 1, ...)", sd_kind(root));
        else
            rc = check_single_document(c, &p);
        if (rc != 0) {
            yaml_document_delete(doc);
            c->doc = NULL;
        }
    }
    yaml_parser_delete(&p);
    fclose(c->in);
    c->in = NULL;
    return rc;
}

/* ---------------------------------------------------------------------------------------- */
/* Tree access                                                                               */

yaml_node_t *sd_node(const sd_ctx *c, int id) { return yaml_document_get_node(c->doc, id); }

const char *sd_scalar(const yaml_node_t *n) {
    return n && n->type == YAML_SCALAR_NODE ? (const char *)n->data.scalar.value : NULL;
}

yaml_node_t *sd_get(const sd_ctx *c, const yaml_node_t *map, const char *key) {
    if (!map || map->type != YAML_MAPPING_NODE) return NULL;
    for (yaml_node_pair_t *p = map->data.mapping.pairs.start; p < map->data.mapping.pairs.top;
         p++) {
        const char *k = sd_scalar(sd_node(c, p->key));
        if (k && strcmp(k, key) == 0) return sd_node(c, p->value);
    }
    return NULL;
}

size_t sd_len(const yaml_node_t *seq) {
    if (!seq || seq->type != YAML_SEQUENCE_NODE) return 0;
    return (size_t)(seq->data.sequence.items.top - seq->data.sequence.items.start);
}

yaml_node_t *sd_item(const sd_ctx *c, const yaml_node_t *seq, size_t i) {
    return sd_node(c, seq->data.sequence.items.start[i]);
}

/* ---------------------------------------------------------------------------------------- */
/* Structure                                                                                 */

int sd_mapping(sd_ctx *c, const yaml_node_t *n, const char *path, const char *valid) {
    if (n && n->type == YAML_MAPPING_NODE) return 0;
    return sd_fail(c, n, path, "expected a mapping, got %s; valid: %s", sd_kind(n), valid);
}

int sd_sequence(sd_ctx *c, const yaml_node_t *n, const char *path, const char *valid) {
    if (n && n->type == YAML_SEQUENCE_NODE) return 0;
    return sd_fail(c, n, path, "expected a sequence, got %s; valid: %s", sd_kind(n), valid);
}

static int known(const char *key, const char *const *allowed) {
    for (size_t i = 0; allowed[i]; i++)
        if (strcmp(key, allowed[i]) == 0) return 1;
    return 0;
}

int sd_keys(sd_ctx *c, const yaml_node_t *map, const char *path, const char *const *allowed) {
    char valid[512] = "a mapping of names";
    if (allowed) {
        join_names(valid, sizeof valid, allowed);
        char text[600];
        snprintf(text, sizeof text, "a mapping with keys %s", valid);
        if (sd_mapping(c, map, path, text)) return -1;
    } else if (sd_mapping(c, map, path, valid)) {
        return -1;
    }
    const yaml_node_pair_t *start = map->data.mapping.pairs.start;
    for (const yaml_node_pair_t *p = start; p < map->data.mapping.pairs.top; p++) {
        const yaml_node_t *kn = sd_node(c, p->key);
        const char *key = sd_scalar(kn);
        if (!key || !*key)
            return sd_fail(c, kn, path, "a key is %s; valid: a name", sd_kind(kn));
        char sub[SD_PATH_MAX];
        sd_join(sub, path, key);
        for (const yaml_node_pair_t *q = start; q < p; q++) {
            const yaml_node_t *qn = sd_node(c, q->key);
            if (strcmp(sd_scalar(qn), key) == 0)
                return sd_fail(c, kn, sub, "duplicate key (first at line %zu); valid: each key "
                               "once", line_of(qn));
        }
        if (allowed && !known(key, allowed))
            return sd_fail(c, kn, sub, "unknown key; valid: %s", valid);
    }
    return 0;
}

int sd_missing(sd_ctx *c, const yaml_node_t *map, const char *path, const char *key,
               const char *valid) {
    char sub[SD_PATH_MAX];
    sd_join(sub, path, key);
    return sd_fail(c, map, sub, "missing; valid: %s", valid);
}

/* ---------------------------------------------------------------------------------------- */
/* Typed values                                                                              */

/* YAML 1.1/1.2 spellings of infinity and NaN (.inf, -.Inf, .NaN, ...). */
int sd_is_inf(const yaml_node_t *n) {
    const char *s = n ? sd_scalar(n) : NULL;
    return s && (strcasecmp(s, ".inf") == 0 || strcasecmp(s, "+.inf") == 0);
}

static int yaml_nonfinite(const char *s) {
    if (*s == '+' || *s == '-') s++;
    static const char *const spell[] = {".inf", ".Inf", ".INF", ".nan", ".NaN", ".NAN", NULL};
    return known(s, spell);
}

/* The text of a plain scalar, or NULL after reporting what the node is instead. */
static const char *plain_text(sd_ctx *c, const yaml_node_t *n, const char *path,
                              const char *what, const char *valid) {
    if (!n || n->type != YAML_SCALAR_NODE || n->data.scalar.length == 0 ||
        n->data.scalar.style != YAML_PLAIN_SCALAR_STYLE) {
        sd_fail(c, n, path, "expected %s, got %s; valid: %s", what, sd_kind(n), valid);
        return NULL;
    }
    return (const char *)n->data.scalar.value;
}

static int in_range(double v, sd_range r) {
    if (r.lo_open ? !(v > r.lo) : !(v >= r.lo)) return 0;
    if (r.hi_open ? !(v < r.hi) : !(v <= r.hi)) return 0;
    return 1;
}

int sd_num(sd_ctx *c, const yaml_node_t *n, const char *path, sd_range r, double *out) {
    char valid[96];
    range_text(r, valid, sizeof valid);
    const char *s = plain_text(c, n, path, "a number", valid);
    if (!s) return -1;
    if (yaml_nonfinite(s))
        return sd_fail(c, n, path, SD_QUOTE " is not a finite number; valid: %s", s, valid);
    char *end;
    errno = 0;
    double v = strtod(s, &end);
    if (end == s || *end != '\0')
        return sd_fail(c, n, path, SD_QUOTE " is not a number; valid: %s", s, valid);
    if (!isfinite(v))
        return sd_fail(c, n, path, SD_QUOTE " is not a finite number; valid: %s", s, valid);
    if (!in_range(v, r)) return sd_fail(c, n, path, "%s is out of range; valid: %s", s, valid);
    *out = v;
    return 0;
}

int sd_int(sd_ctx *c, const yaml_node_t *n, const char *path, int64_t lo, int64_t *out) {
    char valid[64];
    snprintf(valid, sizeof valid, "an integer >= %lld", (long long)lo);
    const char *s = plain_text(c, n, path, "an integer", valid);
    if (!s) return -1;
    char *end;
    errno = 0;
    long long v = strtoll(s, &end, 10);
    if (end == s || *end != '\0' || errno == ERANGE)
        return sd_fail(c, n, path, SD_QUOTE " is not an integer; valid: %s", s, valid);
    if (v < lo) return sd_fail(c, n, path, "%s is out of range; valid: %s", s, valid);
    *out = (int64_t)v;
    return 0;
}

int sd_vec(sd_ctx *c, const yaml_node_t *n, const char *path, size_t dim, double *out) {
    if (!n || n->type != YAML_SEQUENCE_NODE || sd_len(n) != dim) {
        const char *got = sd_kind(n);
        char buf[48];
        if (n && n->type == YAML_SEQUENCE_NODE) {
            snprintf(buf, sizeof buf, "%zu items", sd_len(n));
            got = buf;
        }
        return sd_fail(c, n, path, "expected a sequence of %zu numbers, got %s; valid: %s", dim,
                       got, dim == 3 ? "[x, y, z]" : "one number per item");
    }
    for (size_t i = 0; i < dim; i++) {
        char sub[SD_PATH_MAX];
        sd_join_index(sub, path, i);
        if (sd_num(c, sd_item(c, n, i), sub, SD_ANY, &out[i])) return -1;
    }
    return 0;
}

int sd_points(sd_ctx *c, const yaml_node_t *n, const char *path, size_t count, double *out) {
    if (!n || n->type != YAML_SEQUENCE_NODE || sd_len(n) != count) {
        const char *got = sd_kind(n);
        char buf[48];
        if (n && n->type == YAML_SEQUENCE_NODE) {
            snprintf(buf, sizeof buf, "%zu items", sd_len(n));
            got = buf;
        }
        return sd_fail(c, n, path, "expected a sequence of %zu points, got %s; valid: "
                       "[[x, y, z], ...]", count, got);
    }
    for (size_t i = 0; i < count; i++) {
        char sub[SD_PATH_MAX];
        sd_join_index(sub, path, i);
        if (sd_vec(c, sd_item(c, n, i), sub, 3, &out[3 * i])) return -1;
    }
    return 0;
}

/* A name is data that ends up in file names, LIGGGHTS identifiers and HDF5 attributes: only
 * characters that no shell, deck or path gives a meaning to, and never "." or ".." (the first
 * character is not a dot).  A message quotes at most the first NAME_QUOTE characters of a
 * rejected name, and only the valid ones, so that the reason always fits and stays one line. */
#define NAME_QUOTE 32

static int name_char_ok(unsigned char ch, int first) {
    return (ch >= 'A' && ch <= 'Z') || (ch >= 'a' && ch <= 'z') || (ch >= '0' && ch <= '9') ||
           ch == '_' || (!first && (ch == '.' || ch == '+' || ch == '-'));
}

int sd_check_name(sd_ctx *c, const yaml_node_t *at, const char *path, const char *s, size_t len,
                  size_t size) {
    size_t bad = 0;
    while (bad < len && name_char_ok((unsigned char)s[bad], bad == 0)) bad++;
    const int quoted = (int)(bad < NAME_QUOTE ? bad : NAME_QUOTE);
    const char *more = bad > NAME_QUOTE ? "..." : "";
    char valid[160];
    snprintf(valid, sizeof valid, "valid: 1 to %zu characters from A-Z a-z 0-9 _ . + -, the first "
             "a letter, a digit or _", size - 1);
    if (len == 0) return sd_fail(c, at, path, "expected a name, got an empty value; %s", valid);
    if (bad < len) {
        const unsigned char ch = (unsigned char)s[bad];
        char what[24];
        if (ch > ' ' && ch < 0x7f) snprintf(what, sizeof what, "'%c'", ch);
        else snprintf(what, sizeof what, "byte 0x%02x", ch);
        return sd_fail(c, at, path, "the name '%.*s%s' has %s at character %zu, not allowed in a "
                       "name; %s", quoted, s, more, what, bad + 1, valid);
    }
    if (len >= size)
        return sd_fail(c, at, path, "the name '%.*s%s' is too long (%zu characters); %s", quoted,
                       s, more, len, valid);
    return 0;
}

int sd_name(sd_ctx *c, const yaml_node_t *n, const char *path, char *out, size_t size) {
    if (!n || n->type != YAML_SCALAR_NODE)
        return sd_fail(c, n, path, "expected a name, got %s; valid: a non-empty string",
                       sd_kind(n));
    const char *s = (const char *)n->data.scalar.value;
    if (sd_check_name(c, n, path, s, n->data.scalar.length, size)) return -1;
    memcpy(out, s, n->data.scalar.length + 1);
    return 0;
}

int sd_enum(sd_ctx *c, const yaml_node_t *n, const char *path, const char *const *names,
            int *out) {
    char valid[256];
    join_names(valid, sizeof valid, names);
    const char *s = sd_scalar(n);
    if (!s || !*s) return sd_fail(c, n, path, "expected one of the names, got %s; valid: %s",
                                  sd_kind(n), valid);
    for (int i = 0; names[i]; i++)
        if (strcmp(s, names[i]) == 0) {
            *out = i;
            return 0;
        }
    return sd_fail(c, n, path, "unknown value " SD_QUOTE "; valid: %s", s, valid);
}

int sd_opt_num(sd_ctx *c, const yaml_node_t *map, const char *path, const char *key, sd_range r,
               double *out) {
    const yaml_node_t *n = sd_get(c, map, key);
    if (!n) return 0;
    char sub[SD_PATH_MAX];
    sd_join(sub, path, key);
    return sd_num(c, n, sub, r, out);
}

int sd_opt_num_or_inf(sd_ctx *c, const yaml_node_t *map, const char *path, const char *key,
                      sd_range r, const char *what, const char *valid, double *out) {
    const yaml_node_t *n = sd_get(c, map, key);
    if (!n) return 0;
    if (sd_is_inf(n)) {
        *out = INFINITY;
        return 0;
    }
    char sub[SD_PATH_MAX];
    sd_join(sub, path, key);
    const char *s = sd_scalar(n);
    char *end = NULL;
    const double v = s ? strtod(s, &end) : NAN;
    if (!s || end == s || *end != '\0' || !isfinite(v) || !in_range(v, r))
        return sd_fail(c, n, sub, SD_QUOTE " is not %s; valid: %s", s ? s : sd_kind(n), what, valid);
    *out = v;
    return 0;
}

int sd_req_num(sd_ctx *c, const yaml_node_t *map, const char *path, const char *key, sd_range r,
               double *out) {
    if (sd_get(c, map, key)) return sd_opt_num(c, map, path, key, r, out);
    char valid[96];
    range_text(r, valid, sizeof valid);
    return sd_missing(c, map, path, key, valid);
}

int sd_opt_vec3(sd_ctx *c, const yaml_node_t *map, const char *path, const char *key,
                double out[3]) {
    const yaml_node_t *n = sd_get(c, map, key);
    if (!n) return 0;
    char sub[SD_PATH_MAX];
    sd_join(sub, path, key);
    return sd_vec(c, n, sub, 3, out);
}

int sd_req_vec3(sd_ctx *c, const yaml_node_t *map, const char *path, const char *key,
                double out[3]) {
    if (sd_get(c, map, key)) return sd_opt_vec3(c, map, path, key, out);
    return sd_missing(c, map, path, key, "[x, y, z]");
}

int sd_opt_enum(sd_ctx *c, const yaml_node_t *map, const char *path, const char *key,
                const char *const *names, int *out) {
    const yaml_node_t *n = sd_get(c, map, key);
    if (!n) return 0;
    char sub[SD_PATH_MAX];
    sd_join(sub, path, key);
    return sd_enum(c, n, sub, names, out);
}

/* ---------------------------------------------------------------------------------------- */
/* Sweep                                                                                     */

static const char *const SWEEP_AXIS_KEYS[] = {"axis", "values", NULL};
#define SWEEP_VALID "a list of {axis: NAME, values: {VALUE_NAME: {PATH: VALUE, ...}, ...}}"

/* Check one sweep axis; *count receives its number of values. */
static int check_axis(sd_ctx *c, const yaml_node_t *axis, const char *path, size_t *count) {
    if (sd_keys(c, axis, path, SWEEP_AXIS_KEYS)) return -1;
    char name[JD_NAME_MAX], sub[SD_PATH_MAX];
    sd_join(sub, path, "axis");
    const yaml_node_t *an = sd_get(c, axis, "axis");
    if (!an) return sd_missing(c, axis, path, "axis", "a name");
    if (sd_name(c, an, sub, name, sizeof name)) return -1;
    const yaml_node_t *values = sd_get(c, axis, "values");
    sd_join(sub, path, "values");
    if (!values) return sd_missing(c, axis, path, "values", "{VALUE_NAME: {PATH: VALUE}, ...}");
    if (sd_keys(c, values, sub, NULL)) return -1;
    *count = (size_t)(values->data.mapping.pairs.top - values->data.mapping.pairs.start);
    if (*count == 0) return sd_fail(c, values, sub, "no values; valid: at least one value");
    for (size_t i = 0; i < *count; i++) {
        const yaml_node_pair_t *p = &values->data.mapping.pairs.start[i];
        const yaml_node_t *vn = sd_node(c, p->key);
        if (sd_check_name(c, vn, sub, sd_scalar(vn), vn->data.scalar.length, JD_NAME_MAX))
            return -1;
        char vpath[SD_PATH_MAX];
        sd_join(vpath, sub, sd_scalar(sd_node(c, p->key)));
        if (sd_keys(c, sd_node(c, p->value), vpath, NULL)) return -1;
    }
    return 0;
}

static const yaml_node_t *axis_values(const sd_ctx *c, const yaml_node_t *sweep, size_t a) {
    return sd_get(c, sd_item(c, sweep, a), "values");
}

/* Case `index` -> value index of each axis (the last axis varies fastest). */
static void decompose(const sd_ctx *c, const yaml_node_t *sweep, size_t index, size_t *pick) {
    for (size_t a = sd_len(sweep); a-- > 0;) {
        const yaml_node_t *v = axis_values(c, sweep, a);
        size_t n = (size_t)(v->data.mapping.pairs.top - v->data.mapping.pairs.start);
        pick[a] = index % n;
        index /= n;
    }
}

static int case_name(sd_ctx *c, const yaml_node_t *sweep, const size_t *pick, char **out) {
    char name[2 * JD_NAME_MAX] = "";
    size_t used = 0;
    for (size_t a = 0; a < sd_len(sweep); a++) {
        const yaml_node_t *v = axis_values(c, sweep, a);
        const char *vn = sd_scalar(sd_node(c, v->data.mapping.pairs.start[pick[a]].key));
        int k = snprintf(name + used, sizeof name - used, "%s%s", a ? "_" : "", vn);
        if (k < 0 || (size_t)k >= sizeof name - used)
            return sd_fail(c, sweep, "sweep", "the case name '%s...' is too long; valid: at most "
                           "%zu characters", name, sizeof name - 1);
        used += (size_t)k;
    }
    *out = strdup(name);
    return *out ? 0 : sd_no_memory(c, sweep, "sweep");
}

static int compare_names(const void *a, const void *b) {
    return strcmp(*(char *const *)a, *(char *const *)b);
}

/* Names of every case; two equal names are an error.  Duplicates are found on a sorted copy
 * (O(n log n): a sweep may have up to SD_MAX_CASES cases). */
static int sweep_names(sd_ctx *c, const yaml_node_t *sweep, char **names, size_t total) {
    size_t *pick = calloc(sd_len(sweep), sizeof *pick);
    char **sorted = malloc((total ? total : 1) * sizeof *sorted);
    int rc = (pick && sorted) ? 0 : sd_no_memory(c, sweep, "sweep");
    for (size_t i = 0; i < total && rc == 0; i++) {
        decompose(c, sweep, i, pick);
        rc = case_name(c, sweep, pick, &names[i]);
        sorted[i] = names[i];
    }
    if (rc == 0) {
        qsort(sorted, total, sizeof *sorted, compare_names);
        for (size_t i = 1; i < total && rc == 0; i++)
            if (strcmp(sorted[i], sorted[i - 1]) == 0)
                rc = sd_fail(c, sweep, "sweep", "two cases are named '%s'; valid: value names "
                             "that give distinct case names", sorted[i]);
    }
    free(sorted);
    free(pick);
    return rc;
}

static int sweep_size(sd_ctx *c, const yaml_node_t *sweep, size_t *total) {
    if (sd_sequence(c, sweep, "sweep", SWEEP_VALID)) return -1;
    if (sd_len(sweep) == 0) return sd_fail(c, sweep, "sweep", "no axes; valid: " SWEEP_VALID);
    *total = 1;
    for (size_t a = 0; a < sd_len(sweep); a++) {
        char path[SD_PATH_MAX];
        size_t count = 0;
        sd_join_index(path, "sweep", a);
        if (check_axis(c, sd_item(c, sweep, a), path, &count)) return -1;
        *total *= count;
        if (*total > SD_MAX_CASES)
            return sd_fail(c, sweep, "sweep", "more than %d cases; valid: fewer values",
                           SD_MAX_CASES);
    }
    return 0;
}

int sd_cases(sd_ctx *c, const char *fallback, char ***names, int *n) {
    const yaml_node_t *sweep = sd_get(c, yaml_document_get_root_node(c->doc), "sweep");
    size_t total = 1;
    if (sweep && sweep_size(c, sweep, &total)) return -1;
    char **list = calloc(total, sizeof *list);
    if (!list) return sd_no_memory(c, sweep, "sweep");
    int rc = 0;
    if (sweep) {
        rc = sweep_names(c, sweep, list, total);
    } else if (!(list[0] = strdup(fallback))) {
        rc = sd_no_memory(c, NULL, NULL);
    }
    if (rc) {
        sd_free_names(list, (int)total);
        return -1;
    }
    *names = list;
    *n = (int)total;
    return 0;
}

void sd_free_names(char **names, int n) {
    if (!names) return;
    for (int i = 0; i < n; i++) free(names[i]);
    free(names);
}

/* Keys of a mapping as "a, b, c" (for "valid:" lists). */
static void mapping_keys(const sd_ctx *c, const yaml_node_t *map, char *out, size_t size) {
    size_t used = 0;
    out[0] = '\0';
    for (const yaml_node_pair_t *p = map->data.mapping.pairs.start;
         p < map->data.mapping.pairs.top && used < size; p++) {
        const char *k = sd_scalar(sd_node(c, p->key));
        int w = snprintf(out + used, size - used, "%s%s", used ? ", " : "", k ? k : "?");
        if (w < 0) break;
        used += (size_t)w;
    }
}

/* Index of pair `key` in a mapping, or -1. */
static long pair_index(const sd_ctx *c, const yaml_node_t *map, const char *key) {
    for (const yaml_node_pair_t *p = map->data.mapping.pairs.start;
         p < map->data.mapping.pairs.top; p++) {
        const char *k = sd_scalar(sd_node(c, p->key));
        if (k && strcmp(k, key) == 0) return (long)(p - map->data.mapping.pairs.start);
    }
    return -1;
}

/* Sequence index from a path component, or -1 when it is not a valid index. */
static long seq_index(const char *comp, const yaml_node_t *seq) {
    if (!*comp || strspn(comp, "0123456789") != strlen(comp) || strlen(comp) > 9) return -1;
    long i = strtol(comp, NULL, 10);
    return (size_t)i < sd_len(seq) ? i : -1;
}

/* One override being applied, for messages. */
typedef struct override_at {
    const yaml_node_t *key; /* the override's key node, for messages */
    const char *path;       /* the override path */
    const char *value_name; /* the sweep value applying it */
} override_at;

static int override_miss(sd_ctx *c, const override_at *o, const yaml_node_t *parent,
                         const char *comp, const char *walked) {
    char valid[256];
    if (parent->type == YAML_MAPPING_NODE) {
        mapping_keys(c, parent, valid, sizeof valid);
        return sd_fail(c, o->key, o->path, "sweep value '%s': no key '%s' in '%s'; valid: %s",
                       o->value_name, comp, walked, valid);
    }
    if (parent->type == YAML_SEQUENCE_NODE)
        return sd_fail(c, o->key, o->path, "sweep value '%s': no item '%s' in '%s'; valid: an "
                       "index from 0 to %zu", o->value_name, comp, walked,
                       sd_len(parent) ? sd_len(parent) - 1 : 0);
    return sd_fail(c, o->key, o->path, "sweep value '%s': '%s' is a value, it has no '%s'; "
                   "valid: a path through mappings and sequences", o->value_name, walked, comp);
}

/* Replace (or, as the last key of a mapping, add) component `comp` of node `parent_id`. */
static int override_set(sd_ctx *c, const override_at *o, int parent_id, const char *comp,
                        const char *walked, int value) {
    yaml_node_t *parent = sd_node(c, parent_id);
    if (parent->type == YAML_MAPPING_NODE) {
        long i = pair_index(c, parent, comp);
        if (i >= 0) {
            parent->data.mapping.pairs.start[i].value = value;
            return 0;
        }
        int key = yaml_document_add_scalar(c->doc, NULL, (yaml_char_t *)comp, (int)strlen(comp),
                                           YAML_PLAIN_SCALAR_STYLE);
        if (!key || !yaml_document_append_mapping_pair(c->doc, parent_id, key, value))
            return sd_no_memory(c, o->key, o->path);
        return 0;
    }
    long i = parent->type == YAML_SEQUENCE_NODE ? seq_index(comp, parent) : -1;
    if (i < 0) return override_miss(c, o, parent, comp, walked);
    parent->data.sequence.items.start[i] = value;
    return 0;
}

/* Child id of `comp` in node `id`, or 0 after reporting. */
static int override_child(sd_ctx *c, const override_at *o, int id, const char *comp,
                          const char *walked) {
    const yaml_node_t *n = sd_node(c, id);
    if (n->type == YAML_MAPPING_NODE) {
        long i = pair_index(c, n, comp);
        if (i >= 0) return n->data.mapping.pairs.start[i].value;
    } else if (n->type == YAML_SEQUENCE_NODE) {
        long i = seq_index(comp, n);
        if (i >= 0) return n->data.sequence.items.start[i];
    }
    override_miss(c, o, n, comp, walked);
    return 0;
}

static int apply_override(sd_ctx *c, const override_at *o, int value) {
    char buf[SD_PATH_MAX], walked[SD_PATH_MAX] = "";
    snprintf(buf, sizeof buf, "%s", o->path);
    size_t len = strlen(buf);
    if (len == 0 || buf[0] == '.' || buf[len - 1] == '.' || strstr(buf, ".."))
        return sd_fail(c, o->key, o->path, "sweep value '%s': malformed path; valid: dotted "
                       "keys and indices such as particles.0.velocity", o->value_name);
    if (strcmp(buf, "sweep") == 0 || strncmp(buf, "sweep.", 6) == 0)
        return sd_fail(c, o->key, o->path, "sweep value '%s': a sweep cannot override itself; "
                       "valid: any other path", o->value_name);
    int id = 1; /* libyaml's root node */
    char *save = NULL;
    char *comp = strtok_r(buf, ".", &save);
    for (char *next; (next = strtok_r(NULL, ".", &save)) != NULL; comp = next) {
        if (!(id = override_child(c, o, id, comp, walked[0] ? walked : "(top level)")))
            return -1;
        char tmp[SD_PATH_MAX];
        sd_join(tmp, walked, comp);
        memcpy(walked, tmp, sizeof walked);
    }
    return override_set(c, o, id, comp, walked[0] ? walked : "(top level)", value);
}

int sd_apply_case(sd_ctx *c, int index) {
    const yaml_node_t *sweep = sd_get(c, yaml_document_get_root_node(c->doc), "sweep");
    if (!sweep) return 0;
    size_t naxes = sd_len(sweep);
    size_t *pick = calloc(naxes, sizeof *pick);
    if (!pick) return sd_no_memory(c, sweep, "sweep");
    decompose(c, sweep, (size_t)index, pick);
    /* Node pointers are re-fetched by id throughout: adding a key grows the document's node
     * array, which may move it (scalar texts stay put). */
    int rc = 0;
    for (size_t a = 0; a < naxes && rc == 0; a++) {
        sweep = sd_get(c, yaml_document_get_root_node(c->doc), "sweep");
        const yaml_node_t *values = axis_values(c, sweep, a);
        const yaml_node_pair_t vp = values->data.mapping.pairs.start[pick[a]];
        const char *vname = sd_scalar(sd_node(c, vp.key));
        size_t n = (size_t)(sd_node(c, vp.value)->data.mapping.pairs.top -
                            sd_node(c, vp.value)->data.mapping.pairs.start);
        for (size_t i = 0; i < n && rc == 0; i++) {
            const yaml_node_pair_t op = sd_node(c, vp.value)->data.mapping.pairs.start[i];
            const yaml_node_t *key = sd_node(c, op.key);
            override_at o = {key, sd_scalar(key), vname};
            rc = apply_override(c, &o, op.value);
        }
    }
    free(pick);
    return rc;
}
