/* jdem_inlet.c — the conveyor inlet's stream (jdem_inlet.h has the definitions it implements). */
#include "jdem_inlet.h"

#include <math.h>
#include <stdio.h>

static double dot3(const double a[3], const double b[3]) {
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static double norm3(const double a[3]) {
    return sqrt(dot3(a, a));
}

/* The belt direction u = v/|v|. */
static void belt_direction(const jd_inlet_spec *s, double u[3]) {
    const double speed = norm3(s->velocity);
    for (int i = 0; i < 3; i++)
        u[i] = s->velocity[i] / speed;
}

/* (offset + c L): how far copy c is set back along u [m]. */
static double setback(const jd_inlet_spec *s, int64_t copy) {
    return s->offset + (double)copy * s->period;
}

double jd_inlet_signed_distance(const jd_inlet_spec *s, int64_t copy, size_t p, int64_t step) {
    double u[3], q[3];
    belt_direction(s, u);
    for (int i = 0; i < 3; i++)
        q[i] = s->origin[i] + s->rel[3 * p + i] - s->plane_point[i];
    const double a = dot3(s->plane_normal, q) - setback(s, copy) * dot3(s->plane_normal, u);
    const double w = dot3(s->plane_normal, s->velocity) * s->dt;
    return a + (double)step * w;
}

int64_t jd_inlet_crossing_step(const jd_inlet_spec *s, int64_t copy, size_t p) {
    const double a = jd_inlet_signed_distance(s, copy, p, 0);
    if (a >= 0.0)
        return 0;
    const double w = dot3(s->plane_normal, s->velocity) * s->dt;
    const double estimate = ceil(-a / w);
    if (!(estimate < 9.0e18)) /* beyond any run (and int64) */
        return JD_INLET_NEVER;
    int64_t k = (int64_t)estimate;
    while (k > 0 && jd_inlet_signed_distance(s, copy, p, k - 1) >= 0.0)
        k--;
    while (jd_inlet_signed_distance(s, copy, p, k) < 0.0)
        k++;
    return k;
}

int64_t jd_inlet_section_start(const jd_inlet_spec *s, int64_t copy) {
    int64_t first = JD_INLET_NEVER;
    for (size_t p = 0; p < s->n; p++) {
        const int64_t k = jd_inlet_crossing_step(s, copy, p);
        if (k < first)
            first = k;
    }
    return first;
}

void jd_inlet_particle_at_step(const jd_inlet_spec *s, int64_t copy, size_t p, int64_t step,
                               jd_inlet_particle *out) {
    double u[3];
    belt_direction(s, u);
    out->id = s->first_id + copy * (int64_t)s->n + (int64_t)p;
    out->copy = copy;
    out->index = p;
    out->step = step;
    const double t = (double)step * s->dt;
    const double back = setback(s, copy);
    for (int i = 0; i < 3; i++) {
        const double b = (s->origin[i] + s->rel[3 * p + i]) - back * u[i];
        out->position[i] = b + s->velocity[i] * t;
        out->velocity[i] = s->velocity[i];
    }
    out->radius = s->radius[p];
    out->species = s->species[p];
}

void jd_inlet_particle_at_crossing(const jd_inlet_spec *s, int64_t copy, size_t p,
                                   jd_inlet_particle *out) {
    jd_inlet_particle_at_step(s, copy, p, jd_inlet_crossing_step(s, copy, p), out);
}

int64_t jd_inlet_group_start(const jd_inlet_spec *s, int64_t copy, const size_t *members,
                             size_t n_members) {
    int64_t first = JD_INLET_NEVER;
    for (size_t m = 0; m < n_members; m++) {
        const int64_t k = jd_inlet_crossing_step(s, copy, members[m]);
        if (k < first)
            first = k;
    }
    return first;
}

/* The root of x's component; path halving.  Every union makes the smaller root the parent, so a
 * component's root is its smallest member. */
static int32_t component_root(int32_t *parent, int32_t x) {
    while (parent[x] != x) {
        parent[x] = parent[parent[x]];
        x = parent[x];
    }
    return x;
}

/* Bond a before bond b in the (smaller, larger) order. */
static int bond_before(const int32_t *pair, size_t a, size_t b) {
    return pair[2 * a] != pair[2 * b] ? pair[2 * a] < pair[2 * b] : pair[2 * a + 1] < pair[2 * b + 1];
}

static void swap_bonds(int32_t *pair, int32_t *type, size_t a, size_t b) {
    const int32_t i = pair[2 * a], j = pair[2 * a + 1], t = type[a];
    pair[2 * a] = pair[2 * b];
    pair[2 * a + 1] = pair[2 * b + 1];
    type[a] = type[b];
    pair[2 * b] = i;
    pair[2 * b + 1] = j;
    type[b] = t;
}

/* Restore the max-heap below node `root` of the first n bonds. */
static void sift_down(int32_t *pair, int32_t *type, size_t root, size_t n) {
    for (size_t child; (child = 2 * root + 1) < n; root = child) {
        if (child + 1 < n && bond_before(pair, child, child + 1)) child++;
        if (!bond_before(pair, root, child)) return;
        swap_bonds(pair, type, root, child);
    }
}

size_t jd_inlet_sort_bonds(size_t n_bonds, int32_t *pair, int32_t *type) {
    for (size_t k = 0; k < n_bonds; k++)
        if (pair[2 * k] > pair[2 * k + 1]) {
            const int32_t i = pair[2 * k];
            pair[2 * k] = pair[2 * k + 1];
            pair[2 * k + 1] = i;
        }
    for (size_t k = n_bonds / 2; k-- > 0;) sift_down(pair, type, k, n_bonds);
    for (size_t end = n_bonds; end > 1; end--) {
        swap_bonds(pair, type, 0, end - 1);
        sift_down(pair, type, 0, end - 1);
    }
    for (size_t k = 1; k < n_bonds; k++)
        if (pair[2 * k] == pair[2 * k - 2] && pair[2 * k + 1] == pair[2 * k - 1]) return k;
    return n_bonds;
}

size_t jd_inlet_groups(size_t n, size_t n_bonds, const int32_t *pair, int32_t *parent,
                       int32_t *group_of, size_t *group_first, size_t *group_member) {
    for (size_t p = 0; p < n; p++) {
        parent[p] = (int32_t)p;
        group_of[p] = -1;
    }
    for (size_t k = 0; k < n_bonds; k++) {
        const int32_t x = component_root(parent, pair[2 * k]), y = component_root(parent, pair[2 * k + 1]);
        if (x != y) parent[x < y ? y : x] = x < y ? x : y;
        group_of[pair[2 * k]] = group_of[pair[2 * k + 1]] = -2; /* bonded, not numbered yet */
    }
    /* the root is the smallest member, so it is numbered before the rest of its group */
    size_t groups = 0;
    for (size_t p = 0; p < n; p++) {
        if (group_of[p] == -1) continue;
        const int32_t r = component_root(parent, (int32_t)p);
        group_of[p] = r == (int32_t)p ? (int32_t)groups++ : group_of[r];
    }
    /* counting sort by group: group_first[g] serves as g's cursor, then shifts to its start */
    for (size_t g = 0; g <= groups; g++) group_first[g] = 0;
    for (size_t p = 0; p < n; p++)
        if (group_of[p] >= 0) group_first[group_of[p] + 1]++;
    for (size_t g = 0; g < groups; g++) group_first[g + 1] += group_first[g];
    for (size_t p = 0; p < n; p++)
        if (group_of[p] >= 0) group_member[group_first[group_of[p]]++] = p;
    for (size_t g = groups; g > 0; g--) group_first[g] = group_first[g - 1];
    group_first[0] = 0;
    return groups;
}

double jd_inlet_bond_omega2(const jd_inlet_spec *s, const double *mass, size_t n_bonds,
                            const int32_t *pair, const int32_t *type,
                            const jd_bond_params *const *params, double *work) {
    for (size_t p = 0; p < s->n; p++) work[p] = 0.0;
    for (size_t k = 0; k < n_bonds; k++) {
        const int32_t i = pair[2 * k], j = pair[2 * k + 1];
        double dx[3];
        for (int d = 0; d < 3; d++) dx[d] = s->rel[3 * j + d] - s->rel[3 * i + d];
        const double wk = jd_bond_omega2_pair(params[type[k]], s->radius[i], s->radius[j], mass[i],
                                              mass[j], sqrt(jd_dot(dx, dx)));
        work[i] += wk;
        work[j] += wk;
    }
    double wmax2 = 0.0;
    for (size_t p = 0; p < s->n; p++) wmax2 = work[p] > wmax2 ? work[p] : wmax2;
    return wmax2;
}

void jd_inlet_bond_ids(const jd_inlet_spec *s, int64_t copy, size_t i, size_t j, int64_t ids[2]) {
    const int64_t base = s->first_id + copy * (int64_t)s->n;
    const size_t lo = i < j ? i : j, hi = i < j ? j : i;
    ids[0] = base + (int64_t)lo;
    ids[1] = base + (int64_t)hi;
}

int64_t jd_inlet_insertion_step(const jd_inlet_spec *s, int64_t copy, size_t p) {
    const int32_t g = s->n_groups ? s->group_of[p] : -1;
    if (g < 0)
        return jd_inlet_crossing_step(s, copy, p);
    const size_t first = s->group_first[g];
    return jd_inlet_group_start(s, copy, &s->group_member[first], s->group_first[g + 1] - first);
}

int64_t jd_inlet_copies_by(const jd_inlet_spec *s, int64_t stop_step, int64_t last) {
    const int64_t lim = stop_step == JD_INLET_NO_STOP ? last
                                                     : (stop_step - 1 < last ? stop_step - 1 : last);
    if (jd_inlet_section_start(s, 0) > lim) return 0;
    int64_t lo = 1, hi = 1; /* copies [0, lo) start by lim; find hi that does not */
    while ((s->max_sections == 0 || hi < s->max_sections) && jd_inlet_section_start(s, hi) <= lim) {
        lo = hi + 1;
        hi *= 2;
        if (s->max_sections && hi > s->max_sections) hi = s->max_sections;
    }
    if (s->max_sections && hi >= s->max_sections &&
        jd_inlet_section_start(s, s->max_sections - 1) <= lim)
        return s->max_sections;
    while (lo < hi) { /* copy lo - 1 starts by lim, copy hi does not */
        const int64_t mid = lo + (hi - lo) / 2;
        if (jd_inlet_section_start(s, mid) <= lim) lo = mid + 1; else hi = mid;
    }
    return lo;
}

double jd_inlet_pending_particle_steps(const jd_inlet_spec *s, const jd_inlet_cursor *cursor,
                                       int64_t copies, int64_t last) {
    double sum = 0.0;
    for (size_t p = 0; p < s->n; p++) {
        const int64_t c0 = cursor[p].copy;
        double m = (double)(copies - c0);
        if (m <= 0.0 || cursor[p].step == JD_INLET_NEVER) continue;
        const double k0 = (double)jd_inlet_insertion_step(s, c0, p);
        double k1 = (double)jd_inlet_insertion_step(s, copies - 1, p);
        if (k0 > (double)last) continue;
        if (k1 > (double)last) { /* the copies inserted after `last` are cut off */
            const double spacing = m > 1.0 ? (k1 - k0) / (m - 1.0) : 1.0;
            m = floor(((double)last - k0) / spacing) + 1.0;
            k1 = k0 + (m - 1.0) * spacing;
        }
        sum += m * ((double)last - 0.5 * (k0 + k1));
    }
    return sum;
}

/* ---------------------------------------------------------------------------------------- */
/* Checks                                                                                   */
/* ---------------------------------------------------------------------------------------- */

static int finite3(const double a[3]) {
    return isfinite(a[0]) && isfinite(a[1]) && isfinite(a[2]);
}

/* Overlap of particle p (copy 0) with particle q of the copy `shift` periods behind [m]. */
static double overlap(const jd_inlet_spec *s, const double u[3], size_t p, size_t q, int64_t shift) {
    double d[3];
    for (int i = 0; i < 3; i++)
        d[i] = s->rel[3 * p + i] - (s->rel[3 * q + i] - (double)shift * s->period * u[i]);
    return s->radius[p] + s->radius[q] - norm3(d);
}

static int too_much(double ov, double ra, double rb, double tol) {
    return ov > tol * (ra < rb ? ra : rb);
}

static jd_inlet_status check_values(const jd_inlet_spec *s, int allow_unbounded, char *msg,
                                    size_t len) {
    if (s->n == 0 || !s->rel || !s->radius || !s->species) {
        snprintf(msg, len, "the section has no particles; valid: at least one particle");
        return JD_INLET_EMPTY;
    }
    for (size_t p = 0; p < s->n; p++) {
        if (!(s->radius[p] > 0.0) || !isfinite(s->radius[p])) {
            snprintf(msg, len, "section particle %zu: radius %g is not valid; valid: a number > 0",
                     p, s->radius[p]);
            return JD_INLET_BAD_VALUE;
        }
        if (!finite3(&s->rel[3 * p])) {
            snprintf(msg, len, "section particle %zu: position is not finite", p);
            return JD_INLET_BAD_VALUE;
        }
    }
    if (!(s->dt > 0.0) || !isfinite(s->dt)) {
        snprintf(msg, len, "dt %g is not valid; valid: a number > 0", s->dt);
        return JD_INLET_BAD_VALUE;
    }
    if (s->max_sections != 1 && (!(s->period > 0.0) || !isfinite(s->period))) {
        snprintf(msg, len, "period %g is not valid; valid: a number > 0", s->period);
        return JD_INLET_BAD_VALUE;
    }
    if (!(s->overlap_tol >= 0.0) || !isfinite(s->overlap_tol)) {
        snprintf(msg, len, "overlap tolerance %g is not valid; valid: a number >= 0",
                 s->overlap_tol);
        return JD_INLET_BAD_VALUE;
    }
    if (!(s->max_insert_overlap >= 0.0)) {
        snprintf(msg, len, "max_insert_overlap %g is not valid; valid: a number >= 0 (a fraction "
                           "of the smaller radius) or inf",
                 s->max_insert_overlap);
        return JD_INLET_BAD_VALUE;
    }
    if (!(s->offset >= 0.0) || !isfinite(s->offset)) {
        snprintf(msg, len, "offset %g is not valid; valid: a number >= 0", s->offset);
        return JD_INLET_BAD_VALUE;
    }
    if (s->first_id <= 0 || s->max_sections < 0 || s->stop_step <= 0) {
        snprintf(msg, len,
                 "first id %lld, sections %lld or stop step %lld is not valid; valid: an id > 0, "
                 "sections >= 1 (0: no limit), a stop step > 0",
                 (long long)s->first_id, (long long)s->max_sections, (long long)s->stop_step);
        return JD_INLET_BAD_VALUE;
    }
    if (!allow_unbounded && s->max_sections == 0 && s->stop_step == JD_INLET_NO_STOP) {
        snprintf(msg, len, "the stream never stops; valid: a number of sections, a deposit "
                           "height or a time");
        return JD_INLET_NO_STOP_RULE;
    }
    if (!finite3(s->origin) || !finite3(s->velocity) || !finite3(s->plane_point) ||
        !finite3(s->plane_normal) || !(norm3(s->velocity) > 0.0)) {
        snprintf(msg, len, "belt velocity [%g, %g, %g] is not valid; valid: a finite non-zero "
                           "vector (and finite origin and plane)",
                 s->velocity[0], s->velocity[1], s->velocity[2]);
        return JD_INLET_BAD_VALUE;
    }
    if (!(norm3(s->plane_normal) > 0.0)) {
        snprintf(msg, len, "plane normal has zero length; valid: a non-zero vector towards the domain");
        return JD_INLET_NO_NORMAL;
    }
    return JD_INLET_OK;
}

/* Every group non-empty, its members valid indices listed in increasing order and marked with
 * it in group_of; every particle marked with a group is one of its members. */
static jd_inlet_status check_groups(const jd_inlet_spec *s, char *msg, size_t len) {
    if (!s->n_groups)
        return JD_INLET_OK;
    if (!s->group_first || !s->group_member || !s->group_of) {
        snprintf(msg, len, "%zu bonded groups without their member arrays", s->n_groups);
        return JD_INLET_BAD_GROUP;
    }
    size_t listed = 0;
    for (size_t g = 0; g < s->n_groups; g++) {
        if (s->group_first[g + 1] <= s->group_first[g]) {
            snprintf(msg, len, "bonded group %zu has no members; valid: at least one", g);
            return JD_INLET_BAD_GROUP;
        }
        for (size_t m = s->group_first[g]; m < s->group_first[g + 1]; m++) {
            const size_t p = s->group_member[m];
            if (p >= s->n || s->group_of[p] != (int32_t)g ||
                (m > s->group_first[g] && p <= s->group_member[m - 1])) {
                snprintf(msg, len, "bonded group %zu: member %zu is not a section particle of "
                                   "that group listed in increasing order", g, p);
                return JD_INLET_BAD_GROUP;
            }
            listed++;
        }
    }
    size_t marked = 0;
    for (size_t p = 0; p < s->n; p++)
        marked += s->group_of[p] >= 0;
    if (marked != listed) {
        snprintf(msg, len, "%zu section particles are marked with a bonded group, %zu listed as "
                           "members; valid: the same particles", marked, listed);
        return JD_INLET_BAD_GROUP;
    }
    return JD_INLET_OK;
}

static jd_inlet_status check_geometry(const jd_inlet_spec *s, char *msg, size_t len) {
    const double vn = dot3(s->plane_normal, s->velocity);
    if (!(vn > 0.0)) {
        snprintf(msg, len,
                 "the belt never crosses the inlet plane: velocity . normal = %g <= 0; valid: a "
                 "velocity with a positive component along the normal (towards the domain)",
                 vn);
        return JD_INLET_NEVER_CROSSES;
    }
    for (size_t p = 0; p < s->n; p++) {
        const double d = jd_inlet_signed_distance(s, 0, p, 0);
        if (d >= 0.0) {
            snprintf(msg, len,
                     "section particle %zu is already past the inlet plane at step 0 (signed "
                     "distance %g >= 0); valid: a section behind the plane (move the origin back "
                     "against the belt, or raise the offset)",
                     p, d);
            return JD_INLET_ALREADY_INSIDE;
        }
    }
    return JD_INLET_OK;
}

/* Copies up to `shift` periods apart can touch when shift L is below the section's extent
 * along u plus the largest diameter. */
static int64_t shifts_to_check(const jd_inlet_spec *s, const double u[3]) {
    if (s->max_sections == 1)
        return 0;
    double lo = INFINITY, hi = -INFINITY, rmax = 0.0;
    for (size_t p = 0; p < s->n; p++) {
        const double a = dot3(&s->rel[3 * p], u);
        lo = a < lo ? a : lo;
        hi = a > hi ? a : hi;
        rmax = s->radius[p] > rmax ? s->radius[p] : rmax;
    }
    int64_t k = (int64_t)floor((hi - lo + 2.0 * rmax) / s->period);
    if (k < 1)
        k = 1;
    if (s->max_sections > 1 && k > s->max_sections - 1)
        k = s->max_sections - 1;
    return k;
}

static jd_inlet_status check_overlaps(const jd_inlet_spec *s, char *msg, size_t len) {
    double u[3];
    belt_direction(s, u);
    const int64_t kmax = shifts_to_check(s, u);
    for (int64_t k = 0; k <= kmax; k++)
        for (size_t p = 0; p < s->n; p++)
            for (size_t q = k == 0 ? p + 1 : 0; q < s->n; q++) {
                const double ov = overlap(s, u, p, q, k);
                if (!too_much(ov, s->radius[p], s->radius[q], s->overlap_tol))
                    continue;
                if (k == 0) {
                    snprintf(msg, len, "section particles %zu and %zu overlap by %g m; valid: "
                                       "spheres that do not overlap",
                             p, q, ov);
                    return JD_INLET_OVERLAP;
                }
                snprintf(msg, len,
                         "the section overlaps itself across the period: particle %zu overlaps "
                         "particle %zu of the copy %lld period(s) behind by %g m (period %g m); "
                         "valid: a longer period",
                         p, q, (long long)k, ov, s->period);
                return JD_INLET_PERIOD_OVERLAP;
            }
    return JD_INLET_OK;
}

jd_inlet_status jd_inlet_check(const jd_inlet_spec *s, int allow_unbounded, char *msg,
                               size_t msglen) {
    jd_inlet_status st = check_values(s, allow_unbounded, msg, msglen);
    if (st == JD_INLET_OK)
        st = check_groups(s, msg, msglen);
    if (st == JD_INLET_OK)
        st = check_geometry(s, msg, msglen);
    if (st == JD_INLET_OK)
        st = check_overlaps(s, msg, msglen);
    if (st == JD_INLET_OK && msglen > 0)
        msg[0] = '\0';
    return st;
}

/* ---------------------------------------------------------------------------------------- */
/* The stream during a run                                                                  */
/* ---------------------------------------------------------------------------------------- */

/* Point cursor p at copy c (or at the end of its stream past max_sections). */
static void aim(const jd_inlet_spec *s, jd_inlet_cursor *cur, int64_t copy, size_t p) {
    cur->copy = copy;
    cur->step = s->max_sections > 0 && copy >= s->max_sections ? JD_INLET_NEVER
                                                                : jd_inlet_insertion_step(s, copy, p);
}

static void update_next(const jd_inlet_spec *s, jd_inlet_stream *st) {
    int64_t next = JD_INLET_NEVER;
    for (size_t p = 0; p < s->n; p++)
        if (st->cursor[p].step < next)
            next = st->cursor[p].step;
    st->next_step = next;
}

void jd_inlet_stream_init(const jd_inlet_spec *s, jd_inlet_stream *st, jd_inlet_cursor *cursor) {
    st->cursor = cursor;
    st->started = 0;
    st->stop_step = s->stop_step;
    st->inserted = 0;
    st->skipped = 0;
    for (size_t p = 0; p < s->n; p++)
        aim(s, &cursor[p], 0, p);
    update_next(s, st);
}

/* The smallest copy due at `step`, or -1. */
static int64_t first_copy_due(const jd_inlet_spec *s, const jd_inlet_stream *st, int64_t step) {
    int64_t c = -1;
    for (size_t p = 0; p < s->n; p++)
        if (st->cursor[p].step == step && (c < 0 || st->cursor[p].copy < c))
            c = st->cursor[p].copy;
    return c;
}

size_t jd_inlet_pop(const jd_inlet_spec *s, jd_inlet_stream *st, int64_t step,
                    jd_inlet_particle *out, size_t cap) {
    size_t count = 0;
    if (step != st->next_step)
        return 0;
    for (int64_t c = first_copy_due(s, st, step); c >= 0; c = first_copy_due(s, st, step)) {
        for (size_t p = 0; p < s->n; p++) {
            jd_inlet_cursor *cur = &st->cursor[p];
            if (cur->step != step || cur->copy != c)
                continue;
            /* a copy is admitted at its start step, the first step one of its particles is due */
            if (c == st->started && step < st->stop_step)
                st->started++;
            if (c >= st->started) {
                cur->step = JD_INLET_NEVER;
                continue;
            }
            if (count == cap) {
                update_next(s, st);
                return count;
            }
            jd_inlet_particle_at_step(s, c, p, step, &out[count++]);
            st->inserted++;
            aim(s, cur, c + 1, p);
        }
    }
    update_next(s, st);
    return count;
}

/* ---------------------------------------------------------------------------------------- */
/* Insertion into an occupied place                                                          */
/* ---------------------------------------------------------------------------------------- */

double jd_inlet_overlap_fraction(const double a[3], double ra, const double b[3], double rb) {
    const double d[3] = {a[0] - b[0], a[1] - b[1], a[2] - b[2]};
    const double dist = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    return (ra + rb - dist) / (ra < rb ? ra : rb);
}

void jd_inlet_worst_overlaps(const jd_inlet_particle *due, size_t n_due, size_t n, const double *x,
                             const double *radius, double *worst, size_t *with) {
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (size_t q = 0; q < n_due; q++) {
        worst[q] = -INFINITY;
        with[q] = SIZE_MAX;
        for (int d = 0; d < 3; d++) {
            lo[d] = fmin(lo[d], due[q].position[d] - due[q].radius);
            hi[d] = fmax(hi[d], due[q].position[d] + due[q].radius);
        }
    }
    for (size_t i = 0; i < n; i++) {
        const double *xi = &x[3 * i];
        const double r = radius[i];
        if (xi[0] + r < lo[0] || xi[0] - r > hi[0] || xi[1] + r < lo[1] || xi[1] - r > hi[1] ||
            xi[2] + r < lo[2] || xi[2] - r > hi[2])
            continue;
        for (size_t q = 0; q < n_due; q++) {
            const double f = jd_inlet_overlap_fraction(due[q].position, due[q].radius, xi, r);
            if (f > worst[q]) {
                worst[q] = f;
                with[q] = i;
            }
        }
    }
}

size_t jd_inlet_skip_groups(const jd_inlet_spec *s, const jd_inlet_particle *due, size_t n_due,
                            const double *worst, unsigned char *skip) {
    for (size_t q = 0; q < n_due; q++)
        skip[q] = worst[q] > s->max_insert_overlap;
    for (size_t q = 0; q < n_due; q++) {
        const int32_t g = s->n_groups ? s->group_of[due[q].index] : -1;
        if (!skip[q] || g < 0)
            continue;
        for (size_t r = 0; r < n_due; r++)
            if (due[r].copy == due[q].copy && s->group_of[due[r].index] == g)
                skip[r] = 1;
    }
    size_t count = 0;
    for (size_t q = 0; q < n_due; q++)
        count += skip[q];
    return count;
}

int jd_inlet_skip_reason(char *buf, size_t len, double worst, int64_t with_id,
                         double max_insert_overlap, int64_t nth) {
    const char *rest = nth == JD_INLET_REPORTED ? "; further skips are counted, not reported" : "";
    if (worst > max_insert_overlap)
        return snprintf(buf, len, "particle id %lld overlaps its place by %.6g of the smaller "
                        "radius (max_insert_overlap %g)%s", (long long)with_id, worst,
                        max_insert_overlap, rest);
    return snprintf(buf, len, "with its bonded block (max_insert_overlap %g)%s",
                    max_insert_overlap, rest);
}

void jd_inlet_book_skipped(jd_inlet_stream *st, size_t n_skipped) {
    st->inserted -= (int64_t)n_skipped;
    st->skipped += (int64_t)n_skipped;
}

/* ---------------------------------------------------------------------------------------- */
/* Stop rules and the record                                                                */
/* ---------------------------------------------------------------------------------------- */

int64_t jd_inlet_stop_step_of_time(double time, double dt) {
    const double steps = ceil(time / dt);
    return steps < 9.0e18 ? (int64_t)steps : JD_INLET_NO_STOP;
}

int jd_inlet_height_due(int64_t step, int64_t every) {
    return step > 0 && every > 0 && step % every == 0;
}

double jd_inlet_deposit_top(size_t n, const double *x, const double *v, const double *radius,
                            double below_speed) {
    const double v2 = below_speed * below_speed;
    double top = -INFINITY;
    for (size_t i = 0; i < n; i++)
        if (dot3(&v[3 * i], &v[3 * i]) < v2)
            top = fmax(top, x[3 * i + 2] + radius[i]);
    return top;
}

void jd_inlet_height_stop(jd_inlet_stream *st, int64_t step, double top, double height) {
    if (top >= height && st->stop_step > step + 1)
        st->stop_step = step + 1;
}

int jd_inlet_record_line(const jd_inlet_particle *p, char *buf, size_t len) {
    return snprintf(buf, len, "%lld,%lld,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g\n", (long long)p->id,
                    (long long)p->step, p->position[0], p->position[1], p->position[2],
                    p->velocity[0], p->velocity[1], p->velocity[2]);
}
