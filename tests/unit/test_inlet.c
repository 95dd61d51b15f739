/* test_inlet.c — the conveyor inlet's stream (kernel/jdem_inlet.h) against closed forms. */
#include "unit.h"

#include <stdlib.h>
#include <string.h>

#include "jdem_inlet.h"

/* One sphere of radius 0.01 on a belt along +x towards the plane x = 0. */
static jd_inlet_spec one_sphere(const double *rel, const double *radius, const int32_t *species) {
    jd_inlet_spec s = {
        .n = 1, .rel = rel, .radius = radius, .species = species,
        .origin = {-0.0505, 0.5, 1.8}, .velocity = {1.0, 0.0, 0.0},
        .plane_point = {0.0, 0.0, 0.0}, .plane_normal = {1.0, 0.0, 0.0},
        .period = 0.2, .offset = 0.0, .dt = 1e-3, .first_id = 7,
        .max_sections = 0, .stop_step = JD_INLET_NO_STOP, .overlap_tol = JD_INLET_OVERLAP_TOL,
    };
    return s;
}

/* n spheres in a row along the belt (rel: their positions), origin 0, L = 0.3, ids from 1. */
static jd_inlet_spec row(size_t n, const double *rel, const double *radius, const int32_t *species) {
    jd_inlet_spec s = one_sphere(rel, radius, species);
    s.n = n;
    s.origin[0] = 0.0;
    s.period = 0.3;
    s.first_id = 1;
    return s;
}

static const double ORIGIN_REL[3] = {0.0, 0.0, 0.0};
static const double R1[1] = {0.01};
static const int32_t SP1[1] = {2};

/* k* = ceil((0.0505 + 0.2 c) / 0.001) = 51 + 200 c, far (half a step) from any round-off. */
static void crossing_step_of_each_copy(void **state) {
    (void)state;
    const jd_inlet_spec s = one_sphere(ORIGIN_REL, R1, SP1);
    char msg[256];
    assert_int_equal(jd_inlet_check(&s, 1, msg, sizeof msg), JD_INLET_OK);
    for (int64_t c = 0; c < 5; c++) {
        jd_inlet_particle p;
        jd_inlet_particle_at_crossing(&s, c, 0, &p);
        assert_int_equal(p.step, 51 + 200 * c);
        assert_int_equal(p.id, 7 + c);
        assert_int_equal(p.species, 2);
        assert_rel(p.radius, 0.01, 0.0);
        /* x = -0.0505 - 0.2 c + 1 m/s * k* dt = 0.0005 m past the plane */
        assert_rel(p.position[0], 0.0005, 1e-9);
        assert_rel(p.position[1], 0.5, 0.0);
        assert_rel(p.position[2], 1.8, 0.0);
        assert_rel(p.velocity[0], 1.0, 0.0);
        assert_rel(p.velocity[2], 0.0, 0.0);
    }
}

/* Dyadic values: s(50) = -50 2^-10 + 50 2^-10 = 0 exactly, and s >= 0 counts as crossed. */
static void exactly_on_the_plane_counts_as_crossed(void **state) {
    (void)state;
    jd_inlet_spec s = one_sphere(ORIGIN_REL, R1, SP1);
    s.dt = 0x1p-10;
    s.origin[0] = -50.0 * 0x1p-10;
    assert_rel(jd_inlet_signed_distance(&s, 0, 0, 50), 0.0, 0.0);
    assert_int_equal(jd_inlet_crossing_step(&s, 0, 0), 50);
    jd_inlet_particle p;
    jd_inlet_particle_at_crossing(&s, 0, 0, &p);
    assert_rel(p.position[0], 0.0, 0.0);
}

/* Round-off cases (dt = 1e-4, distances that are integers of steps in decimal): k* is, by the
 * definition, the first k with s(k) >= 0 as evaluated, never more than one step from the real
 * quotient. */
static void crossing_step_is_the_first_nonnegative_distance(void **state) {
    (void)state;
    jd_inlet_spec s = one_sphere(ORIGIN_REL, R1, SP1);
    s.dt = 1e-4;
    s.period = 0.24;
    s.velocity[0] = 0.8;
    s.velocity[2] = -0.6; /* inclined belt, plane normal along x: N.v = 0.8 */
    for (int i = 1; i < 400; i++) {
        s.origin[0] = -0.0001 * i * 0.8;
        for (int64_t c = 0; c < 3; c++) {
            const int64_t k = jd_inlet_crossing_step(&s, c, 0);
            assert_true(jd_inlet_signed_distance(&s, c, 0, k) >= 0.0);
            assert_true(k == 0 || jd_inlet_signed_distance(&s, c, 0, k - 1) < 0.0);
            /* real quotient: (0.0001 i 0.8 + 0.24 c 0.8) / (0.8 * 1e-4) = i + 2400 c */
            assert_true(llabs(k - (i + 2400 * c)) <= 1);
        }
    }
}

/* An inclined plane: normal (1, 0, 1)/sqrt 2 through (0, 0, 1.8), belt v = (1, 0, 0) at
 * z = 1.8 - 0.3: the centre crosses at x = 0.3, i.e. after (0.3 - x0)/v = 0.35 s from x0 = -0.05. */
static void inclined_plane_closed_form(void **state) {
    (void)state;
    jd_inlet_spec s = one_sphere(ORIGIN_REL, R1, SP1);
    s.origin[0] = -0.05;
    s.origin[2] = 1.5;
    s.plane_point[2] = 1.8;
    s.plane_normal[0] = 1.0;
    s.plane_normal[2] = 1.0; /* not unit: only the sign of s matters */
    s.dt = 1.0 / 1024.0;
    jd_inlet_particle p;
    jd_inlet_particle_at_crossing(&s, 0, 0, &p);
    assert_int_equal(p.step, (int64_t)ceil(0.35 * 1024.0)); /* 358.4 -> 359 */
    assert_rel(p.position[0], -0.05 + 359.0 / 1024.0, 1e-12);
}

static const double ROW_REL[9] = {-0.1005, 0, 0, -0.0505, 0, 0.05, -0.1505, 0.0, -0.05};
static const double ROW_RADIUS[3] = {0.01, 0.01, 0.02};
static const int32_t ROW_SPECIES[3] = {0, 0, 1};

/* The row of three of stream_order_ids_and_steps. */
static jd_inlet_spec three_in_a_row(void) { return row(3, ROW_REL, ROW_RADIUS, ROW_SPECIES); }

/* Three particles at x = -0.10, -0.05, -0.15 (relative to origin 0), L = 0.3, 4 sections, dt 1e-3:
 * particle p of copy c crosses at ceil((d_p + 0.3 c)/1e-3) + tiny; the stream pops every particle
 * once, at its step, in increasing step and, within a step, increasing id. */
static void stream_order_ids_and_steps(void **state) {
    (void)state;
    jd_inlet_spec s = three_in_a_row();
    s.max_sections = 4;
    char msg[256];
    assert_int_equal(jd_inlet_check(&s, 0, msg, sizeof msg), JD_INLET_OK);
    jd_inlet_cursor cur[3];
    jd_inlet_stream st;
    jd_inlet_stream_init(&s, &st, cur);
    assert_int_equal(st.next_step, 51);
    int seen[13] = {0};
    int64_t last_step = -1, last_id = 0, got = 0;
    while (st.next_step != JD_INLET_NEVER) {
        jd_inlet_particle out[8];
        const int64_t step = st.next_step;
        const size_t k = jd_inlet_pop(&s, &st, step, out, 8);
        assert_true(k >= 1);
        for (size_t i = 0; i < k; i++) {
            const int64_t c = (out[i].id - 1) / 3, p = (out[i].id - 1) % 3;
            const double d[3] = {100.5, 50.5, 150.5};
            assert_int_equal(out[i].step, step);
            assert_int_equal(step, (int64_t)ceil(d[p] + 300.0 * (double)c));
            assert_true(step > last_step || out[i].id > last_id);
            seen[out[i].id]++;
            last_step = step;
            last_id = out[i].id;
            got++;
        }
    }
    assert_int_equal(got, 12);
    for (int id = 1; id <= 12; id++)
        assert_int_equal(seen[id], 1);
    assert_int_equal(st.inserted, 12);
    assert_int_equal(st.started, 4);
}

/* The stop rule cuts at section boundaries: with stop_step 400 copy 1 (start 351) is completed
 * (its last particle at 451), copy 2 (start 651) never starts.  A cap of 1 leaves the rest due. */
static void stop_step_keeps_whole_sections(void **state) {
    (void)state;
    const double rel[6] = {-0.0505, 0, 0, -0.1505, 0, 0};
    const double radius[2] = {0.01, 0.01};
    const int32_t species[2] = {0, 0};
    jd_inlet_spec s = row(2, rel, radius, species);
    s.stop_step = 400;
    jd_inlet_cursor cur[2];
    jd_inlet_stream st;
    jd_inlet_stream_init(&s, &st, cur);
    int64_t ids[8], steps[8];
    size_t got = 0;
    while (st.next_step != JD_INLET_NEVER) {
        jd_inlet_particle out[1];
        const int64_t step = st.next_step;
        const size_t k = jd_inlet_pop(&s, &st, step, out, 1);
        for (size_t i = 0; i < k && got < 8; i++, got++) {
            ids[got] = out[i].id;
            steps[got] = out[i].step;
        }
    }
    assert_int_equal(got, 4);
    const int64_t want_ids[4] = {1, 2, 3, 4}, want_steps[4] = {51, 151, 351, 451};
    for (size_t i = 0; i < 4; i++) {
        assert_int_equal(ids[i], want_ids[i]);
        assert_int_equal(steps[i], want_steps[i]);
    }
    assert_int_equal(st.started, 2);
    /* a pop at a step with nothing due inserts nothing */
    jd_inlet_particle out[1];
    assert_int_equal(jd_inlet_pop(&s, &st, 500, out, 1), 0);
}

/* The work a stream still brings (jd_inlet_pending_particle_steps) against the sum over its
 * particles one by one, and jd_inlet_copies_by against a count of the section starts: the row of
 * stream_order_ids_and_steps (crossings at 101, 51, 151 + 300 c, all integers, so both sums are
 * exact), 6 sections, after the insertions of every 50th step, to a last step that cuts the
 * stream's copies off (1000, 1234) and one beyond it (5000); then a stop step (700: the copies
 * starting at 51, 351 and 651 only). */
static void pending_work_is_the_sum_over_particles(void **state) {
    (void)state;
    jd_inlet_spec s = three_in_a_row();
    s.max_sections = 6;
    jd_inlet_cursor cur[3];
    jd_inlet_stream st;
    jd_inlet_stream_init(&s, &st, cur);
    const int64_t lasts[3] = {1000, 1234, 5000};
    int checked_nonzero = 0;
    for (int64_t step = 0; step <= 2000; step++) {
        jd_inlet_particle out[8];
        while (st.next_step == step && jd_inlet_pop(&s, &st, step, out, 8) > 0) {}
        if (step % 50) continue;
        for (size_t q = 0; q < 3; q++) {
            const int64_t last = lasts[q];
            int64_t want_copies = 0;
            while (want_copies < s.max_sections && jd_inlet_section_start(&s, want_copies) <= last)
                want_copies++;
            const int64_t copies = jd_inlet_copies_by(&s, s.stop_step, last);
            assert_int_equal(copies, want_copies);
            double want = 0.0;
            for (int64_t c = 0; c < copies; c++)
                for (size_t p = 0; p < s.n; p++) {
                    const int64_t k = jd_inlet_insertion_step(&s, c, p);
                    if (k > step && k <= last) want += (double)(last - k);
                }
            assert_true(jd_inlet_pending_particle_steps(&s, cur, copies, last) == want);
            checked_nonzero += want > 0.0;
        }
    }
    assert_true(checked_nonzero > 40);
    assert_int_equal(jd_inlet_copies_by(&s, 700, 5000), 3);
    assert_int_equal(jd_inlet_copies_by(&s, 700, 350), 1);
    assert_int_equal(jd_inlet_copies_by(&s, JD_INLET_NO_STOP, 50), 0);
}

/* Two particles of different copies due at one step (period shorter than one step's travel) and
 * cap 1: one particle per call, in id order, the rest stays due at the same step. */
static void cap_leaves_the_rest_due(void **state) {
    (void)state;
    jd_inlet_spec s = one_sphere(ORIGIN_REL, R1, SP1);
    s.dt = 0.1;        /* 0.1 m per step */
    s.period = 0.025;  /* > 2 R = 0.02: no overlap; 4 periods per step's travel */
    s.max_sections = 3;
    s.first_id = 1;
    char msg[256];
    assert_int_equal(jd_inlet_check(&s, 0, msg, sizeof msg), JD_INLET_OK);
    jd_inlet_cursor cur[1];
    jd_inlet_stream st;
    jd_inlet_stream_init(&s, &st, cur);
    assert_int_equal(st.next_step, 1); /* copies 0 and 1: -0.0505 - 0.025 c + 0.1 >= 0 */
    jd_inlet_particle out[1];
    assert_int_equal(jd_inlet_pop(&s, &st, 1, out, 1), 1);
    assert_int_equal(out[0].id, 1);
    assert_int_equal(st.next_step, 1);
    assert_int_equal(jd_inlet_pop(&s, &st, 1, out, 1), 1);
    assert_int_equal(out[0].id, 2);
    assert_int_equal(st.next_step, 2); /* copy 2: -0.1005 + 0.1 k >= 0 at k = 2 */
    assert_int_equal(jd_inlet_pop(&s, &st, 2, out, 1), 1);
    assert_int_equal(out[0].id, 3);
    assert_int_equal(st.next_step, JD_INLET_NEVER);
}

/* Jiang's Ch. 4 section: 8 x 8 x 8 small spheres (R 0.015, pitch 0.03) and 4 big (R 0.03) on top.
 * Touching across L = 0.24 (the block length) is accepted; L = 0.23 overlaps itself. */
static void jiang_section_period(void **state) {
    (void)state;
    static double rel[3 * 516];
    static double radius[516];
    static int32_t species[516];
    size_t n = 0;
    for (int k = 0; k < 8; k++)
        for (int j = 0; j < 8; j++)
            for (int i = 0; i < 8; i++, n++) {
                rel[3 * n] = -0.105 + 0.03 * i;
                rel[3 * n + 1] = -0.105 + 0.03 * j;
                rel[3 * n + 2] = 0.015 + 0.03 * k;
                radius[n] = 0.015;
                species[n] = 1;
            }
    for (int q = 0; q < 4; q++, n++) {
        rel[3 * n] = q % 2 ? 0.06 : -0.06;
        rel[3 * n + 1] = q / 2 ? 0.06 : -0.06;
        rel[3 * n + 2] = 0.24 + 0.03;
        radius[n] = 0.03;
        species[n] = 0;
    }
    jd_inlet_spec s = {
        .n = n, .rel = rel, .radius = radius, .species = species,
        .origin = {-0.13005, 0.5, 1.8}, .velocity = {1.0, 0.0, 0.0},
        .plane_point = {0.0, 0.0, 0.0}, .plane_normal = {1.0, 0.0, 0.0},
        .period = 0.24, .offset = 0.0, .dt = 1e-4, .first_id = 1,
        .max_sections = 80, .stop_step = JD_INLET_NO_STOP, .overlap_tol = JD_INLET_OVERLAP_TOL,
    };
    char msg[256];
    assert_int_equal(jd_inlet_check(&s, 0, msg, sizeof msg), JD_INLET_OK);
    s.period = 0.23;
    assert_int_equal(jd_inlet_check(&s, 0, msg, sizeof msg), JD_INLET_PERIOD_OVERLAP);
    assert_non_null(strstr(msg, "overlaps itself across the period"));
    /* the first sphere of copy 1 starts 0.13005 + 0.105 + 0.24 = 0.47505 m behind the plane */
    s.period = 0.24;
    assert_int_equal(jd_inlet_crossing_step(&s, 1, 0), 4751);
}

static void check_messages(void **state) {
    (void)state;
    char msg[512];
    jd_inlet_spec s = one_sphere(ORIGIN_REL, R1, SP1);
    s.velocity[0] = -1.0;
    assert_int_equal(jd_inlet_check(&s, 1, msg, sizeof msg), JD_INLET_NEVER_CROSSES);
    assert_string_equal(msg, "the belt never crosses the inlet plane: velocity . normal = -1 <= 0; "
                             "valid: a velocity with a positive component along the normal "
                             "(towards the domain)");
    s = one_sphere(ORIGIN_REL, R1, SP1);
    s.origin[0] = 0.01;
    assert_int_equal(jd_inlet_check(&s, 1, msg, sizeof msg), JD_INLET_ALREADY_INSIDE);
    assert_string_equal(msg, "section particle 0 is already past the inlet plane at step 0 "
                             "(signed distance 0.01 >= 0); valid: a section behind the plane "
                             "(move the origin back against the belt, or raise the offset)");
    s = one_sphere(ORIGIN_REL, R1, SP1);
    assert_int_equal(jd_inlet_check(&s, 0, msg, sizeof msg), JD_INLET_NO_STOP_RULE);
    assert_string_equal(msg, "the stream never stops; valid: a number of sections, a deposit "
                             "height or a time");
    const double bad_r[1] = {-0.01};
    s = one_sphere(ORIGIN_REL, bad_r, SP1);
    assert_int_equal(jd_inlet_check(&s, 1, msg, sizeof msg), JD_INLET_BAD_VALUE);
    assert_string_equal(msg, "section particle 0: radius -0.01 is not valid; valid: a number > 0");
    s = one_sphere(ORIGIN_REL, R1, SP1);
    s.period = 0.0;
    assert_int_equal(jd_inlet_check(&s, 1, msg, sizeof msg), JD_INLET_BAD_VALUE);
    assert_string_equal(msg, "period 0 is not valid; valid: a number > 0");
    s.max_sections = 1; /* a single section (the second pass's queued cells) needs no period */
    assert_int_equal(jd_inlet_check(&s, 1, msg, sizeof msg), JD_INLET_OK);
    s = one_sphere(ORIGIN_REL, R1, SP1);
    s.plane_normal[0] = 0.0;
    assert_int_equal(jd_inlet_check(&s, 1, msg, sizeof msg), JD_INLET_NO_NORMAL);
    s = one_sphere(ORIGIN_REL, R1, SP1);
    s.dt = -1e-4;
    assert_int_equal(jd_inlet_check(&s, 1, msg, sizeof msg), JD_INLET_BAD_VALUE);
    assert_string_equal(msg, "dt -0.0001 is not valid; valid: a number > 0");
    const double two[6] = {0, 0, 0, 0.015, 0, 0};
    const double r2[2] = {0.01, 0.01};
    const int32_t sp2[2] = {0, 0};
    s = one_sphere(two, r2, sp2);
    s.n = 2;
    assert_int_equal(jd_inlet_check(&s, 1, msg, sizeof msg), JD_INLET_OVERLAP);
    assert_string_equal(msg, "section particles 0 and 1 overlap by 0.005 m; valid: spheres that "
                             "do not overlap");
    s.overlap_tol = 0.6; /* a deposit's cells keep their contacts' overlaps: 0.005 < 0.6 R */
    assert_int_equal(jd_inlet_check(&s, 1, msg, sizeof msg), JD_INLET_OK);
    s.n = 0;
    assert_int_equal(jd_inlet_check(&s, 1, msg, sizeof msg), JD_INLET_EMPTY);
}

/* ceil(time/dt): 0.5 s at 1e-3 s is step 500 (0.5/1e-3 rounds to 500 exactly); 0.5005 s is step
 * 501 (a step boundary is not a copy's start: the next step is the first refused). */
static void time_stop_is_the_ceiling(void **state) {
    (void)state;
    assert_int_equal(jd_inlet_stop_step_of_time(0.5, 1e-3), 500);
    assert_int_equal(jd_inlet_stop_step_of_time(0.5005, 1e-3), 501);
    assert_true(jd_inlet_stop_step_of_time(1e300, 1e-3) == JD_INLET_NO_STOP);
}

/* The height rule: checked at every, 2 every, ... only; the top of the slow particles; a top
 * at the height stops copies that start after the step, not one that starts at it. */
static void height_rule(void **state) {
    (void)state;
    assert_false(jd_inlet_height_due(0, 10));
    assert_false(jd_inlet_height_due(5, 10));
    assert_true(jd_inlet_height_due(10, 10));
    assert_true(jd_inlet_height_due(30, 10));
    const double x[9] = {0, 0, 1.0, 0, 0, 2.0, 0, 0, 0.5};
    const double v[9] = {0.05, 0, 0, 0, 0.2, 0, 0, 0, -0.0999};
    const double r[3] = {0.01, 0.02, 0.03};
    /* particle 1 is too fast: the top is max(1.0 + 0.01, 0.5 + 0.03) */
    assert_true(jd_inlet_deposit_top(3, x, v, r, 0.1) == 1.0 + 0.01);
    assert_true(jd_inlet_deposit_top(3, x, v, r, 0.01) == -INFINITY);
    const double rel[3] = {0, 0, 0};
    const int32_t sp[1] = {0};
    jd_inlet_spec s = one_sphere(rel, R1, sp);
    jd_inlet_cursor cur[1];
    jd_inlet_stream st;
    jd_inlet_stream_init(&s, &st, cur);
    jd_inlet_height_stop(&st, 300, 1.0, 1.01); /* below: nothing */
    assert_true(st.stop_step == JD_INLET_NO_STOP);
    jd_inlet_height_stop(&st, 251, 1.01, 1.01); /* copy 1 starts at 251 (51 + 200): admitted */
    assert_int_equal(st.stop_step, 252);
    jd_inlet_height_stop(&st, 400, 2.0, 1.01); /* a later check never raises it */
    assert_int_equal(st.stop_step, 252);
    jd_inlet_particle p[1];
    int64_t last = -1;
    for (int64_t k = 0; k < 1000; k++)
        if (jd_inlet_pop(&s, &st, k, p, 1)) last = p[0].copy;
    assert_int_equal(last, 1);
}

/* A record line reads back bit for bit (strtod of %.17g) with the header's columns. */
static void record_line_round_trip(void **state) {
    (void)state;
    const jd_inlet_particle p = {.id = 123456789012LL, .step = 42, .position = {0.1, -1.0 / 3.0, 1e-300},
                                 .velocity = {1.0, 0.0, -2.5e-17}};
    char line[JD_INLET_RECORD_LINE_MAX];
    const int len = jd_inlet_record_line(&p, line, sizeof line);
    assert_int_equal(len, (int)strlen(line));
    assert_true(line[len - 1] == '\n');
    char *at = line;
    assert_true(strtoll(at, &at, 10) == p.id && *at++ == ',');
    assert_true(strtoll(at, &at, 10) == p.step && *at++ == ',');
    for (int k = 0; k < 6; k++) {
        const double want = k < 3 ? p.position[k] : p.velocity[k - 3];
        assert_true(strtod(at, &at) == want);
        assert_true(*at++ == (k < 5 ? ',' : '\n'));
    }
    /* the longest line fits: 19-digit numbers and 6 negative subnormal-exponent values */
    const jd_inlet_particle big = {.id = INT64_MAX, .step = INT64_MAX,
                                   .position = {-1.2345678901234567e-300, -1.2345678901234567e-300,
                                                -1.2345678901234567e-300},
                                   .velocity = {-1.2345678901234567e-300, -1.2345678901234567e-300,
                                                -1.2345678901234567e-300}};
    assert_true(jd_inlet_record_line(&big, line, sizeof line) < JD_INLET_RECORD_LINE_MAX);
}

/* A 2 x 2 x 8 block (r = 0.01 m, spacing 0.02 m, long axis z) on the belt of one_sphere with
 * L = 0.3 m: its leading column (rel_x = 0) crosses first, at k* = ceil((0.0505 + 0.3 c)/0.001)
 * = 51 + 300 c; the trailing column (rel_x = -0.02) would cross 20 steps later.  The whole block
 * starts at the leading column's step, the trailing spheres at their rigid belt positions, so
 * every face-neighbour distance is still 2 r. */
static void bonded_block_starts_with_its_first_sphere(void **state) {
    (void)state;
    double rel[3 * 32], radius[32];
    int32_t species[32];
    size_t members[32];
    for (size_t p = 0; p < 32; p++) {
        rel[3 * p] = -0.02 * (double)(p % 2);
        rel[3 * p + 1] = 0.02 * (double)(p / 2 % 2);
        rel[3 * p + 2] = 0.02 * (double)(p / 4);
        radius[p] = 0.01;
        species[p] = 1;
        members[p] = p;
    }
    jd_inlet_spec s = one_sphere(rel, radius, species);
    s.n = 32;
    s.period = 0.3;
    char msg[256];
    assert_int_equal(jd_inlet_check(&s, 1, msg, sizeof msg), JD_INLET_OK);
    for (int64_t c = 0; c < 4; c++) {
        const int64_t start = jd_inlet_group_start(&s, c, members, 32);
        assert_int_equal(start, 51 + 300 * c);
        assert_int_equal(jd_inlet_crossing_step(&s, c, 1), 71 + 300 * c);
        jd_inlet_particle lead, trail;
        jd_inlet_particle_at_step(&s, c, 0, start, &lead);
        jd_inlet_particle_at_step(&s, c, 1, start, &trail);
        assert_int_equal(trail.step, start);
        assert_int_equal(trail.id, 7 + 32 * c + 1);
        assert_rel(lead.position[0], 0.0005, 1e-9);
        assert_rel(trail.position[0], -0.0195, 1e-9); /* still behind the plane, on the belt */
        assert_rel(lead.position[0] - trail.position[0], 0.02, 1e-12);
        assert_rel(trail.velocity[0], 1.0, 0.0);
        jd_inlet_particle at_crossing;
        jd_inlet_particle_at_crossing(&s, c, 0, &at_crossing);
        assert_memory_equal(at_crossing.position, lead.position, sizeof lead.position);
    }
    assert_int_equal(jd_inlet_group_start(&s, 0, members, 0), JD_INLET_NEVER);
    int64_t ids[2];
    jd_inlet_bond_ids(&s, 2, 5, 3, ids);
    assert_int_equal(ids[0], 7 + 64 + 3);
    assert_int_equal(ids[1], 7 + 64 + 5);
}

/* The stream of a section of two spheres in a row along the belt (rel_x = 0 and -0.02) bonded
 * into one group, and a third, unbonded sphere behind them (rel_x = -0.05): with origin
 * -0.0505, dt = 1 ms and L = 0.3 m their own crossing steps are 51, 71 and 101 (+ 300 c).  The
 * pair is popped whole at 51 + 300 c, the trailing sphere at x = -0.0195 + 0.3 ... on the belt,
 * the unbonded one alone at its own step. */
static void stream_inserts_a_group_whole(void **state) {
    (void)state;
    const double rel[9] = {0.0, 0.0, 0.0, -0.02, 0.0, 0.0, -0.05, 0.0, 0.0};
    const double radius[3] = {0.01, 0.01, 0.01};
    const int32_t species[3] = {1, 1, 1};
    const size_t first[2] = {0, 2}, member[2] = {0, 1};
    const int32_t group_of[3] = {0, 0, -1};
    jd_inlet_spec s = one_sphere(rel, radius, species);
    s.n = 3;
    s.period = 0.3;
    s.max_sections = 2;
    s.n_groups = 1;
    s.group_first = first;
    s.group_member = member;
    s.group_of = group_of;
    char msg[256];
    assert_int_equal(jd_inlet_check(&s, 0, msg, sizeof msg), JD_INLET_OK);
    jd_inlet_cursor cursor[3];
    jd_inlet_stream st;
    jd_inlet_stream_init(&s, &st, cursor);
    const int64_t due[4] = {51, 101, 351, 401};
    const size_t count[4] = {2, 1, 2, 1};
    for (int e = 0; e < 4; e++) {
        assert_int_equal(st.next_step, due[e]);
        jd_inlet_particle out[3];
        assert_int_equal(jd_inlet_pop(&s, &st, due[e], out, 3), count[e]);
        const int64_t c = e / 2;
        for (size_t q = 0; q < count[e]; q++) {
            assert_int_equal(out[q].step, due[e]);
            assert_int_equal(out[q].id, 7 + 3 * c + (int64_t)(e % 2 ? 2 : q));
        }
        if (count[e] == 2) { /* the pair: the trailing sphere 0.02 m behind, on the belt */
            assert_rel(out[0].position[0], 0.0005, 1e-9);
            assert_rel(out[1].position[0], -0.0195, 1e-9);
        }
    }
    assert_int_equal(st.next_step, JD_INLET_NEVER);
    assert_int_equal(jd_inlet_insertion_step(&s, 1, 1), 351);
    assert_int_equal(jd_inlet_crossing_step(&s, 1, 1), 371);
    const int32_t bad_of[3] = {0, -1, -1}; /* member 1 not marked with its group */
    s.group_of = bad_of;
    assert_int_equal(jd_inlet_check(&s, 0, msg, sizeof msg), JD_INLET_BAD_GROUP);
    assert_string_equal(msg, "bonded group 0: member 1 is not a section particle of that group "
                             "listed in increasing order");
}

/* jd_inlet_groups on a hand-worked graph of 8 particles: bonds 5-6, 1-3, 6-2, 3-7 (given out of
 * order, the larger index first in one) make the components {1, 3, 7} and {2, 5, 6}, numbered by
 * their smallest members 1 and 2; particles 0 and 4 are in no bond, so in no group.  The result
 * passes the kernel's own group check of a spec. */
static void groups_are_the_bond_components(void **state) {
    (void)state;
    const int32_t pair[8] = {5, 6, 1, 3, 6, 2, 3, 7};
    int32_t parent[8], group_of[8];
    size_t first[9], member[8];
    assert_int_equal(jd_inlet_groups(8, 4, pair, parent, group_of, first, member), 2);
    const int32_t want_of[8] = {-1, 0, 1, 0, -1, 1, 1, 0};
    for (int p = 0; p < 8; p++) assert_int_equal(group_of[p], want_of[p]);
    const size_t want_first[3] = {0, 3, 6}, want_member[6] = {1, 3, 7, 2, 5, 6};
    for (int g = 0; g < 3; g++) assert_int_equal(first[g], want_first[g]);
    for (int m = 0; m < 6; m++) assert_int_equal(member[m], want_member[m]);
    double rel[24] = {0};
    const double radius[8] = {0.01, 0.01, 0.01, 0.01, 0.01, 0.01, 0.01, 0.01};
    const int32_t species[8] = {0};
    for (int p = 0; p < 8; p++) rel[3 * p] = -0.03 * p; /* a row along the belt, 1 cm gaps */
    jd_inlet_spec s = one_sphere(rel, radius, species);
    s.n = 8;
    s.max_sections = 1;
    s.n_groups = 2;
    s.group_first = first;
    s.group_member = member;
    s.group_of = group_of;
    char msg[256];
    assert_int_equal(jd_inlet_check(&s, 0, msg, sizeof msg), JD_INLET_OK);
    assert_int_equal(jd_inlet_groups(8, 0, pair, parent, group_of, first, member), 0);
    for (int p = 0; p < 8; p++) assert_int_equal(group_of[p], -1);
}

/* jd_inlet_sort_bonds: 7 bonds given out of order, two with the larger index first, come back
 * smaller first in the (smaller, larger) order with their types; the same list with a pair
 * repeated (reversed) reports the repeat at its sorted index. */
static void section_bonds_sort_into_the_resolved_order(void **state) {
    (void)state;
    int32_t pair[14] = {5, 6, 1, 3, 6, 2, 3, 7, 0, 9, 1, 2, 4, 0};
    int32_t type[7] = {10, 11, 12, 13, 14, 15, 16};
    assert_int_equal(jd_inlet_sort_bonds(7, pair, type), 7);
    const int32_t want_pair[14] = {0, 4, 0, 9, 1, 2, 1, 3, 2, 6, 3, 7, 5, 6};
    const int32_t want_type[7] = {16, 14, 15, 11, 12, 13, 10};
    for (int k = 0; k < 14; k++) assert_int_equal(pair[k], want_pair[k]);
    for (int k = 0; k < 7; k++) assert_int_equal(type[k], want_type[k]);
    int32_t twice[8] = {3, 1, 0, 2, 1, 3, 0, 1}, t2[4] = {0, 1, 2, 3};
    assert_int_equal(jd_inlet_sort_bonds(4, twice, t2), 3); /* 0-1, 0-2, 1-3, 1-3 */
    assert_int_equal(twice[4], 1);
    assert_int_equal(twice[7], 3);
    assert_int_equal(jd_inlet_sort_bonds(0, twice, t2), 0);
}

/* The overlap fraction (ra + rb - d)/min(ra, rb): spheres 0.01 and 0.02 m, 0.027 m apart
 * (a 3-4-12 right triangle of 0.001 m units: |(0.003, 0.024, 0.012)| = 0.027) overlap by 0.003 m,
 * 0.3 of the smaller radius; 0.03 m apart they touch (0), 0.04 m apart they are 1.0 apart (-1). */
static void overlap_fraction_closed_form(void **state) {
    (void)state;
    const double a[3] = {0.0, 0.0, 0.0}, b[3] = {0.003, 0.024, 0.012}, c[3] = {0.0, 0.0, 0.04};
    assert_rel(jd_inlet_overlap_fraction(a, 0.01, b, 0.02), 0.3, 1e-12);
    assert_rel(jd_inlet_overlap_fraction(b, 0.02, a, 0.01), 0.3, 1e-12);
    assert_rel(jd_inlet_overlap_fraction(a, 0.01, c, 0.03), 0.0, 0.0);
    assert_rel(jd_inlet_overlap_fraction(a, 0.01, c, 0.02), -1.0, 1e-12);
}

/* Three due particles of one copy: 0 and 1 a bonded group, 2 alone; two particles in the domain:
 * one 0.012 m from particle 1 across the belt (radii 0.01: overlap 0.8), one far away.  worst and with name the
 * near one; with max_insert_overlap 0.5 particle 1 is skipped and so is its
 * block partner 0, whose own place is free; particle 2 of the same copy, in no group, is not.
 * A limit of 0.9 skips none; one of INFINITY none; the booked count moves from inserted to
 * skipped. */
static void occupied_place_skips_its_block(void **state) {
    (void)state;
    const double rel[9] = {0.0, 0.0, 0.0, -0.03, 0.0, 0.0, -0.06, 0.0, 0.0};
    const double radius[3] = {0.01, 0.01, 0.01};
    const int32_t species[3] = {0, 0, 0}, group_of[3] = {0, 0, -1};
    const size_t first[2] = {0, 2}, member[2] = {0, 1};
    jd_inlet_spec s = row(3, rel, radius, species);
    s.n_groups = 1;
    s.group_first = first;
    s.group_member = member;
    s.group_of = group_of;
    jd_inlet_particle due[3];
    for (size_t p = 0; p < 3; p++) jd_inlet_particle_at_step(&s, 4, p, 100, &due[p]);
    const double x[6] = {due[1].position[0], due[1].position[1] + 0.012, due[1].position[2],
                         5.0, 5.0, 5.0};
    const double r[2] = {0.01, 0.01};
    double worst[3];
    size_t with[3];
    jd_inlet_worst_overlaps(due, 3, 2, x, r, worst, with);
    assert_rel(worst[1], 0.8, 1e-12);
    assert_int_equal(with[1], 0);
    /* particles 0 and 2 are |(0.03, 0.012, 0)| = 0.0323 m from it: apart, (0.02 - 0.0323)/0.01 */
    assert_rel(worst[0], (0.02 - sqrt(0.03 * 0.03 + 0.012 * 0.012)) / 0.01, 1e-9);
    assert_rel(worst[2], worst[0], 1e-9);
    unsigned char skip[3];
    s.max_insert_overlap = 0.5;
    assert_int_equal(jd_inlet_skip_groups(&s, due, 3, worst, skip), 2);
    assert_int_equal(skip[0], 1);
    assert_int_equal(skip[1], 1);
    assert_int_equal(skip[2], 0);
    s.max_insert_overlap = 0.9;
    assert_int_equal(jd_inlet_skip_groups(&s, due, 3, worst, skip), 0);
    s.max_insert_overlap = INFINITY;
    assert_int_equal(jd_inlet_skip_groups(&s, due, 3, worst, skip), 0);
    jd_inlet_stream st = {.inserted = 5, .skipped = 1};
    jd_inlet_book_skipped(&st, 2);
    assert_int_equal(st.inserted, 3);
    assert_int_equal(st.skipped, 3);
    char msg[256];
    s.max_insert_overlap = NAN;
    assert_int_equal(jd_inlet_check(&s, 0, msg, sizeof msg), JD_INLET_BAD_VALUE);
    assert_string_equal(msg, "max_insert_overlap nan is not valid; valid: a number >= 0 (a "
                             "fraction of the smaller radius) or inf");
}

/* Nothing within reach: worst = -INFINITY and with = SIZE_MAX, also for an empty domain. */
static void free_place_has_no_partner(void **state) {
    (void)state;
    jd_inlet_spec s = one_sphere(ORIGIN_REL, R1, SP1);
    jd_inlet_particle p;
    jd_inlet_particle_at_crossing(&s, 0, 0, &p);
    const double x[3] = {p.position[0] + 0.5, p.position[1], p.position[2]}, r[1] = {0.01};
    double worst = 0.0;
    size_t with = 0;
    jd_inlet_worst_overlaps(&p, 1, 1, x, r, &worst, &with);
    assert_true(isinf(worst) && worst < 0.0);
    assert_int_equal(with, SIZE_MAX);
    jd_inlet_worst_overlaps(&p, 1, 0, NULL, NULL, &worst, &with);
    assert_true(isinf(worst) && worst < 0.0);
}

int run_inlet_tests(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(crossing_step_of_each_copy),
        cmocka_unit_test(exactly_on_the_plane_counts_as_crossed),
        cmocka_unit_test(crossing_step_is_the_first_nonnegative_distance),
        cmocka_unit_test(inclined_plane_closed_form),
        cmocka_unit_test(stream_order_ids_and_steps),
        cmocka_unit_test(stop_step_keeps_whole_sections),
        cmocka_unit_test(pending_work_is_the_sum_over_particles),
        cmocka_unit_test(cap_leaves_the_rest_due),
        cmocka_unit_test(jiang_section_period),
        cmocka_unit_test(check_messages),
        cmocka_unit_test(time_stop_is_the_ceiling),
        cmocka_unit_test(height_rule),
        cmocka_unit_test(record_line_round_trip),
        cmocka_unit_test(bonded_block_starts_with_its_first_sphere),
        cmocka_unit_test(stream_inserts_a_group_whole),
        cmocka_unit_test(groups_are_the_bond_components),
        cmocka_unit_test(section_bonds_sort_into_the_resolved_order),
        cmocka_unit_test(overlap_fraction_closed_form),
        cmocka_unit_test(occupied_place_skips_its_block),
        cmocka_unit_test(free_place_has_no_partner),
    };
    return cmocka_run_group_tests_name("inlet", tests, NULL, NULL);
}
