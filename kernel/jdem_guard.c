/*
 * jdem_guard.c — the time-step guard (jdem_guard.h; docs/model.md §8).
 *
 * The coordination bound.  Linearised about a contact, velocity Verlet is stable while
 * omega_max dt <= 2, omega_max^2 the largest eigenvalue of M^-1/2 K M^-1/2 (6 degrees of freedom
 * per sphere).  By the block Gershgorin theorem (Feingold & Varga 1962) that eigenvalue is at most
 * max_i sum_{contacts c of i} (||D_ci|| + ||O_c||), D_ci the block a contact adds on particle i's
 * diagonal and O_c the block coupling it to its partner.  With the secant stiffness K = k_n
 * sqrt(delta) of Jiang's law, the normal tangent stiffness is 3/2 K, the tangential spring K_t
 * (K_t = K, Sec. 2.3.2, or Mindlin's 8 G* sqrt(R* delta), which exceeds K: 3(1-nu)/(2-nu) K for
 * like materials) acting at the lever arm R, and the rolling spring K r_roll^2:
 *   ||D_ai|| <= max(3/2 K/m_a, K_t (1/m_a + R_a^2/I_a)) + K r_roll^2/I_a
 *   ||O||    <= max(3/2 K/sqrt(m_a m_b), K_t sqrt((1/m_a + R_a^2/I_a)(1/m_b + R_b^2/I_b)))
 *               + K r_roll^2/sqrt(I_a I_b)
 * (the normal and the two tangential directions are orthogonal in the mass-scaled coordinates,
 * so their parts combine by max; the rolling part is added).  For two equal spheres without
 * rolling this is exact: omega^2 = 7 K_t/m, the coupled sliding-rolling mode.  K is taken at the
 * peak overlap of an impact at max_impact_speed, and a particle is assumed to carry
 * `coordination` contacts of the stiffest kind its species has.  Viscous damping of ratio zeta
 * lowers the limit of the central-difference scheme to (2/omega)(sqrt(1 + zeta^2) - zeta).
 */
#include "jdem_guard.h"

#include <math.h>
#include <stdio.h>

#include "jdem_kernel.h"

const char *jd_guard_bound_name(int bound) {
    switch (bound) {
    case JD_GUARD_RAYLEIGH: return "20 % of the Rayleigh time step";
    case JD_GUARD_CONTACT_TIME: return "1/50 of the shortest Hertz contact time";
    case JD_GUARD_COORDINATION: return "the Verlet stability limit at coordination number";
    case JD_GUARD_BOND: return "1/20 of the fastest bond period";
    default: return "";
    }
}

/* One side of a contact: mass, inertia and 1/m + R^2/I (the tangential mobility). */
typedef struct side {
    double m, I, mob;
} side;

static side side_of(double R, double rho) {
    const double m = jd_sphere_mass(R, rho), I = jd_sphere_inertia(m, R);
    return (side){.m = m, .I = I, .mob = 1.0 / m + R * R / I};
}

/* The stiffnesses of one contact at the impact's peak overlap: normal tangent [N/m],
 * tangential [N/m] and rolling [N m/rad]. */
typedef struct springs {
    double Kn, Kt, Kr;
} springs;

/* Gershgorin row sum ||D_a|| + ||O|| of one contact of a (b NULL: a wall) [1/s^2]. */
static double row_sum(const side *a, const side *b, springs k) {
    double s = fmax(k.Kn / a->m, k.Kt * a->mob) + k.Kr / a->I;
    if (b)
        s += fmax(k.Kn / sqrt(a->m * b->m), k.Kt * sqrt(a->mob * b->mob)) + k.Kr / sqrt(a->I * b->I);
    return s;
}

/* Jiang's Hertz contact at peak overlap d with secant stiffness K and rolling arm r: the normal
 * tangent 3/2 K, the tangential spring Kt, the rolling spring K r^2. */
static springs hertz_springs(double K, double Kt, double r) {
    return (springs){.Kn = 1.5 * K, .Kt = Kt, .Kr = K * r * r};
}

/* The tangential stiffness at overlap delta of a contact with secant stiffness K, effective
 * radius r_star and Mindlin's share of 1/G* of each side (jd_shear_compliance; a wall's is 0). */
static double tangential_k(int rule, double K, double share_a, double share_b, double r_star,
                           double delta) {
    if (rule != JD_KT_MINDLIN) return K;
    return 8.0 / (share_a + share_b) * sqrt(r_star * delta);
}

/* A MEPA contact at peak overlap d: the unloading branch's tangent n k2 d^(n-1), the stiffest the
 * contact has there; its rolling spring takes the virgin secant k1 d^(n-1) (jd_law_mepa), its
 * tangential spring that too, or Mindlin's K_t (tangential_k, with the shares of 1/G*). */
static springs mepa_springs(const jd_guard_input *in, double k1, double k2, double d, double r,
                            double share_a, double share_b) {
    const double s = pow(d, in->mepa_n - 1.0), K = k1 * s;
    return (springs){.Kn = in->mepa_n * k2 * s,
                     .Kt = tangential_k(in->tangential_rule, K, share_a, share_b, r, d),
                     .Kr = K * r * r};
}

/* One kind of contact at the scene's impact speed: its duration [s] and its springs at the
 * impact's peak overlap. */
typedef struct impact {
    double time;
    springs k;
} impact;

/* Jiang's Hertz contact of effective mass m_eff [kg], prefactor kn [N/m^1.5] and radius r [m];
 * share_a, share_b: the sides' shares of Mindlin's 1/G* (a wall's is 0). */
static impact hertz_impact(const jd_guard_input *in, double m_eff, double kn, double r,
                           double share_a, double share_b) {
    const double v = in->max_impact_speed;
    const double d = jd_hertz_peak_overlap(m_eff, kn, v), K = kn * sqrt(d);
    return (impact){.time = jd_hertz_contact_time(m_eff, kn, v),
                    .k = hertz_springs(K, tangential_k(in->tangential_rule, K, share_a, share_b,
                                                       r, d), r)};
}

/* A MEPA contact of pair stiffnesses k1, k2 (jd_mepa_impact_time), the rest as hertz_impact. */
static impact mepa_impact(const jd_guard_input *in, double m_eff, double k1, double k2, double r,
                          double share_a, double share_b) {
    double d;
    const double t = jd_mepa_impact_time(m_eff, k1, k2, in->mepa_n, in->max_impact_speed, &d);
    return (impact){.time = t, .k = mepa_springs(in, k1, k2, d, r, share_a, share_b)};
}

static void tighten(jd_guard_result *r, double dt, double bound, int which) {
    if (bound < r->safe_dt) {
        r->safe_dt = bound;
        r->binding = which;
    }
    if (dt > bound && (!r->violated || bound < r->violated_value)) {
        r->violated = which;
        r->violated_value = bound;
    }
}

void jd_guard_assess(const jd_guard_input *in, jd_guard_result *out) {
    *out = (jd_guard_result){.rayleigh_bound = INFINITY, .contact_time = INFINITY,
                             .contact_bound = INFINITY, .coordination_bound = INFINITY,
                             .bond_bound = INFINITY,
                             .safe_dt = INFINITY, .binding = JD_GUARD_SAFE,
                             .violated = JD_GUARD_SAFE};
    const double v = in->max_impact_speed;
    double omega2 = 0.0; /* the largest row sum of one contact */
    for (size_t a = 0; a < in->n_species; a++) {
        const jd_guard_species *sa = &in->species[a];
        if (!sa->count) continue;
        out->rayleigh_bound = fmin(out->rayleigh_bound, JD_GUARD_RAYLEIGH_FRACTION *
                                   jd_rayleigh_step(sa->rmin, sa->density, sa->E, sa->nu));
        if (!(v > 0.0)) continue; /* nothing moves: no impact to resolve */
        const side pa = side_of(sa->rmin, sa->density);
        const double kp_a = jd_hertz_prefactor(sa->E, sa->nu, sa->rmin);
        const double share_a = jd_shear_compliance(sa->E, sa->nu);
        for (size_t b = 0; b < in->n_species; b++) {
            const jd_guard_species *sb = &in->species[b];
            if (!sb->count || (b == a && sa->count < 2)) continue;
            const side pb = side_of(sb->rmin, sb->density);
            const double m_eff = pa.m * pb.m / (pa.m + pb.m);
            const double r = sa->rmin * sb->rmin / (sa->rmin + sb->rmin);
            const double share_b = jd_shear_compliance(sb->E, sb->nu);
            const double kn = jd_kn_pair(kp_a, jd_hertz_prefactor(sb->E, sb->nu, sb->rmin));
            const impact c =
                in->normal_law == JD_NORMAL_MEPA
                    ? mepa_impact(in, m_eff, jd_mepa_series(sa->mepa_k1, sb->mepa_k1),
                                  jd_mepa_series(sa->mepa_k2, sb->mepa_k2), r, share_a, share_b)
                    : hertz_impact(in, m_eff, kn, r, share_a, share_b);
            out->contact_time = fmin(out->contact_time, c.time);
            omega2 = fmax(omega2, row_sum(&pa, &pb, c.k));
        }
        if (in->has_walls) {
            /* MEPA: the wall's own stiffness only softens the series, so it is taken as rigid */
            const impact c =
                in->normal_law == JD_NORMAL_MEPA
                    ? mepa_impact(in, pa.m, sa->mepa_k1, sa->mepa_k2, sa->rmin, share_a, 0.0)
                    : hertz_impact(in, pa.m, jd_kn_wall(in->wall_rule, sa->E, sa->nu, sa->rmin),
                                   sa->rmin, share_a, 0.0);
            out->contact_time = fmin(out->contact_time, c.time);
            omega2 = fmax(omega2, row_sum(&pa, NULL, c.k));
        }
    }
    out->contact_bound = out->contact_time / JD_GUARD_STEPS_PER_CONTACT;
    if (omega2 > 0.0) {
        const double z = in->damping_ratio;
        out->omega_max = sqrt(in->coordination * omega2);
        out->coordination_bound = 2.0 / out->omega_max * (sqrt(1.0 + z * z) - z);
    }
    tighten(out, in->dt, out->rayleigh_bound, JD_GUARD_RAYLEIGH);
    tighten(out, in->dt, out->contact_bound, JD_GUARD_CONTACT_TIME);
    tighten(out, in->dt, out->coordination_bound, JD_GUARD_COORDINATION);
    if (in->bond_omega2 > 0.0)
        out->bond_bound = 2.0 * JD_PI / sqrt(in->bond_omega2) / JD_GUARD_STEPS_PER_BOND_PERIOD;
    tighten(out, in->dt, out->bond_bound, JD_GUARD_BOND);
}

/* "BOUND (V s)", with the coordination number where it is that bound. */
static int describe(const jd_guard_input *in, int bound, double value, char *buf, size_t len) {
    if (bound == JD_GUARD_CONTACT_TIME && in->normal_law == JD_NORMAL_MEPA)
        return snprintf(buf, len, "1/%g of the shortest MEPA contact time (%.6g s)",
                        JD_GUARD_STEPS_PER_CONTACT, value);
    if (bound == JD_GUARD_COORDINATION)
        return snprintf(buf, len, "%s %g (%.6g s)", jd_guard_bound_name(bound), in->coordination,
                        value);
    return snprintf(buf, len, "%s (%.6g s)", jd_guard_bound_name(bound), value);
}

int jd_guard_refusal(const jd_guard_input *in, const jd_guard_result *r, const char *hint,
                     char *buf, size_t len) {
    char what[160];
    describe(in, r->violated, r->violated_value, what, sizeof what);
    return snprintf(buf, len, "time step %g s is unsafe: it exceeds %s; largest safe dt = %.6g s. "
                    "%s", in->dt, what, r->safe_dt, hint);
}

int jd_guard_warning(const jd_guard_input *in, const jd_guard_result *r, const char *how,
                     char *buf, size_t len) {
    char what[160];
    describe(in, r->violated, r->violated_value, what, sizeof what);
    return snprintf(buf, len, "warning: time step %g s exceeds %s; running anyway (%s)", in->dt,
                    what, how);
}

double jd_guard_damping_ratio(const jd_guard_species *species, size_t n_species,
                              const double *restitution, int damping_map) {
    double z = 0.0;
    for (size_t a = 0; a < n_species; a++)
        for (size_t b = 0; species[a].count && b < n_species; b++)
            z = fmax(z, jd_gamma_for(damping_map, restitution[a * n_species + b]));
    return z;
}
