/*
 * scene_emit.c — a resolved jd_scene as YAML in the scene-file schema (docs/scenes.md), written
 * with libyaml's emitter: every default explicit, no sweep and no generate, numbers with %.17g
 * so that scene_load() of the output reproduces every double bit for bit.
 *
 * The output adds one key to the documented schema: `case`, the case name, so that a resolved
 * sweep case loads back under its own name.
 */
#include <inttypes.h>
#include <limits.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <unistd.h>
#include <yaml.h>

#include "scene.h"

/* Each emitter helper returns 0 on success and 1 on failure, so calls chain with ||. */

static int emit(yaml_emitter_t *e, yaml_event_t *ev, int ok) {
    return !ok || !yaml_emitter_emit(e, ev);
}

static int scalar(yaml_emitter_t *e, const char *text, yaml_scalar_style_t style) {
    yaml_event_t ev;
    int ok = yaml_scalar_event_initialize(&ev, NULL, NULL, (yaml_char_t *)text, (int)strlen(text),
                                          1, 1, style);
    return emit(e, &ev, ok);
}

/* Strings that other YAML readers (PyYAML in scripts/) would type as numbers, booleans or null
 * are quoted; jdem itself reads any scalar as a string where a name is expected. */
static int looks_typed(const char *s) {
    static const char *const words[] = {"true", "false", "yes", "no", "on", "off", "y", "n",
                                        "null", "~", NULL};
    char *end;
    if (!*s) return 1;
    strtod(s, &end);
    if (*end == '\0') return 1;
    for (size_t i = 0; words[i]; i++)
        if (strcasecmp(s, words[i]) == 0) return 1;
    return s[0] == '.'; /* .inf, .nan */
}

static int str(yaml_emitter_t *e, const char *s) {
    return scalar(e, s, looks_typed(s) ? YAML_DOUBLE_QUOTED_SCALAR_STYLE : YAML_ANY_SCALAR_STYLE);
}

/* %.17g reproduces every double exactly.  "1e-08" gets a ".0" ("1.0e-08") because YAML 1.1
 * readers such as PyYAML only type a scalar with an exponent as a float if it has a dot. */
static int num(yaml_emitter_t *e, double v) {
    char buf[40];
    snprintf(buf, sizeof buf, "%.17g", v);
    char *exp = strchr(buf, 'e');
    if (exp && !strchr(buf, '.')) {
        memmove(exp + 2, exp, strlen(exp) + 1);
        memcpy(exp, ".0", 2);
    }
    return scalar(e, buf, YAML_PLAIN_SCALAR_STYLE);
}

static int integer(yaml_emitter_t *e, int64_t v) {
    char buf[32];
    snprintf(buf, sizeof buf, "%" PRId64, v);
    return scalar(e, buf, YAML_PLAIN_SCALAR_STYLE);
}

static int map_start(yaml_emitter_t *e, int flow) {
    yaml_event_t ev;
    int ok = yaml_mapping_start_event_initialize(
        &ev, NULL, NULL, 1, flow ? YAML_FLOW_MAPPING_STYLE : YAML_BLOCK_MAPPING_STYLE);
    return emit(e, &ev, ok);
}

static int map_end(yaml_emitter_t *e) {
    yaml_event_t ev;
    return emit(e, &ev, yaml_mapping_end_event_initialize(&ev));
}

static int seq_start(yaml_emitter_t *e, int flow) {
    yaml_event_t ev;
    int ok = yaml_sequence_start_event_initialize(
        &ev, NULL, NULL, 1, flow ? YAML_FLOW_SEQUENCE_STYLE : YAML_BLOCK_SEQUENCE_STYLE);
    return emit(e, &ev, ok);
}

static int seq_end(yaml_emitter_t *e) {
    yaml_event_t ev;
    return emit(e, &ev, yaml_sequence_end_event_initialize(&ev));
}

static int vec(yaml_emitter_t *e, const double *v, int n) {
    if (seq_start(e, 1)) return 1;
    for (int i = 0; i < n; i++)
        if (num(e, v[i])) return 1;
    return seq_end(e);
}

static int key_num(yaml_emitter_t *e, const char *key, double v) {
    return str(e, key) || num(e, v);
}
static int key_int(yaml_emitter_t *e, const char *key, int64_t v) {
    return str(e, key) || integer(e, v);
}
static int key_str(yaml_emitter_t *e, const char *key, const char *v) {
    return str(e, key) || str(e, v);
}
static int key_vec(yaml_emitter_t *e, const char *key, const double *v) {
    return str(e, key) || vec(e, v, 3);
}

/* ---------------------------------------------------------------------------------------- */

static const char *const WALL_RULES[] = {"hertz", "jiang2021"};
static const char *const DAMPING_MAPS[] = {"jiang2021", "exact_restitution"};
static const char *const XI_LIMITS[] = {"coulomb", "unconstrained"};
static const char *const TANGENTIAL_RULES[] = {"jiang2021", "mindlin"};
static const char *const NORMAL_LAWS[] = {"hertz", "mepa"};

static int emit_watchdog(yaml_emitter_t *e, const jd_watchdog_limits *w) {
    return str(e, "watchdog") || map_start(e, 0) || str(e, "enabled") ||
           scalar(e, w->enabled ? "true" : "false", YAML_PLAIN_SCALAR_STYLE) ||
           key_num(e, "max_overlap_fraction", w->max_overlap_fraction) ||
           key_num(e, "max_energy_jump", w->max_energy_jump) || map_end(e);
}

static int emit_domain(yaml_emitter_t *e, const jd_scene *s) {
    return s->has_domain && (str(e, "domain") || map_start(e, 0) ||
                             key_vec(e, "lo", s->domain_lo) || key_vec(e, "hi", s->domain_hi) ||
                             map_end(e));
}

static int emit_header(yaml_emitter_t *e, const jd_scene *s) {
    return key_int(e, "jdem_scene", 1) || key_str(e, "name", s->name) ||
           key_str(e, "case", s->case_name) || key_str(e, "description", s->description) ||
           str(e, "time") || map_start(e, 0) || key_num(e, "dt", s->dt) ||
           key_int(e, "steps", s->steps) || key_num(e, "max_impact_speed", s->max_impact_speed) ||
           key_num(e, "coordination_number", s->coordination_number) ||
           map_end(e) || str(e, "output") || map_start(e, 0) ||
           key_int(e, "every", s->output_every) ||
           key_int(e, "observables_every", s->observables_every) ||
           key_num(e, "compare_tolerance", s->compare_tolerance) || str(e, "energy") ||
           scalar(e, s->energy ? "true" : "false", YAML_PLAIN_SCALAR_STYLE) || map_end(e) ||
           key_vec(e, "gravity", s->gravity) || emit_domain(e, s) || str(e, "model") ||
           map_start(e, 0) ||
           key_str(e, "wall_rule", WALL_RULES[s->wall_rule]) ||
           key_str(e, "damping", DAMPING_MAPS[s->damping_map]) ||
           key_str(e, "tangential_limit", XI_LIMITS[s->xi_limit]) || key_num(e, "mu_r", s->mu_r) ||
           key_str(e, "tangential_stiffness", TANGENTIAL_RULES[s->tangential_rule]) ||
           key_str(e, "normal_law", NORMAL_LAWS[s->normal_law]) ||
           (s->normal_law == JD_NORMAL_MEPA && /* MEPA's options only with MEPA (scene.c) */
            (key_num(e, "mepa_exponent", s->mepa_exponent) ||
             key_num(e, "mepa_plastic_depth", s->mepa_plastic_depth))) ||
           map_end(e) || emit_watchdog(e, &s->watchdog) || str(e, "neighbour") ||
           map_start(e, 0) || key_int(e, "skin_steps", s->skin_steps) || map_end(e);
}

static int emit_material(yaml_emitter_t *e, const jd_material *m) {
    if (str(e, m->name) || map_start(e, 0)) return 1;
    if (m->has_elastic &&
        (key_num(e, "youngs_modulus", m->youngs_modulus) ||
         key_num(e, "poisson_ratio", m->poisson_ratio) || key_num(e, "density", m->density)))
        return 1;
    if (m->has_mepa && (key_num(e, "loading_stiffness", m->loading_stiffness) ||
                        key_num(e, "unloading_stiffness", m->unloading_stiffness) ||
                        key_num(e, "cohesive_stiffness", m->cohesive_stiffness)))
        return 1;
    return key_num(e, "restitution", m->restitution) || key_num(e, "friction", m->friction) ||
           key_num(e, "rolling_friction", m->rolling_friction) || map_end(e);
}

/* Every unordered pair, the like ones included (an entry may override a like pair). */
static int emit_interactions(yaml_emitter_t *e, const jd_scene *s) {
    if (str(e, "interactions") || seq_start(e, 0)) return 1;
    for (size_t a = 0; a < s->n_materials; a++)
        for (size_t b = a; b < s->n_materials; b++) {
            const jd_interaction *x = &s->interactions[a * s->n_materials + b];
            if (map_start(e, 1) || str(e, "materials") || seq_start(e, 1) ||
                str(e, s->materials[a].name) || str(e, s->materials[b].name) || seq_end(e) ||
                key_num(e, "restitution", x->restitution) ||
                key_num(e, "friction", x->friction) ||
                key_num(e, "rolling_friction", x->rolling_friction) || map_end(e))
                return 1;
        }
    return seq_end(e);
}

/* One flow mapping per particle: one line each, so large scenes stay greppable. */
static int emit_particles(yaml_emitter_t *e, const jd_scene *s) {
    if (str(e, "particles") || seq_start(e, 0)) return 1;
    for (size_t i = 0; i < s->n_particles; i++)
        if (map_start(e, 1) || key_int(e, "id", s->id[i]) ||
            key_str(e, "material", s->materials[s->material[i]].name) ||
            key_num(e, "radius", s->radius[i]) || key_vec(e, "position", &s->position[3 * i]) ||
            key_vec(e, "velocity", &s->velocity[3 * i]) ||
            key_vec(e, "angular_velocity", &s->angular_velocity[3 * i]) ||
            (s->fixed[i] && (str(e, "fixed") || scalar(e, "true", YAML_PLAIN_SCALAR_STYLE))) ||
            (s->settled[i] && (str(e, "settled") || scalar(e, "true", YAML_PLAIN_SCALAR_STYLE))) ||
            ((s->force[3 * i] != 0.0 || s->force[3 * i + 1] != 0.0 || s->force[3 * i + 2] != 0.0) &&
             key_vec(e, "force", &s->force[3 * i])) ||
            map_end(e))
            return 1;
    return seq_end(e);
}

static int emit_points(yaml_emitter_t *e, const char *key, const double (*p)[3], int n) {
    if (str(e, key) || seq_start(e, 1)) return 1;
    for (int i = 0; i < n; i++)
        if (vec(e, p[i], 3)) return 1;
    return seq_end(e);
}

/* A strength or a speed cap: INFINITY as YAML's .inf. */
static int num_or_inf(yaml_emitter_t *e, double v) {
    return isinf(v) ? scalar(e, ".inf", YAML_PLAIN_SCALAR_STYLE) : num(e, v);
}

static int emit_wall(yaml_emitter_t *e, const jd_scene *s, const jd_wall *w) {
    const int plane = w->type == JD_WALL_PLANE;
    if (map_start(e, 0) || key_str(e, "name", w->name) ||
        key_str(e, "type", plane ? "plane" : "cylinder"))
        return 1;
    if (plane ? emit_points(e, "corners", w->corners, 4)
              : emit_points(e, "axis", w->axis, 2) || key_num(e, "radius", w->radius) ||
                    key_str(e, "side", w->inside ? "inside" : "outside") ||
                    key_num(e, "angular_velocity", w->angular_velocity))
        return 1;
    if (key_str(e, "material", s->materials[w->material].name)) return 1;
    if (w->until_step != JD_WALL_ALWAYS && key_int(e, "until_step", w->until_step)) return 1;
    if (!w->has_servo) return key_vec(e, "velocity", w->velocity) || map_end(e);
    const jd_servo_spec *sp = &w->servo;
    return str(e, "servo") || map_start(e, 1) || key_num(e, "target", sp->target) ||
           key_num(e, "gain", sp->gain) || key_num(e, "tolerance", sp->tolerance) ||
           str(e, "max_speed") || num_or_inf(e, sp->max_speed) ||
           key_num(e, "hold", w->servo_hold) || map_end(e) || map_end(e);
}

/* A mesh wall: its STL file as an absolute path, so that the resolved scene reads the same file
 * from any folder. */
static int emit_mesh_wall(yaml_emitter_t *e, const jd_scene *s, const jd_mesh_wall *w) {
    char cwd[PATH_MAX], absolute[2 * PATH_MAX + 2];
    const char *file = w->file;
    if (file[0] != '/' && getcwd(cwd, sizeof cwd)) {
        snprintf(absolute, sizeof absolute, "%s/%s", cwd, w->file);
        file = absolute;
    }
    const jd_mesh_motion *m = &w->motion;
    const double still[3] = {0.0, 0.0, 0.0};
    if (map_start(e, 0) || key_str(e, "name", w->name) || key_str(e, "type", "mesh") ||
        key_str(e, "file", file) || key_num(e, "scale", w->scale) ||
        key_str(e, "material", s->materials[w->material].name) ||
        key_vec(e, "velocity", m->kind == JD_MESH_TRANSLATING ? m->velocity : still) ||
        key_vec(e, "surface_velocity", w->surface_velocity))
        return 1;
    if (m->kind == JD_MESH_ROTATING &&
        (str(e, "rotation") || map_start(e, 1) || key_vec(e, "origin", m->origin) ||
         key_vec(e, "axis", w->rotation_axis) || key_num(e, "period", w->rotation_period) ||
         map_end(e)))
        return 1;
    if (w->spinning &&
        (str(e, "surface_angular_velocity") || map_start(e, 1) || key_vec(e, "origin", w->spin_origin) ||
         key_vec(e, "axis", w->spin_axis) || key_num(e, "omega", w->spin_omega) || map_end(e)))
        return 1;
    return map_end(e);
}

static const char *const BENDINGS[] = {"potyondy_cundall", "jiang2021_literal"};

/* Bonds (docs/scenes.md "Bonds"): the types, every step-0 bond, the rules of later steps; only
 * for scenes with bond types, so scenes without bonds resolve as before. */
static int emit_bonds(yaml_emitter_t *e, const jd_scene *s) {
    if (!s->n_bond_types) return 0;
    if (str(e, "bond_types") || map_start(e, 0)) return 1;
    for (size_t i = 0; i < s->n_bond_types; i++) {
        const jd_bond_params *p = &s->bond_types[i].p;
        if (str(e, s->bond_types[i].name) || map_start(e, 1) ||
            key_num(e, "normal_stiffness", p->kn) || key_num(e, "shear_stiffness", p->kt) ||
            str(e, "tensile_strength") || num_or_inf(e, p->sigma_c) ||
            str(e, "shear_strength") || num_or_inf(e, p->tau_c) ||
            key_num(e, "radius_multiplier", p->lambda) || key_num(e, "damping", p->gamma) ||
            key_str(e, "bending", BENDINGS[p->bending]) || map_end(e))
            return 1;
    }
    if (map_end(e) || str(e, "bonds") || seq_start(e, 0)) return 1;
    for (size_t k = 0; k < s->n_bonds; k++)
        if (map_start(e, 1) || str(e, "ids") || seq_start(e, 1) ||
            integer(e, s->bond_ids[2 * k]) || integer(e, s->bond_ids[2 * k + 1]) || seq_end(e) ||
            key_str(e, "type", s->bond_types[s->bond_type[k]].name) || map_end(e))
            return 1;
    if (seq_end(e) || str(e, "bond_rules") || seq_start(e, 0)) return 1;
    for (size_t r = 0; r < s->n_bond_rules; r++) {
        const jd_bond_rule *b = &s->bond_rules[r];
        if (map_start(e, 1) || key_str(e, "type", s->bond_types[b->type].name) ||
            key_int(e, "step", b->step) || str(e, "materials") || seq_start(e, 1))
            return 1;
        for (size_t m = 0; m < s->n_materials; m++)
            if (b->materials[m] && str(e, s->materials[m].name)) return 1;
        if (seq_end(e) || str(e, "id_range") || seq_start(e, 1) || integer(e, b->id_range[0]) ||
            integer(e, b->id_range[1]) || seq_end(e) || key_num(e, "max_gap", b->max_gap) ||
            map_end(e))
            return 1;
    }
    return seq_end(e);
}

static int emit_inlet_stop(yaml_emitter_t *e, const jd_inlet *in) {
    if (str(e, "stop") || map_start(e, 1)) return 1;
    if (in->stop == JD_INLET_STOP_SECTIONS) {
        if (key_int(e, "sections", in->sections)) return 1;
    } else if (in->stop == JD_INLET_STOP_TIME) {
        if (key_num(e, "time", in->stop_time)) return 1;
    } else if (str(e, "deposit_height") || map_start(e, 1) || key_num(e, "height", in->height) ||
               key_num(e, "below_speed", in->below_speed) || key_int(e, "every", in->every) ||
               map_end(e)) {
        return 1;
    }
    return map_end(e);
}

/* An inlet section's bonds (its blocks' and explicit ones), by section index, sorted; only
 * for a section that has any. */
static int emit_section_bonds(yaml_emitter_t *e, const jd_scene *s, const jd_inlet *in) {
    if (!in->n_bonds) return 0;
    if (str(e, "bonds") || seq_start(e, 0)) return 1;
    for (size_t k = 0; k < in->n_bonds; k++) {
        char pair[2][24];
        for (int d = 0; d < 2; d++) snprintf(pair[d], sizeof pair[d], "%d", in->bond_pair[2 * k + d]);
        if (map_start(e, 1) || str(e, "pair") || seq_start(e, 1) ||
            scalar(e, pair[0], YAML_PLAIN_SCALAR_STYLE) || scalar(e, pair[1], YAML_PLAIN_SCALAR_STYLE) ||
            seq_end(e) || key_str(e, "type", s->bond_types[in->bond_type[k]].name) || map_end(e))
            return 1;
    }
    return seq_end(e);
}

/* Inlets (docs/mixing.md 2.1): the section as explicit particles, every default explicit; only
 * for scenes with inlets, so the others resolve as before. */
static int emit_inlets(yaml_emitter_t *e, const jd_scene *s) {
    if (!s->n_inlets) return 0;
    if (str(e, "inlets") || seq_start(e, 0)) return 1;
    for (size_t k = 0; k < s->n_inlets; k++) {
        const jd_inlet *in = &s->inlets[k];
        if (map_start(e, 0) || key_str(e, "name", in->name) || str(e, "section") ||
            map_start(e, 0) || str(e, "particles") || seq_start(e, 0))
            return 1;
        for (size_t p = 0; p < in->n; p++)
            if (map_start(e, 1) || key_str(e, "material", s->materials[in->material[p]].name) ||
                key_num(e, "radius", in->radius[p]) || key_vec(e, "position", &in->rel[3 * p]) ||
                (in->settled && (str(e, "settled") || scalar(e, "true", YAML_PLAIN_SCALAR_STYLE))) ||
                map_end(e))
                return 1;
        if (seq_end(e) || emit_section_bonds(e, s, in) || map_end(e) ||
            key_vec(e, "origin", in->origin) ||
            key_vec(e, "velocity", in->velocity) || str(e, "plane") || map_start(e, 1) ||
            key_vec(e, "point", in->plane_point) || key_vec(e, "normal", in->plane_normal) ||
            map_end(e) || key_num(e, "period", in->period) || key_num(e, "offset", in->offset) ||
            key_int(e, "first_id", in->first_id) || str(e, "max_insert_overlap") ||
            num_or_inf(e, in->max_insert_overlap) || emit_inlet_stop(e, in) || map_end(e))
            return 1;
    }
    return seq_end(e);
}

static int emit_scene(yaml_emitter_t *e, const jd_scene *s) {
    yaml_event_t ev;
    if (emit(e, &ev, yaml_stream_start_event_initialize(&ev, YAML_UTF8_ENCODING)) ||
        emit(e, &ev, yaml_document_start_event_initialize(&ev, NULL, NULL, NULL, 1)) ||
        map_start(e, 0) || emit_header(e, s) || str(e, "materials") || map_start(e, 0))
        return 1;
    for (size_t i = 0; i < s->n_materials; i++)
        if (emit_material(e, &s->materials[i])) return 1;
    if (map_end(e) || emit_interactions(e, s) || emit_particles(e, s) || str(e, "walls") ||
        seq_start(e, 0))
        return 1;
    for (size_t i = 0; i < s->n_walls; i++)
        if (emit_wall(e, s, &s->walls[i])) return 1;
    for (size_t i = 0; i < s->n_mesh_walls; i++)
        if (emit_mesh_wall(e, s, &s->mesh_walls[i])) return 1;
    return seq_end(e) || emit_bonds(e, s) || emit_inlets(e, s) || map_end(e) ||
           emit(e, &ev, yaml_document_end_event_initialize(&ev, 1)) ||
           emit(e, &ev, yaml_stream_end_event_initialize(&ev)) || !yaml_emitter_flush(e);
}

/* Emit with an output already attached to the emitter; 0 or -1. */
static int emit_with(yaml_emitter_t *e, const jd_scene *s) {
    yaml_emitter_set_unicode(e, 1);
    yaml_emitter_set_width(e, -1); /* no line folding: one particle per line */
    int rc = emit_scene(e, s) ? -1 : 0;
    yaml_emitter_delete(e);
    return rc;
}

int scene_emit_yaml(const jd_scene *scene, FILE *out) {
    yaml_emitter_t e;
    if (!yaml_emitter_initialize(&e)) return -1;
    yaml_emitter_set_output_file(&e, out);
    return emit_with(&e, scene);
}

typedef struct strbuf {
    char *p;
    size_t n, cap;
} strbuf;

static int append(void *data, unsigned char *buffer, size_t size) {
    strbuf *b = data;
    if (b->n + size + 1 > b->cap) {
        size_t cap = b->cap ? b->cap : 4096;
        while (cap < b->n + size + 1) cap *= 2;
        char *p = realloc(b->p, cap);
        if (!p) return 0;
        b->p = p;
        b->cap = cap;
    }
    memcpy(b->p + b->n, buffer, size);
    b->n += size;
    b->p[b->n] = '\0';
    return 1;
}

char *scene_yaml_string(const jd_scene *scene) {
    yaml_emitter_t e;
    strbuf b = {0};
    if (!yaml_emitter_initialize(&e)) return NULL;
    yaml_emitter_set_output(&e, append, &b);
    if (emit_with(&e, scene) != 0 || !b.p) {
        free(b.p);
        return NULL;
    }
    return b.p;
}
