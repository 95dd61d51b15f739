/*
 * test_bond.c — the parallel bond law (kernel/jdem_bond.h) against closed forms: the section of
 * eq. (15), the four incremental springs under constant relative motion (F = k A v t,
 * M = k J w t, M = k I w t), failure at the step where the stress of eq. (17) reaches the
 * strength, the frame rotation of stored vectors, action–reaction with a and b swapped (the
 * newton table), the damped axial oscillator's decay exp(-gamma w t) and its energy balance.
 */
#include "unit.h"

#include "jdem_bond.h"

static const double R = 1e-3; /* sphere radius [m] */

static jd_bond_params params(void) {
    return (jd_bond_params){.kn = 2e12, .kt = 1e12, .sigma_c = 5e6, .tau_c = 8e6, .lambda = 0.8,
                            .gamma = 0.0, .bending = JD_BOND_BEND_I};
}

/* Two touching spheres of radius R along z, a at the origin. */
static jd_bond_geom touching_z(const jd_bond_params *p) {
    jd_bond_geom g;
    const double xa[3] = {0, 0, 0}, xb[3] = {0, 0, 2 * R};
    assert_int_equal(jd_bond_geom_spheres(xa, R, xb, R, &g), 1);
    g.sec = jd_bond_section_of(p->lambda, R, R);
    g.m_eff = 0.5 * jd_sphere_mass(R, 2600.0);
    g.i_eff = 0.5 * jd_sphere_inertia(jd_sphere_mass(R, 2600.0), R);
    return g;
}

static void section_closed_form(void **state) {
    (void)state;
    const jd_bond_section s = jd_bond_section_of(0.5, 2e-3, 1e-3);
    assert_rel(s.rbar, 0.5e-3, 1e-15);
    assert_rel(s.A, JD_PI * 0.25e-6, 1e-15);
    assert_rel(s.I, JD_PI * pow(0.5e-3, 4) / 4, 1e-14);
    assert_rel(s.J, 2 * s.I, 1e-15);
}

static void separated_geometry_puts_the_bond_mid_gap(void **state) {
    (void)state;
    jd_bond_geom g;
    const double xa[3] = {1, 2, 3}, xb[3] = {1, 2 + 3 * R, 3}; /* gap R */
    assert_int_equal(jd_bond_geom_spheres(xa, R, xb, R, &g), 1);
    assert_rel(g.delta, -R, 1e-12);
    assert_rel(g.ra[1], 1.5 * R, 1e-12);
    assert_rel(g.rb[1], -1.5 * R, 1e-12);
    assert_rel(g.n[1], 1.0, 1e-15);
    assert_int_equal(jd_bond_geom_spheres(xa, R, xa, R, &g), 0);
}

/* Drive the bond with constant kinematics; return the step at which it broke (1-based) or 0. */
static int drive(const jd_bond_params *p, const jd_bond_geom *g, const jd_kinematics *k,
                 double dt, int steps, jd_bond_state *s, jd_bond_result *out) {
    for (int i = 1; i <= steps; i++)
        if (jd_bond(JD_B_ENERGY, p, g, k, dt, s, out) != JD_BOND_INTACT) return i;
    return 0;
}

static void tension_force_and_break_step(void **state) {
    (void)state;
    const jd_bond_params p = params();
    const jd_bond_geom g = touching_z(&p);
    const double v = 0.0099, dt = 1e-7; /* sigma_c/(kn v dt) = 2525.25 steps */
    jd_kinematics k = {.vb = {0, 0, v}};
    jd_bond_state s;
    jd_bond_result out;
    jd_bond_form(&s);
    /* 10 steps: F_n = -kn A v t (tension), force on b towards a */
    assert_int_equal(drive(&p, &g, &k, dt, 10, &s, &out), 0);
    assert_rel(out.fn, -p.kn * g.sec.A * v * 10 * dt, 1e-12);
    assert_rel(out.f[2], -p.kn * g.sec.A * v * 10 * dt, 1e-12);
    assert_rel(out.sigma_max, p.kn * v * 10 * dt, 1e-12);
    assert_rel(jd_bond_energy(&p, &g.sec, &s), 0.5 * p.kn * g.sec.A * pow(v * 10 * dt, 2), 1e-12);
    /* break at the first step with kn v t >= sigma_c */
    const int expected = (int)ceil(p.sigma_c / (p.kn * v * dt));
    jd_bond_form(&s);
    const int at = drive(&p, &g, &k, dt, 10 * expected, &s, &out);
    assert_int_equal(at, expected);
    assert_int_equal(out.mode, JD_BOND_BROKE_TENSION);
    assert_rel(out.f[2], 0.0, 0.0);
    assert_false(jd_bond_intact(&s));
    /* released energy: what the bond stored one step before, plus the kinetic energy its last
     * (tensile) force still takes from the bodies over the first half of the breaking step */
    const double F1 = p.kn * g.sec.A * v * (expected - 1) * dt;
    assert_rel(s.e_break, 0.5 * F1 * F1 / (p.kn * g.sec.A) + 0.5 * F1 * v * dt, 1e-9);
}

static void shear_force_and_break_step(void **state) {
    (void)state;
    const jd_bond_params p = params();
    const jd_bond_geom g = touching_z(&p);
    const double v = 0.0199, dt = 1e-7; /* tau_c/(kt v dt) = 4020.1 steps */
    /* pure translation of b along x: the contact-point velocity is v; no rotation */
    jd_kinematics k = {.vb = {v, 0, 0}};
    jd_bond_state s;
    jd_bond_result out;
    jd_bond_form(&s);
    assert_int_equal(drive(&p, &g, &k, dt, 7, &s, &out), 0);
    assert_rel(out.ft, p.kt * g.sec.A * v * 7 * dt, 1e-12);
    assert_rel(out.f[0], -p.kt * g.sec.A * v * 7 * dt, 1e-12);
    /* torque on a about its centre: ra x (-f) with ra = R z, -f = +x: R F_t in +y */
    assert_rel(out.ta[1], R * p.kt * g.sec.A * v * 7 * dt, 1e-12);
    assert_rel(out.tb[1], R * p.kt * g.sec.A * v * 7 * dt, 1e-12);
    assert_rel(out.tau_max, p.kt * v * 7 * dt, 1e-12);
    const int expected = (int)ceil(p.tau_c / (p.kt * v * dt));
    jd_bond_form(&s);
    assert_int_equal(drive(&p, &g, &k, dt, 10 * expected, &s, &out), expected);
    assert_int_equal(out.mode, JD_BOND_BROKE_SHEAR);
}

static void twisting_moment_and_break(void **state) {
    (void)state;
    const jd_bond_params p = params();
    const jd_bond_geom g = touching_z(&p);
    const double w = 3.0, dt = 1e-7;
    jd_kinematics k = {.wb = {0, 0, w}};
    jd_bond_state s;
    jd_bond_result out;
    jd_bond_form(&s);
    assert_int_equal(drive(&p, &g, &k, dt, 5, &s, &out), 0);
    const double M = p.kt * g.sec.J * w * 5 * dt; /* k J theta */
    assert_rel(out.mn, M, 1e-12);
    assert_rel(out.tb[2], -M, 1e-12);
    assert_rel(out.ta[2], M, 1e-12);
    assert_rel(out.tau_max, M * g.sec.rbar / g.sec.J, 1e-12);
    const int expected = (int)ceil(p.tau_c / (p.kt * g.sec.rbar * w * dt) - 1e-9);
    jd_bond_form(&s);
    assert_int_equal(drive(&p, &g, &k, dt, 10 * expected, &s, &out), expected);
    assert_int_equal(out.mode, JD_BOND_BROKE_SHEAR);
}

static void bending_moment_and_break_and_literal_option(void **state) {
    (void)state;
    jd_bond_params p = params();
    const jd_bond_geom g = touching_z(&p);
    const double w = 2.0, dt = 1e-7;
    /* a and b counter-rotate about x: no contact-point velocity, pure bending */
    jd_kinematics k = {.wa = {-0.5 * w, 0, 0}, .wb = {0.5 * w, 0, 0}};
    jd_bond_state s;
    jd_bond_result out;
    jd_bond_form(&s);
    assert_int_equal(drive(&p, &g, &k, dt, 4, &s, &out), 0);
    const double M = p.kn * g.sec.I * w * 4 * dt; /* k I theta */
    assert_rel(out.mt, M, 1e-12);
    assert_rel(out.tb[0], -M, 1e-12);
    assert_rel(out.sigma_max, M * g.sec.rbar / g.sec.I, 1e-12);
    assert_rel(out.ft, 0.0, 0.0);
    const int expected = (int)ceil(p.sigma_c / (p.kn * g.sec.rbar * w * dt) - 1e-9);
    jd_bond_form(&s);
    assert_int_equal(drive(&p, &g, &k, dt, 10 * expected, &s, &out), expected);
    assert_int_equal(out.mode, JD_BOND_BROKE_TENSION);
    /* the dissertation's literal J doubles the bending stiffness */
    p.bending = JD_BOND_BEND_J_LITERAL;
    jd_bond_form(&s);
    assert_int_equal(drive(&p, &g, &k, dt, 4, &s, &out), 0);
    assert_rel(out.mt, 2 * M, 1e-12);
}

static void stored_vectors_follow_the_frame(void **state) {
    (void)state;
    const jd_bond_params p = params();
    jd_bond_geom g = touching_z(&p);
    const double dt = 1e-7;
    /* shear along x, bending about y */
    jd_kinematics k = {.vb = {0.01, 0, 0}, .wb = {0, 0.5, 0}, .wa = {0, -0.5, 0}};
    jd_bond_state s;
    jd_bond_result out;
    jd_bond_form(&s);
    drive(&p, &g, &k, dt, 3, &s, &out);
    const double ft = out.ft, mt = out.mt;
    /* the pair turns by 45 degrees about y: the shear force is no longer in the plane normal to
     * n; turned into it, with no further motion, both magnitudes stay */
    const double xa[3] = {0, 0, 0}, xb[3] = {sqrt(2.0) * R, 0, sqrt(2.0) * R};
    jd_bond_geom_spheres(xa, R, xb, R, &g);
    const jd_kinematics still = {.va = {0, 0, 0}};
    jd_bond(0, &p, &g, &still, dt, &s, &out);
    assert_rel(out.ft, ft, 1e-12);
    assert_rel(out.mt, mt, 1e-12);
    assert_true(fabs(jd_dot(s.ft, g.n)) <= 1e-15 * out.ft);
    assert_true(fabs(jd_dot(s.mt, g.n)) <= 1e-15 * out.mt);
}

static void swapping_a_and_b_is_action_reaction(void **state) {
    (void)state;
    const jd_bond_params p = params();
    const double xa[3] = {0, 0, 0}, xb[3] = {0.3 * R, 0.2 * R, 1.9 * R};
    jd_bond_geom g, h;
    jd_bond_geom_spheres(xa, R, xb, R, &g);
    jd_bond_geom_spheres(xb, R, xa, R, &h);
    g.sec = h.sec = jd_bond_section_of(p.lambda, R, R);
    const jd_kinematics k = {.va = {0.01, -0.02, 0.005}, .wa = {1, 2, -3},
                             .vb = {-0.01, 0.03, 0.02}, .wb = {-2, 0.5, 4}};
    const jd_kinematics ks = {.va = {-0.01, 0.03, 0.02}, .wa = {-2, 0.5, 4},
                              .vb = {0.01, -0.02, 0.005}, .wb = {1, 2, -3}};
    jd_bond_state s, t;
    jd_bond_result o, q;
    jd_bond_form(&s);
    for (int i = 0; i < 5; i++) jd_bond(JD_B_ENERGY, &p, &g, &k, 1e-7, &s, &o);
    /* the same history seen from b: newton entries flip */
    const double *sv = (const double *)&s;
    double *tv = (double *)&t;
    for (int i = 0; i < JD_BOND_STATE_LEN; i++) tv[i] = jd_bond_state_newton[i] ? -sv[i] : sv[i];
    jd_bond(JD_B_ENERGY, &p, &g, &k, 1e-7, &s, &o);
    jd_bond(JD_B_ENERGY, &p, &h, &ks, 1e-7, &t, &q);
    for (int d = 0; d < 3; d++) {
        assert_rel(q.f[d], -o.f[d], 1e-12);
        assert_rel(q.ta[d], o.tb[d], 1e-12);
        assert_rel(q.tb[d], o.ta[d], 1e-12);
    }
    assert_rel(q.sigma_max, o.sigma_max, 1e-12);
    assert_rel(q.tau_max, o.tau_max, 1e-12);
}

/* Two spheres on a bond, axial mode, integrated by velocity Verlet as the engines do. */
static void damped_axial_oscillator(void **state) {
    (void)state;
    jd_bond_params p = params();
    p.gamma = 0.05;
    p.sigma_c = p.tau_c = INFINITY;
    jd_bond_geom g = touching_z(&p);
    const double m = jd_sphere_mass(R, 2600.0);
    const double K = p.kn * g.sec.A, w0 = sqrt(K / g.m_eff);
    const double dt = 2 * JD_PI / w0 / 400, v0 = 0.01;
    double za = 0, zb = 2 * R, va = -0.5 * v0, vb = 0.5 * v0, fb = 0;
    const double e0 = 0.5 * m * (va * va + vb * vb);
    jd_bond_state s;
    jd_bond_result out;
    jd_bond_form(&s);
    const int steps = 4 * 400;
    double umax_last = 0, ref_last = 0;
    const double wd = w0 * sqrt(1 - p.gamma * p.gamma);
    for (int i = 0; i < steps; i++) {
        va += 0.5 * dt * (-fb) / m;
        vb += 0.5 * dt * fb / m;
        za += dt * va;
        zb += dt * vb;
        const double xa[3] = {0, 0, za}, xb[3] = {0, 0, zb};
        jd_bond_geom_spheres(xa, R, xb, R, &g);
        const jd_kinematics k = {.va = {0, 0, va}, .vb = {0, 0, vb}};
        jd_bond(JD_B_DAMPING | JD_B_ENERGY, &p, &g, &k, dt, &s, &out);
        fb = out.f[2];
        va += 0.5 * dt * (-fb) / m;
        vb += 0.5 * dt * fb / m;
        if (i >= steps - 400) {
            /* spring force K x(t) of the damped oscillator x = v0/wd e^(-gamma w0 t) sin(wd t),
             * at the end of the step (the force is evaluated at the new positions) */
            const double t = (i + 1) * dt;
            umax_last = fmax(umax_last, fabs(s.fn));
            ref_last = fmax(ref_last, fabs(K * v0 / wd * exp(-p.gamma * w0 * t) * sin(wd * t)));
        }
    }
    /* peak spring force of the fourth period against the closed form */
    assert_rel(umax_last, ref_last, 5e-3);
    /* kinetic + stored + dissipated is conserved to O(dt^2) */
    const double ek = 0.5 * m * (va * va + vb * vb);
    assert_rel(ek + jd_bond_energy(&p, &g.sec, &s) + s.e_damp, e0, 1e-3);
    assert_true(s.e_damp > 0.5 * e0);
}

static void frequency_bound(void **state) {
    (void)state;
    const jd_bond_params p = params();
    const jd_bond_section sec = jd_bond_section_of(p.lambda, R, R);
    const double m = jd_sphere_mass(R, 2600.0), I = jd_sphere_inertia(m, R);
    const double w2 = jd_bond_omega2_bound(&p, &sec, m, m, I, I, R, R);
    /* the shear–bending block dominates for these spheres: kt A (2/m + 2 R^2/I) + kn I 2/I_s */
    const double expected = p.kt * sec.A * (2 / m + 2 * R * R / I) + p.kn * sec.I * 2 / I;
    assert_rel(w2, expected, 1e-14);
    assert_true(w2 >= p.kn * sec.A * 2 / m); /* at least the axial pair frequency */
}

int run_bond_tests(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(section_closed_form),
        cmocka_unit_test(separated_geometry_puts_the_bond_mid_gap),
        cmocka_unit_test(tension_force_and_break_step),
        cmocka_unit_test(shear_force_and_break_step),
        cmocka_unit_test(twisting_moment_and_break),
        cmocka_unit_test(bending_moment_and_break_and_literal_option),
        cmocka_unit_test(stored_vectors_follow_the_frame),
        cmocka_unit_test(swapping_a_and_b_is_action_reaction),
        cmocka_unit_test(damped_axial_oscillator),
        cmocka_unit_test(frequency_bound),
    };
    return cmocka_run_group_tests_name("bond", tests, NULL, NULL);
}
