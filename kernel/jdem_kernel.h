/*
 * jdem_kernel.h — the contact laws of Jiang (2021), the single source of jdem's physics.
 *
 * Pure C11. No I/O, no allocation, no globals, no engine types: both engines (the standalone
 * stepper `jdem` and the LIGGGHTS plugin) call these functions on the same per-contact state.
 * Every equation and every choice is explained, with its evidence, in docs/model.md; the
 * section numbers below (§) refer to that page.
 *
 * Units are SI throughout: m, s, kg, N, N·m, J, Pa, rad.
 *
 * Conventions for one contact between body a and body b:
 *   - n is the unit normal pointing from a to b. For a wall contact a is the particle and b is the
 *     wall, so n points from the particle centre towards the wall.
 *   - delta > 0 is the overlap (eq. 1: R_a + R_b - |x_b - x_a|; wall: R_a - distance to the wall).
 *   - ra = x_C - x_a and rb = x_C - x_b are the lever arms from the centres to the contact point
 *     x_C (sphere–sphere: x_C = x_a + (R_a - delta/2) n).  For a wall, rb is unused.
 *   - vrel = (v_b + w_b x rb) - (v_a + w_a x ra) is the velocity of b's material point at the
 *     contact relative to a's (eq. 6).  For a wall, v_b is the wall's velocity and w_b = 0.
 *   - The kernel returns the force on b; the force on a is its negative.
 *
 * Hot-path functions are `static inline` here so that each engine inlines them into force loops
 * specialised at compile time for the scene's feature set (the `features` argument is meant to be
 * a compile-time constant at every call site; see JD_F_*).  Set-up functions (damping mappings,
 * time-step bounds) live in jdem_kernel.c.
 */
#ifndef JDEM_KERNEL_H
#define JDEM_KERNEL_H

#include <math.h>
#include <stdint.h>

/* pi as LIGGGHTS spells it (MY_PI), so that masses agree bit for bit. */
#define JD_PI 3.14159265358979323846

#ifdef __cplusplus
extern "C" {
#endif

/* How every law of the kernel is declared: `static JD_ALWAYS_INLINE`.  Each engine's force
 * loops are specialised per law set (jdem_laws.h), and each must get its own copy of the laws
 * with the unused ones compiled away; compilers otherwise keep one out-of-line copy, with the
 * features as a run-time value, for functions this large called from many loops.  The same
 * arithmetic either way (no contraction, no fast-math). */
#if defined(__GNUC__)
#define JD_ALWAYS_INLINE inline __attribute__((always_inline))
#else
#define JD_ALWAYS_INLINE inline
#endif

/* ------------------------------------------------------------------------------------------ */
/* Feature flags: which laws a force loop evaluates.  A scene pays only for what it uses.      */
/* ------------------------------------------------------------------------------------------ */
enum {
    JD_F_DAMPING = 1u << 0,  /* viscous normal/tangential/rolling dashpots and Luding's end rule */
    JD_F_FRICTION = 1u << 1, /* cumulative tangential spring with Coulomb cap (mu > 0)           */
    JD_F_ROLLING = 1u << 2,  /* rolling resistance spring with cap (eta > 0)                     */
    JD_F_MU_R = 1u << 3,     /* mu_R != 1: reduced rotational slip while sliding (eq. 76)        */
    JD_F_ENERGY = 1u << 4,   /* accumulate the dissipated energies in the contact state          */
    JD_F_MINDLIN = 1u << 5,  /* Mindlin's K_t = 8 G* sqrt(R* delta) instead of K_t = K_n (§4.5)   */
    JD_F_MEPA = 1u << 6      /* Del Cid's (2015) MEPA normal law instead of Hertz (§13): virgin
                                loading, elastic un/reloading and adhesion, with plastic history */
};

/* The laws that read jd_contact_geom.r_roll (the rolling radius, which is also R* of Mindlin's
 * K_t and of MEPA's plasticity depth): an engine fills it when the law set has one of these
 * bits. */
#define JD_F_READS_R_STAR (JD_F_ROLLING | JD_F_MINDLIN | JD_F_MEPA)

/* Tangential stiffness rule (§4.5). */
typedef enum {
    JD_KT_JIANG2021 = 0, /* K_t = K_n, the seed's Sec. 2.3.2 (default)                         */
    JD_KT_MINDLIN = 1    /* K_t = 8 G* sqrt(R* delta), G* from both materials as LIGGGHTS'
                            hertz model computes it (jd_shear_compliance)                     */
} jd_tangential_rule;

/* How the stored tangential displacement xi behaves while sliding (§4.4). */
typedef enum {
    JD_XI_COULOMB = 0,      /* xi is reset so that K_t |xi| = mu F_n (Di Maio & Di Renzo 2004) */
    JD_XI_UNCONSTRAINED = 1 /* xi keeps accumulating (the seed's literal Cundall–Strack reading) */
} jd_xi_limit;

/* Sphere–wall normal stiffness rule (§3.3). */
typedef enum {
    JD_WALL_HERTZ = 0,   /* exact Hertz against a rigid plane: E* = E/(1-nu^2), R* = R (default) */
    JD_WALL_JIANG2021 = 1 /* the seed's literal K_n = 2 K_p, which is 1/sqrt(2) of Hertz          */
} jd_wall_rule;

/* The normal law (§3, §13). */
typedef enum {
    JD_NORMAL_HERTZ = 0, /* Jiang's secant Hertz with Luding's end of collision (default)      */
    JD_NORMAL_MEPA = 1   /* Del Cid's (2015) elasto-plastic adhesive law (JD_F_MEPA)            */
} jd_normal_law;

/* Mapping from the input restitution coefficient e to the damping ratio gamma (§7). */
typedef enum {
    JD_DAMP_JIANG2021 = 0, /* gamma = -ln e / sqrt(pi^2 + ln^2 e) (eq. 30), the seed's default   */
    JD_DAMP_EXACT = 1      /* gamma chosen so that a Hertz impact with Luding's end rule
                              rebounds with exactly e (solved once, jd_gamma_exact)             */
} jd_damping_map;

/* ------------------------------------------------------------------------------------------ */
/* MEPA's normal law (Del Cid 2015, Ch. 4.2, as her LIGGGHTS code computes it; docs/model.md    */
/* §13): F = k1 d^n on virgin loading, k2 (d^n - dp^n) on un/reloading, -kadh d^n on the       */
/* adhesive bound, with the plastic overlap dp <= depth R* carried by the contact.             */
/* ------------------------------------------------------------------------------------------ */
typedef struct jd_mepa_coeffs {
    double k1;      /* virgin-loading stiffness of the pair                               [N/m^n] */
    double k2;      /* unloading/reloading stiffness of the pair, > k1                    [N/m^n] */
    double kadh;    /* adhesive stiffness of the pair, >= 0                               [N/m^n] */
    double n;       /* the law's exponent (1: linear; Del Cid's runs: 3/2)                [-]     */
    double depth;   /* the plastic overlap's cap dp_max as a fraction of R* (Del Cid: 0.1) [-]    */
    /* derived by jd_mepa_coeffs_of, so that a contact evaluates no power but d^n and dp^n:    */
    double x_virgin; /* dp/d on the virgin branch, ((k2 - k1)/k2)^(1/n)                    [-]    */
    double x_adh;    /* dp/d on the adhesive branch, ((k2 + kadh)/k2)^(1/n)                [-]    */
    double x_end;    /* the virgin branch's end as a multiple of dp_max, (k2/(k2 - k1))^(1/n) [-] */
} jd_mepa_coeffs;

/* MEPA's pair stiffness from the two materials' [N/m^n]: Del Cid's series combination
 * k_a k_b/(k_a + k_b), 0 for two zeros (her code's 0/0; spec §7.12). */
static inline double jd_mepa_series(double ka, double kb) {
    return ka + kb > 0.0 ? ka * kb / (ka + kb) : 0.0;
}

/* A material's MEPA stiffnesses are valid when k2 > k1 > 0 and kadh >= 0 (k1 = k2 would divide
 * by zero at the virgin branch's end); both engines' readers refuse the others. */
static inline int jd_mepa_material_valid(double k1, double k2, double kadh) {
    return k1 > 0.0 && k2 > k1 && kadh >= 0.0;
}

/* MEPA's defaults: Del Cid's exponent in her production runs, and her code's plasticity depth
 * dmax = 0.1 R*. */
#define JD_MEPA_DEFAULT_EXPONENT 1.5
#define JD_MEPA_DEFAULT_DEPTH 0.1

/* ------------------------------------------------------------------------------------------ */
/* Coefficients of one interaction (species pair, or species–wall), fixed for a run.           */
/* ------------------------------------------------------------------------------------------ */
typedef struct jd_pair_coeffs {
    double gamma;  /* damping ratio, dimensionless, >= 0 (0: no damping)                          */
    double mu;     /* Coulomb friction coefficient, dimensionless, >= 0                           */
    double eta;    /* rolling friction coefficient, dimensionless (cap = eta * r_roll * F_n)      */
    double mu_r;   /* rotational-slip reduction factor while sliding, in [0, 1] (eq. 76)          */
    int xi_limit;  /* jd_xi_limit                                                                  */
    double g_star; /* effective shear modulus G* of Mindlin's K_t (JD_F_MINDLIN) [Pa]: of the pair
                      of materials, or, in the copy jd_wall_coeffs makes, of the particle's
                      material against a rigid wall                                              */
    double g_wall; /* G* of the first material against a rigid wall [Pa]                         */
    jd_mepa_coeffs mepa; /* MEPA's normal law (JD_F_MEPA; all zero otherwise)                     */
} jd_pair_coeffs;

/* The coefficients of a sphere–wall contact from its entry (particle material, wall material):
 * walls are rigid in both wall rules (jd_kn_wall takes the particle's E and nu only), so
 * Mindlin's G* is the particle's against a rigid body. */
static inline jd_pair_coeffs jd_wall_coeffs(const jd_pair_coeffs *c) {
    jd_pair_coeffs w = *c;
    w.g_star = c->g_wall;
    return w;
}

/* ------------------------------------------------------------------------------------------ */
/* Geometry and kinematics of one contact at the current step (filled by the engine).          */
/* ------------------------------------------------------------------------------------------ */
typedef struct jd_contact_geom {
    double n[3];   /* unit normal a -> b                                                   [-]    */
    double delta;  /* overlap, > 0                                                         [m]    */
    double ra[3];  /* x_C - x_a                                                            [m]    */
    double rb[3];  /* x_C - x_b (ignored for walls)                                        [m]    */
    double k_n;    /* Hertz prefactor: K_n = k_n sqrt(delta), F_el = k_n delta^1.5        [N/m^1.5] */
    double m_eff;  /* effective mass m_a m_b/(m_a+m_b); wall: m_a                          [kg]   */
    double i_eff;  /* effective moment of inertia I_a I_b/(I_a+I_b); wall: I_a             [kg m^2] */
    double r_roll; /* rolling radius R_a R_b/(R_a+R_b); wall: R_a; also R* of Mindlin's K_t
                      (read only with JD_F_READS_R_STAR)                                   [m]    */
} jd_contact_geom;

typedef struct jd_kinematics {
    double va[3], wa[3]; /* velocity [m/s] and angular velocity [rad/s] of a                     */
    double vb[3], wb[3]; /* of b (wall: its velocity, and zero angular velocity)                 */
} jd_kinematics;

/* ------------------------------------------------------------------------------------------ */
/* Per-contact history.  A plain array of doubles so that LIGGGHTS' contact-history machinery  */
/* can store and migrate it (jd_contact_state_newton lists which entries flip sign i<->j).     */
/* Zero-initialised state means "contact just detected" (t_0 of eq. 9).                        */
/* ------------------------------------------------------------------------------------------ */
typedef struct jd_contact_state {
    double xi[3];     /* cumulative tangential displacement, kept in the tangent plane     [m]    */
    double flags;     /* phase: 0 (sticking, or not yet touched), JD_S_ENDED or JD_S_SLIDING [-]   */
    /* Energy bookkeeping (JD_F_ENERGY), second order in dt like the velocity-Verlet integrator:
     * the work of a step is the average of the forces at its two ends times the displacement. */
    double f_prev[3]; /* force on b at the previous evaluation                             [N]    */
    double fd_prev;   /* normal dashpot force C_n d(delta)/dt at the previous evaluation   [N]    */
    double u_prev;    /* energy stored in the contact's springs at the previous evaluation [J]    */
    double e_damp;    /* energy dissipated by the dashpots and lost at Luding's end       [J]    */
    double e_fric;    /* energy dissipated by the tangential and rolling springs/sliders  [J]    */
    /* the torques of f_prev about the centres at the previous evaluation, T_a = r_a x (-f),
     * T_b = r_b x f (rolling moment apart), as their sum and difference so that a <-> b only
     * flips the difference's sign: the lever arms turn with the contact, and the previous
     * force works through the levers it was applied with                                     */
    double ts_prev[3]; /* T_a + T_b                                                         [N m]  */
    double td_prev[3]; /* T_b - T_a                                                         [N m]  */
    /* MEPA's history (JD_F_MEPA), last so that the records of the other laws keep their length */
    double dp;         /* plastic overlap, in [0, depth R*]                                 [m]    */
} jd_contact_state;

/* Phases of a contact (jd_contact_state.flags; one at a time, compared as doubles). */
enum { JD_S_ENDED = 1, JD_S_SLIDING = 2 };

#define JD_CONTACT_STATE_LEN 18  /* doubles in jd_contact_state */
#define JD_CONTACT_ENERGY_LEN 17 /* the leading ones, up to td_prev: all but MEPA's */
/* 1 where the entry is a vector component that changes sign when a and b swap, else 0. */
static const int jd_contact_state_newton[JD_CONTACT_STATE_LEN] = {1, 1, 1, 0, 1, 1, 1, 0, 0,
                                                                  0, 0, 0, 0, 0, 1, 1, 1, 0};

/* Rolling history, only allocated by scenes with rolling resistance. */
typedef struct jd_rolling_state {
    double theta[3];  /* cumulative relative rotation (w_b - w_a) dt                      [rad]  */
    double m_prev[3]; /* rolling moment on b at the previous evaluation (JD_F_ENERGY)     [N m]  */
} jd_rolling_state;

#define JD_ROLLING_STATE_LEN 6
static const int jd_rolling_state_newton[JD_ROLLING_STATE_LEN] = {1, 1, 1, 1, 1, 1};

/* What one evaluation returns. */
typedef struct jd_contact_result {
    double f[3];  /* force on b (on a: -f)                                                 [N]    */
    double ta[3]; /* torque on a about its centre                                          [N m]  */
    double tb[3]; /* torque on b about its centre (walls: ignore)                          [N m]  */
    double fn;    /* normal force, >= 0 but for MEPA's adhesion (JD_F_MEPA)                [N]    */
} jd_contact_result;

/* ------------------------------------------------------------------------------------------ */
/* Small vector helpers (internal).                                                            */
/* ------------------------------------------------------------------------------------------ */
static inline double jd_dot(const double a[3], const double b[3]) {
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}
static inline void jd_cross(const double a[3], const double b[3], double out[3]) {
    out[0] = a[1] * b[2] - a[2] * b[1];
    out[1] = a[2] * b[0] - a[0] * b[2];
    out[2] = a[0] * b[1] - a[1] * b[0];
}

/* ------------------------------------------------------------------------------------------ */
/* Material and stiffness rules (§3).                                                          */
/* ------------------------------------------------------------------------------------------ */

/* Per-particle Hertz prefactor of eq. (4): k_p = 2 G sqrt(2R) / (3 (1 - nu)), G = E/(2(1+nu)),
 * so that K_p = k_p sqrt(delta).  E [Pa], nu [-], R [m] -> [N/m^1.5]. */
static inline double jd_hertz_prefactor(double E, double nu, double R) {
    const double G = E / (2.0 * (1.0 + nu));
    return 2.0 * G * sqrt(2.0 * R) / (3.0 * (1.0 - nu));
}

/* Sphere–sphere rule of eq. (5): the harmonic mean 2 k_a k_b/(k_a + k_b) [N/m^1.5]. */
static inline double jd_kn_pair(double kp_a, double kp_b) {
    return 2.0 * kp_a * kp_b / (kp_a + kp_b);
}

/* Sphere–wall rule (§3.3): exact Hertz (4/3) E/(1-nu^2) sqrt(R), or the seed's 2 k_p [N/m^1.5]. */
static inline double jd_kn_wall(int wall_rule, double E, double nu, double R) {
    if (wall_rule == JD_WALL_JIANG2021) return 2.0 * jd_hertz_prefactor(E, nu, R);
    return 4.0 / 3.0 * E / (1.0 - nu * nu) * sqrt(R);
}

/* One material's share of Mindlin's 1/G*: 2 (2 - nu)(1 + nu)/E [1/Pa], as LIGGGHTS' Geff
 * (1/G* = the sum over both materials; a rigid body's share is 0). */
static inline double jd_shear_compliance(double E, double nu) {
    return 2.0 * (2.0 - nu) * (1.0 + nu) / E;
}

/* Mass and moment of inertia of a solid sphere, written exactly as LIGGGHTS computes them
 * (`set density`: 4 pi/3 r^3 rho; fix nve/sphere: I = 0.4 m r^2) so that the engines agree to
 * round-off. */
static inline double jd_sphere_mass(double R, double rho) {
    return 4.0 * JD_PI / 3.0 * R * R * R * rho;
}
static inline double jd_sphere_inertia(double m, double R) { return 0.4 * m * R * R; }

/* ------------------------------------------------------------------------------------------ */
/* Set-up functions (jdem_kernel.c).                                                           */
/* ------------------------------------------------------------------------------------------ */

/* Eq. (30): gamma = -ln e / sqrt(pi^2 + ln^2 e), e in (0, 1]. */
double jd_gamma_jiang2021(double e);

/* Restitution coefficient produced by damping ratio gamma for a Hertz contact with the seed's
 * C_n = 2 gamma sqrt(m K_n) and Luding's end rule, in the limit dt -> 0.  It depends on gamma
 * only (independent of mass, stiffness and speed).  Integrates the dimensionless equation
 * x'' = -x^1.5 - 2 gamma x^0.25 x' with classical RK4 (relative accuracy about 1e-7). */
double jd_restitution_for_gamma(double gamma);

/* Inverse of jd_restitution_for_gamma: the gamma that rebounds with exactly e, e in (0, 1].
 * Returns 0 for e >= 1. */
double jd_gamma_exact(double e);

/* gamma for a mapping (jd_damping_map) and input restitution e. */
double jd_gamma_for(int damping_map, double e);

/* Rayleigh time step of eq. (34): pi R sqrt(rho/G) / (0.1631 nu + 0.876605) [s]. */
double jd_rayleigh_step(double R, double rho, double E, double nu);

/* Duration of an undamped Hertz impact, F = k_n delta^1.5, effective mass m_eff [kg],
 * approach speed v [m/s]: t_c = tau (m/k)^(2/5) v^(-1/5), tau = 3.2181 (docs/model.md §8) [s]. */
double jd_hertz_contact_time(double m_eff, double k_n, double v);

/* Peak overlap [m] and peak force [N] of the same impact. */
double jd_hertz_peak_overlap(double m_eff, double k_n, double v);
double jd_hertz_peak_force(double m_eff, double k_n, double v);

/* A MEPA impact (jd_law_mepa, undamped, no adhesion) of effective mass m_eff [kg] at speed
 * v [m/s] with pair stiffnesses k1 < k2 [N/m^n] and exponent n: its duration [s] (the virgin
 * loading exactly, the unloading at the stiffest tangent of its branch) and *peak_overlap [m]. */
double jd_mepa_impact_time(double m_eff, double k1, double k2, double n, double v,
                           double *peak_overlap);

/* ------------------------------------------------------------------------------------------ */
/* The contact laws.                                                                           */
/* ------------------------------------------------------------------------------------------ */

/* Reset the history when the bodies separate (delta <= 0): the next overlap is a new contact.
 * The dissipated-energy accumulators are kept (they are cumulative per pair); engines that
 * drop the pair read them first.  Nothing is booked: the little energy still stored at the last
 * contact step returns to the bodies during the separating step. */
static inline void jd_contact_separate(jd_contact_state *s, jd_rolling_state *r) {
    for (int d = 0; d < 3; d++) s->xi[d] = s->f_prev[d] = s->ts_prev[d] = s->td_prev[d] = 0.0;
    s->flags = s->fd_prev = s->u_prev = s->dp = 0.0;
    if (r)
        for (int d = 0; d < 3; d++) r->theta[d] = r->m_prev[d] = 0.0;
}

/* Keep a stored tangential vector in the current tangent plane: remove its normal component and
 * rescale it to its previous length, so that a turning contact frame neither creates nor destroys
 * spring energy (§4.3).  A zero vector stays as it is; one that lies along n is projected to zero
 * length and not rescaled.  Written with selects instead of branches (see jd_contact). */
static JD_ALWAYS_INLINE void jd_rotate_into_plane(double v[3], const double n[3]) {
    const double len2 = jd_dot(v, v);
    const double vn = jd_dot(v, n);
    const double p[3] = {v[0] - vn * n[0], v[1] - vn * n[1], v[2] - vn * n[2]};
    const double new2 = jd_dot(p, p);
    const int rescale = new2 > 0.0;
    const double s = sqrt(len2 / (rescale ? new2 : 1.0));
    for (int d = 0; d < 3; d++) v[d] = len2 == 0.0 ? v[d] : (rescale ? p[d] * s : p[d]);
}

/* Normal law (§3, §7, §8): F_n = K_n delta + C_n d(delta)/dt with K_n = k_n sqrt(delta) and
 * C_n = 2 gamma sqrt(m_eff K_n).  ddelta is the overlap rate [m/s]; damped = 0 means gamma = 0
 * (C_n = 0 without evaluating the square root; the same value).  Returns the unclamped force [N]
 * (it is negative only while unloading with strong damping: Luding's end of collision); *c_n
 * receives C_n [N s/m] and *k_sec the secant stiffness K_n [N/m]. */
static inline double jd_normal_force(double k_n, double delta, double ddelta, int damped,
                                     double gamma, double m_eff, double *k_sec, double *c_n) {
    const double K = k_n * sqrt(delta);
    const double C = damped ? 2.0 * gamma * sqrt(m_eff * K) : 0.0;
    *k_sec = K;
    *c_n = C;
    return K * delta + C * ddelta;
}

/* Elastic energy of the normal spring: integral of k_n d^1.5 = 0.4 k_n delta^2.5 [J]. */
static inline double jd_normal_energy(double k_n, double delta) {
    return 0.4 * k_n * delta * delta * sqrt(delta);
}

/* Coulomb-capped spring–dashpot of eqs. (9)–(11), (31) on one stored vector (tangential xi with
 * stiffness K and dashpot C, or rolling theta with K_r, C_r).  rate is the relative velocity
 * (vt or w_rel), cap the magnitude limit (mu F_n, or eta r F_n).  On return out holds the force
 * (or moment) on b; the return value is 1 when the cap was active (sliding).  With
 * JD_XI_COULOMB the stored vector is reset to -out/K while sliding (the dashpot is off while
 * sliding, as the seed states), so K |stored| never exceeds the cap.  Written with selects. */
static JD_ALWAYS_INLINE int jd_capped_spring(double stored[3], const double rate[3], double K,
                                             double C, double cap, double dt, int xi_limit,
                                             double out[3]) {
    for (int d = 0; d < 3; d++) {
        stored[d] += rate[d] * dt;
        out[d] = -K * stored[d] - C * rate[d];
    }
    const double m2 = jd_dot(out, out);
    const int sliding = !(m2 <= cap * cap);
    const double s = cap / sqrt(sliding ? m2 : 1.0);
    const int reset = sliding & (xi_limit == JD_XI_COULOMB) & (K > 0.0);
    const double K_div = K > 0.0 ? K : 1.0;
    for (int d = 0; d < 3; d++) {
        out[d] = sliding ? out[d] * s : out[d];
        stored[d] = reset ? -out[d] / K_div : stored[d];
    }
    return sliding;
}

/* ------------------------------------------------------------------------------------------ */
/* jd_contact as a composition of small laws (docs/adding_a_law.md).  Each takes the part of   */
/* the step it needs and is unit-tested alone (tests/unit/test_laws.c); jd_contact calls them  */
/* in the order of the reference algorithm (docs/model.md §9), so that every value is the same */
/* expression on the same operands as in one body.                                             */
/* ------------------------------------------------------------------------------------------ */

/* The relative motion at the contact point (eq. 6). */
typedef struct jd_contact_motion {
    double wxa[3], wxb[3]; /* w_a x r_a and w_b x r_b                                  [m/s]  */
    double vrel[3];        /* velocity of b's material point relative to a's            [m/s]  */
    double vn;             /* vrel . n                                                  [m/s]  */
    double ddelta;         /* overlap rate -vn                                          [m/s]  */
    double wrel[3];        /* w_b - w_a with JD_F_ROLLING, else zero                   [rad/s] */
} jd_contact_motion;

static JD_ALWAYS_INLINE void jd_contact_kinematics(const unsigned features, const jd_contact_geom *g,
                                            const jd_kinematics *k, jd_contact_motion *m) {
    jd_cross(k->wa, g->ra, m->wxa);
    jd_cross(k->wb, g->rb, m->wxb);
    for (int d = 0; d < 3; d++) m->vrel[d] = (k->vb[d] + m->wxb[d]) - (k->va[d] + m->wxa[d]);
    m->vn = jd_dot(m->vrel, g->n);
    m->ddelta = -m->vn;
    for (int d = 0; d < 3; d++) m->wrel[d] = 0.0;
    if (features & JD_F_ROLLING)
        for (int d = 0; d < 3; d++) m->wrel[d] = k->wb[d] - k->wa[d];
}

/* The history one evaluation starts from, and the phase it is in.  An ended contact stays
 * ended while the bodies keep separating; a new approach while still overlapping begins a new
 * contact (the history as jd_contact_separate leaves it). */
typedef struct jd_contact_step {
    int still_ended;     /* ended before, and the bodies are still separating          [-]    */
    int restart;         /* ended before, and approaching again: a new contact          [-]    */
    double flags;        /* phase the step starts from (jd_contact_state.flags)          [-]    */
    double xi[3];        /* tangential displacement, updated by jd_law_tangential        [m]    */
    double theta[3];     /* rolling rotation, updated by jd_law_rolling (JD_F_ROLLING)   [rad]  */
    double dp;           /* MEPA's plastic overlap before the step (JD_F_MEPA; else zero) [m]   */
    /* the energy bookkeeping's starting values (JD_F_ENERGY; else zero) */
    double f_prev[3], m_prev[3];          /* force [N] and rolling moment [N m] of the last step */
    double ts_prev[3], td_prev[3];        /* its lever torques' sum and difference [N m]         */
    double fd_prev, u_prev, e_damp, e_fric; /* dashpot force [N], stored energy, totals [J]      */
} jd_contact_step;

static JD_ALWAYS_INLINE void jd_contact_begin(const unsigned features, const jd_contact_geom *g,
                                       const jd_contact_state *s, const jd_rolling_state *r,
                                       double ddelta, jd_contact_step *h) {
    const int rolling = (features & JD_F_ROLLING) != 0;
    const int was_ended = s->flags == (double)JD_S_ENDED;
    h->still_ended = was_ended & (ddelta <= 0.0);
    h->restart = was_ended & !h->still_ended;
    const int restart = h->restart;
    h->flags = restart ? 0.0 : s->flags;
    for (int d = 0; d < 3; d++) h->xi[d] = restart ? 0.0 : s->xi[d];
    for (int d = 0; d < 3; d++) h->theta[d] = 0.0;
    if (rolling)
        for (int d = 0; d < 3; d++) h->theta[d] = restart ? 0.0 : r->theta[d];
    h->dp = (features & JD_F_MEPA) ? s->dp : 0.0; /* a MEPA contact never ends: no restart */
    for (int d = 0; d < 3; d++) h->f_prev[d] = h->m_prev[d] = h->ts_prev[d] = h->td_prev[d] = 0.0;
    h->fd_prev = h->u_prev = h->e_damp = h->e_fric = 0.0;
    if (features & JD_F_ENERGY) {
        for (int d = 0; d < 3; d++) {
            h->f_prev[d] = restart ? 0.0 : s->f_prev[d];
            h->ts_prev[d] = restart ? 0.0 : s->ts_prev[d];
            h->td_prev[d] = restart ? 0.0 : s->td_prev[d];
            if (rolling) h->m_prev[d] = restart ? 0.0 : r->m_prev[d];
        }
        h->fd_prev = restart ? 0.0 : s->fd_prev;
        /* The restarted contact's normal spring is already compressed.  That energy was booked as
         * damping at the end of the collision and is stored again now: take it back from
         * damping, so that the friction term does not see it. */
        const double u_spring = jd_normal_energy(g->k_n, g->delta);
        h->u_prev = restart ? u_spring : s->u_prev;
        h->e_damp = restart ? s->e_damp - u_spring : s->e_damp;
        h->e_fric = s->e_fric;
    }
}

/* What the normal law gives the other laws. */
typedef struct jd_normal {
    double fn;   /* normal force, unclamped (jd_normal_force)                          [N]    */
    double fcap; /* the normal force the Coulomb and rolling caps scale: fn, or |fn| with
                    MEPA (Del Cid's code: an adhesive contact resists sliding too)      [N]    */
    double Kn;   /* secant stiffness k_n sqrt(delta); MEPA: the virgin secant k1 d^(n-1) [N/m] */
    double Cn;   /* dashpot coefficient 2 gamma sqrt(m_eff K_n); MEPA: with k2 d^(n-1)  [N s/m] */
    int ends;    /* Luding's end of collision this step (never with MEPA)               [-]    */
    int carries; /* the contact carries force after this step                           [-]    */
    double u;         /* energy stored in the normal spring (JD_F_ENERGY; else zero): Hertz's
                         jd_normal_energy, MEPA's jd_mepa_energy                         [J]    */
    /* MEPA only (JD_F_MEPA; else zero) */
    double dp;        /* plastic overlap after the step                                 [m]    */
    double e_plastic; /* energy the plastic overlap's change dissipated this step       [J]    */
} jd_normal;

/* The energy stored in a MEPA contact [J]: the work of its un/reloading branch
 * k2 (x^n - dp^n) from the branch's zero, x = dp, to x = delta, which is >= 0 on both sides;
 * dn = delta^n, dpn = dp^n. */
static JD_ALWAYS_INLINE double jd_mepa_energy(const jd_mepa_coeffs *c, double delta, double dn,
                                              double dp, double dpn) {
    return c->k2 * ((delta * dn - dp * dpn) / (c->n + 1.0) - dpn * (delta - dp));
}

/* The powers a MEPA step computes once: delta^n, the plastic overlap before the step (capped)
 * and after it, and their n-th powers. */
typedef struct jd_mepa_step {
    double dn;       /* delta^n                                              [m^n] */
    double up, upn;  /* dp before the step, min(dp_old, dp_max), and up^n   [m], [m^n] */
    double dp, dpn;  /* dp after the step and dp^n                           [m], [m^n] */
} jd_mepa_step;

/* MEPA's hysteretic force [N] (Del Cid 2015 §4.3.1; her LudingForce, docs/model.md §13) at
 * overlap delta > 0 [m], the overlap rate ddelta [m/s] choosing loading (>= 0) or unloading, the
 * plasticity radius r_star [m] and the plastic overlap dp_old [m] before the step.  On the
 * virgin bound (a new contact starts there, k2 > k1) dp follows x_virgin delta, and past the
 * branch's end x_end dp_max the contact reloads along k2 with dp = dp_max; below the adhesive
 * bound while unloading dp follows x_adh delta; inside the bounds dp stays.  *s receives the
 * step's powers and overlaps.  Written with selects. */
static JD_ALWAYS_INLINE double jd_mepa_force(const jd_mepa_coeffs *c, double delta, double ddelta,
                                             double r_star, double dp_old, jd_mepa_step *s) {
    const double dp_max = c->depth * r_star;
    s->up = dp_old < dp_max ? dp_old : dp_max;
    s->dn = pow(delta, c->n);
    s->upn = pow(s->up, c->n);
    const double f1 = c->k1 * s->dn, f2 = c->k2 * (s->dn - s->upn), f3 = -c->kadh * s->dn;
    const int loading = ddelta >= 0.0;
    const int virgin = loading & (f2 - f1 > 0.0);
    const int beyond = delta > c->x_end * dp_max;
    const int adhesive = !loading & (f2 - f3 < 0.0);
    double q = virgin ? (beyond ? dp_max : c->x_virgin * delta) : (adhesive ? c->x_adh * delta : s->up);
    q = q < dp_max ? q : dp_max;
    s->dp = q > 0.0 ? q : 0.0;
    s->dpn = pow(s->dp, c->n);
    return (virgin & !beyond) ? f1 : (adhesive ? f3 : c->k2 * (s->dn - s->dpn));
}

/* MEPA's normal law (JD_F_MEPA, §13): the hysteretic force plus the dashpot C_n ddelta with
 * C_n = 2 gamma sqrt(m_eff k2 delta^(n-1)) (with JD_F_DAMPING).  The contact never ends while
 * the bodies overlap: it carries tension on the adhesive bound, and the engines end it when the
 * overlap does (jd_contact_separate).  With JD_F_ENERGY also the stored energy and what the
 * change of dp dissipated during the step of length dt [s]: the stored energy before and after
 * the change at the step's mid-point overlap delta - ddelta dt/2, or 0 (exact for n = 1, second
 * order otherwise, like the rest of the accounts). */
static JD_ALWAYS_INLINE void jd_law_mepa(const unsigned features, const jd_pair_coeffs *c,
                                         const jd_contact_geom *g, double ddelta, double dp_old,
                                         double dt, jd_normal *nl) {
    const jd_mepa_coeffs *mc = &c->mepa;
    jd_mepa_step s;
    const double f = jd_mepa_force(mc, g->delta, ddelta, g->r_roll, dp_old, &s);
    nl->dp = s.dp;
    nl->Kn = mc->k1 * s.dn / g->delta;
    nl->Cn = (features & JD_F_DAMPING) ? 2.0 * c->gamma * sqrt(g->m_eff * mc->k2 * s.dn / g->delta)
                                       : 0.0;
    nl->fn = f + nl->Cn * ddelta;
    nl->fcap = fabs(nl->fn);
    nl->ends = 0;
    nl->carries = 1;
    nl->u = nl->e_plastic = 0.0;
    if (features & JD_F_ENERGY) {
        nl->u = jd_mepa_energy(mc, g->delta, s.dn, s.dp, s.dpn);
        /* (not below zero: a contact that began less than half a step ago) */
        const double mid = fmax(g->delta - 0.5 * ddelta * dt, 0.0), mid_n = pow(mid, mc->n);
        nl->e_plastic = jd_mepa_energy(mc, mid, mid_n, s.up, s.upn) -
                        jd_mepa_energy(mc, mid, mid_n, s.dp, s.dpn);
    }
}

/* Normal law with damping and Luding's end of contact (§3, §7, §8): with JD_F_DAMPING the
 * contact ends, never pulling, once the total normal force reaches zero while unloading.  With
 * JD_F_MEPA, MEPA's law instead (jd_law_mepa); dp_old is its plastic overlap, dt the step. */
static JD_ALWAYS_INLINE void jd_law_normal(const unsigned features, const jd_pair_coeffs *c,
                                    const jd_contact_geom *g, double ddelta, int still_ended,
                                    double dp_old, double dt, jd_normal *nl) {
    if (features & JD_F_MEPA) {
        jd_law_mepa(features, c, g, ddelta, dp_old, dt, nl);
        return;
    }
    const int damping = (features & JD_F_DAMPING) != 0;
    nl->fn = jd_normal_force(g->k_n, g->delta, ddelta, damping, damping ? c->gamma : 0.0, g->m_eff,
                             &nl->Kn, &nl->Cn);
    nl->fcap = nl->fn;
    nl->ends = damping ? !still_ended & (nl->fn <= 0.0) : 0;
    nl->carries = !still_ended & !nl->ends;
    nl->dp = nl->e_plastic = 0.0;
    nl->u = (features & JD_F_ENERGY) ? jd_normal_energy(g->k_n, g->delta) : 0.0;
}

/* Tangential stiffness K_t [N/m] (§4.5): the seed's K_t = K_n (Sec. 2.3.2), or with
 * JD_F_MINDLIN Mindlin's K_t = 8 G* sqrt(R* delta) (c->g_star, R* = g->r_roll). */
static JD_ALWAYS_INLINE double jd_tangential_stiffness(const unsigned features,
                                                       const jd_pair_coeffs *c,
                                                       const jd_contact_geom *g,
                                                       const jd_normal *nl) {
    if (features & JD_F_MINDLIN) return 8.0 * c->g_star * sqrt(g->r_roll * g->delta);
    return nl->Kn;
}

/* Tangential dashpot C_t = 2 gamma sqrt(m_eff K_t) (eq. 29) [N s/m]: C_n itself when K_t = K_n
 * (the same expression; not with MEPA, whose C_n is k2's), zero without JD_F_DAMPING. */
static JD_ALWAYS_INLINE double jd_tangential_damping(const unsigned features,
                                                     const jd_pair_coeffs *c,
                                                     const jd_contact_geom *g,
                                                     const jd_normal *nl, double Kt) {
    if (!(features & (JD_F_MINDLIN | JD_F_MEPA))) return nl->Cn;
    return (features & JD_F_DAMPING) ? 2.0 * c->gamma * sqrt(g->m_eff * Kt) : 0.0;
}

/* Tangential law (§4): the cumulative spring on h->xi, turned into the tangent plane, with its
 * dashpot and Coulomb cap mu F_n; with JD_F_MU_R only mu_R of the rotational slip acts on the
 * spring while sliding (eq. 76).  Adds the tangential force to f, sets h->flags (sliding or
 * sticking); with JD_F_ENERGY adds the spring's stored energy to *u and the dashpot's
 * dissipation of the step to *dash. */
static JD_ALWAYS_INLINE void jd_law_tangential(const unsigned features, const jd_pair_coeffs *c,
                                        const jd_contact_geom *g, const jd_contact_motion *m,
                                        const jd_normal *nl, double dt, jd_contact_step *h,
                                        double f[3], double *u, double *dash) {
    double vt[3], vt_law[3];
    for (int d = 0; d < 3; d++) vt_law[d] = vt[d] = m->vrel[d] - m->vn * g->n[d];
    if (features & JD_F_MU_R) {
        const int was_sliding = h->flags == (double)JD_S_SLIDING;
        const double red = 1.0 - c->mu_r;
        double wr[3];
        for (int d = 0; d < 3; d++) wr[d] = m->wxb[d] - m->wxa[d];
        const double wrn = jd_dot(wr, g->n);
        for (int d = 0; d < 3; d++)
            vt_law[d] = was_sliding ? vt_law[d] - red * (wr[d] - wrn * g->n[d]) : vt_law[d];
    }
    jd_rotate_into_plane(h->xi, g->n);
    const double Kt = jd_tangential_stiffness(features, c, g, nl);
    const double Ct = jd_tangential_damping(features, c, g, nl, Kt);
    double ft[3];
    const int sliding = jd_capped_spring(h->xi, vt_law, Kt, Ct, c->mu * nl->fcap, dt, c->xi_limit, ft);
    h->flags = sliding ? (double)JD_S_SLIDING : 0.0;
    for (int d = 0; d < 3; d++) f[d] += ft[d];
    if (features & JD_F_ENERGY) {
        /* the spring carries the whole force while sliding, -K_t xi while sticking */
        double fs[3];
        for (int d = 0; d < 3; d++) fs[d] = sliding ? ft[d] : -Kt * h->xi[d];
        *u += Kt > 0.0 ? 0.5 * jd_dot(fs, fs) / (Kt > 0.0 ? Kt : 1.0) : 0.0;
        /* the dashpot acts on vt_law, and only while sticking */
        *dash = sliding ? *dash : *dash + Ct * jd_dot(vt_law, vt) * dt;
    }
}

/* Rolling law (§5): the spring on h->theta with K_r = K_t r^2, its dashpot (eq. 32) and the cap
 * eta r F_n.  The moment on b goes to m_roll; with JD_F_ENERGY the stored energy is added to *u
 * and the dashpot's dissipation to *dash. */
static JD_ALWAYS_INLINE void jd_law_rolling(const unsigned features, const jd_pair_coeffs *c,
                                     const jd_contact_geom *g, const jd_contact_motion *m,
                                     const jd_normal *nl, double dt, jd_contact_step *h,
                                     double m_roll[3], double *u, double *dash) {
    /* K_r = K_t r^2 with the seed's K_t = K_n, whatever the tangential rule (§4.5) */
    const double Kr = nl->Kn * g->r_roll * g->r_roll;
    const double Cr = (features & JD_F_DAMPING) ? 2.0 * c->gamma * sqrt(g->i_eff * Kr) : 0.0;
    const int rsl = jd_capped_spring(h->theta, m->wrel, Kr, Cr, c->eta * g->r_roll * nl->fcap, dt,
                                     c->xi_limit, m_roll);
    if (features & JD_F_ENERGY) {
        double ms[3];
        for (int d = 0; d < 3; d++) ms[d] = rsl ? m_roll[d] : -Kr * h->theta[d];
        *u += Kr > 0.0 ? 0.5 * jd_dot(ms, ms) / (Kr > 0.0 ? Kr : 1.0) : 0.0;
        *dash = rsl ? *dash : *dash + Cr * jd_dot(m->wrel, m->wrel) * dt;
    }
}

/* What the energy bookkeeping books for one step. */
typedef struct jd_contact_energy {
    double fd;     /* normal dashpot force C_n d(delta)/dt at this evaluation          [N]    */
    double e_damp; /* dissipated by the dashpots (and at Luding's end) so far          [J]    */
    double e_fric; /* dissipated by the sliders so far                                 [J]    */
} jd_contact_energy;

/* The torques of a force f on b (on a: -f) about the two centres through the lever arms r_a, r_b
 * (contact or bond point minus centre), T_a = r_a x (-f) and T_b = r_b x f [N m]: what the bodies
 * get (before a couple is added) and what the energy records keep for the next step. */
typedef struct jd_lever_torques {
    double ta[3], tb[3];
} jd_lever_torques;

static JD_ALWAYS_INLINE void jd_lever_torques_of(const double ra[3], const double rb[3],
                                                 const double f[3], jd_lever_torques *t) {
    const double fa[3] = {-f[0], -f[1], -f[2]};
    jd_cross(ra, fa, t->ta);
    jd_cross(rb, f, t->tb);
}

/* The power now [W] of a load applied at the previous step (a contact's or a bond's): its force
 * f_prev on b through the centres' velocities, and its torques about the centres (kept as their
 * sum ts_prev and difference td_prev, with the lever arms and couple they were applied with, not
 * today's) through the spins: f.(v_b - v_a) + T_a.w_a + T_b.w_b (docs/model.md §7, §9.3). */
static JD_ALWAYS_INLINE double jd_previous_power(const double f_prev[3], const double ts_prev[3],
                                                 const double td_prev[3], const jd_kinematics *k) {
    double w = 0.0;
    for (int d = 0; d < 3; d++)
        w += f_prev[d] * (k->vb[d] - k->va[d]) +
             0.5 * (ts_prev[d] * (k->wa[d] + k->wb[d]) + td_prev[d] * (k->wb[d] - k->wa[d]));
    return w;
}

/* Energy bookkeeping (JD_F_ENERGY), second order in dt like the velocity-Verlet integrator.
 * Velocity Verlet changes the bodies' kinetic energy by the average of the forces at the two
 * ends of a step times its displacement (exactly, up to terms that cancel over a collision), so
 * the contact books the same: work W on the bodies this step, and what it dissipated is -W less
 * the change of its stored energy.  The normal dashpot's share is the same trapezoid on its own
 * force; the remainder is the sliders' (friction), or the dashpot's too when there are no
 * sliders.  f, m_roll: this step's force and rolling moment on b; u_new: the energy stored now;
 * dash: the tangential and rolling dashpots' share so far. */
static JD_ALWAYS_INLINE void jd_law_energy(const unsigned features, const jd_kinematics *k,
                                    const jd_contact_motion *m, const jd_normal *nl,
                                    const jd_contact_step *h, const double f[3],
                                    const double m_roll[3], double u_new, double dash, double dt,
                                    jd_contact_energy *e) {
    const int rolling = (features & JD_F_ROLLING) != 0;
    /* the previous step's force alone (also Luding's end) */
    double w_prev = jd_previous_power(h->f_prev, h->ts_prev, h->td_prev, k);
    if (rolling) w_prev += jd_dot(h->m_prev, m->wrel);
    double w = w_prev + jd_dot(f, m->vrel); /* this step's force through this step's levers */
    if (rolling) w += jd_dot(m_roll, m->wrel);
    e->fd = nl->Cn * m->ddelta;
    dash += 0.5 * (h->fd_prev + e->fd) * m->ddelta * dt;
    const double diss = -0.5 * w * dt - (u_new - h->u_prev);
    if (features & (JD_F_FRICTION | JD_F_ROLLING)) {
        e->e_damp = h->e_damp + dash;
        e->e_fric = h->e_fric + (diss - dash);
    } else {
        e->e_damp = h->e_damp + diss; /* no sliders: all of it is the dashpot's (to O(dt^2)) */
        e->e_fric = h->e_fric;
    }
    /* At Luding's end the energy still stored in the springs is never returned, so it counts as
     * dissipated, less the work the previous step's force still does during this step (the same
     * trapezoid). */
    if (features & JD_F_DAMPING) {
        e->e_damp = nl->ends ? h->e_damp + (h->u_prev - 0.5 * w_prev * dt) : e->e_damp;
        e->e_fric = nl->ends ? h->e_fric : e->e_fric;
    }
}

/* The history after the step: unchanged while still ended, reset (and marked ended) at Luding's
 * end, else the evaluated one. */
static JD_ALWAYS_INLINE void jd_contact_commit(const unsigned features, const jd_lever_torques *t,
                                        const jd_contact_step *h,
                                        const jd_normal *nl, const double f[3],
                                        const double m_roll[3], double u_new,
                                        const jd_contact_energy *e, jd_contact_state *s,
                                        jd_rolling_state *r) {
    const int rolling = (features & JD_F_ROLLING) != 0;
    const int still_ended = h->still_ended, carries = nl->carries;
    s->flags = still_ended ? s->flags : (nl->ends ? (double)JD_S_ENDED : h->flags);
    for (int d = 0; d < 3; d++) s->xi[d] = carries ? h->xi[d] : (still_ended ? s->xi[d] : 0.0);
    if (rolling)
        for (int d = 0; d < 3; d++)
            r->theta[d] = carries ? h->theta[d] : (still_ended ? r->theta[d] : 0.0);
    if (features & JD_F_MEPA) s->dp = nl->dp; /* a MEPA contact always carries */
    if (features & JD_F_ENERGY) {
        for (int d = 0; d < 3; d++) {
            s->f_prev[d] = carries ? f[d] : (still_ended ? s->f_prev[d] : 0.0);
            s->ts_prev[d] = carries ? t->ta[d] + t->tb[d] : (still_ended ? s->ts_prev[d] : 0.0);
            s->td_prev[d] = carries ? t->tb[d] - t->ta[d] : (still_ended ? s->td_prev[d] : 0.0);
            if (rolling) r->m_prev[d] = carries ? m_roll[d] : (still_ended ? r->m_prev[d] : 0.0);
        }
        s->fd_prev = carries ? e->fd : (still_ended ? s->fd_prev : 0.0);
        s->u_prev = carries ? u_new : (still_ended ? s->u_prev : 0.0);
        s->e_damp = still_ended ? s->e_damp : e->e_damp;
        s->e_fric = still_ended ? s->e_fric : e->e_fric;
    }
}

/* The force on b and the torques about each centre (eq. 19), with the rolling moment on b
 * (without rolling resistance nothing is added: the engines' torque sums start from +0, so
 * adding a +0 moment could only have turned a -0 torque into +0, which their sums never see).
 * All zero once the contact has ended (carries 0). */
static JD_ALWAYS_INLINE void jd_contact_assemble(const unsigned features, const jd_lever_torques *t,
                                          const jd_normal *nl, const double f[3],
                                          const double m_roll[3], jd_contact_result *out) {
    const int carries = nl->carries;
    double ta[3], tb[3];
    for (int d = 0; d < 3; d++) {
        ta[d] = t->ta[d];
        tb[d] = t->tb[d];
    }
    if (features & JD_F_ROLLING)
        for (int d = 0; d < 3; d++) {
            ta[d] -= m_roll[d];
            tb[d] += m_roll[d];
        }
    for (int d = 0; d < 3; d++) {
        out->f[d] = carries ? f[d] : 0.0;
        out->ta[d] = carries ? ta[d] : 0.0;
        out->tb[d] = carries ? tb[d] : 0.0;
    }
    out->fn = carries ? nl->fn : 0.0;
}

/* One evaluation of a contact (the reference algorithm of docs/model.md §9).
 *
 * features: a law set (jdem_laws.h, JD_LAW_SETS), a compile-time constant at the call site but
 *           for the run-time laws (JD_F_RUN_TIME: a branch, jd_law_set_of_loop).
 * c, g, k:  coefficients, geometry (g->delta > 0) and kinematics.
 * dt:       time step [s] (the springs accumulate rate * dt).
 * s:        contact history, updated.   r: rolling history (NULL unless JD_F_ROLLING).
 * out:      force on b and the torques on a and b; all zero when the contact has ended.
 * Returns 1 while the contact carries force, 0 once it has ended (Luding's rule: the total
 * normal force reached zero while unloading; it stays ended until the bodies separate or start
 * approaching again, which begins a new contact).
 *
 * The energy fields of s (f_prev, fd_prev, u_prev, e_damp, e_fric) and r->m_prev are read and
 * written only with JD_F_ENERGY: without it an engine may keep just xi and flags (and theta).
 *
 * The law has no branches that depend on the contact's data: every case (still ended, new
 * approach, Luding's end, sticking, sliding) is computed and the result selected, so that an
 * engine can evaluate a batch of contacts in SIMD lanes (`#pragma omp simd` over the batch); the
 * arithmetic of each case is exactly that of the case alone. */
static JD_ALWAYS_INLINE int jd_contact(const unsigned features, const jd_pair_coeffs *c,
                                const jd_contact_geom *g, const jd_kinematics *k, double dt,
                                jd_contact_state *s, jd_rolling_state *r, jd_contact_result *out) {
    const int energy = (features & JD_F_ENERGY) != 0;
    jd_contact_motion m;
    jd_contact_kinematics(features, g, k, &m);
    jd_contact_step h;
    jd_contact_begin(features, g, s, r, m.ddelta, &h);
    jd_normal nl;
    jd_law_normal(features, c, g, m.ddelta, h.still_ended, h.dp, dt, &nl);

    double f[3] = {nl.fn * g->n[0], nl.fn * g->n[1], nl.fn * g->n[2]};
    double m_roll[3] = {0.0, 0.0, 0.0};
    double u_new = nl.u; /* the normal spring's, with the tangential and rolling springs' added */
    /* the share of the dissipation booked as damping besides the normal dashpot: the tangential
     * and rolling dashpots', and MEPA's plastic work [J] */
    double dash = nl.e_plastic;
    if (features & JD_F_FRICTION) jd_law_tangential(features, c, g, &m, &nl, dt, &h, f, &u_new, &dash);
    if (features & JD_F_ROLLING) jd_law_rolling(features, c, g, &m, &nl, dt, &h, m_roll, &u_new, &dash);
    jd_contact_energy e = {0.0, h.e_damp, h.e_fric};
    if (energy) jd_law_energy(features, k, &m, &nl, &h, f, m_roll, u_new, dash, dt, &e);

    jd_lever_torques t;
    jd_lever_torques_of(g->ra, g->rb, f, &t);
    jd_contact_commit(features, &t, &h, &nl, f, m_roll, u_new, &e, s, r);
    jd_contact_assemble(features, &t, &nl, f, m_roll, out);
    return nl.carries;
}

/* LIGGGHTS evaluates the forces of step 0 (`setup`) without advancing the contact history, and
 * both engines follow it: they evaluate a copy of the history and discard it.  Afterwards this
 * keeps, from that evaluated copy, only what the energy bookkeeping of the next evaluation starts
 * from (previous force, dashpot force, stored energy, rolling moment), so that a contact that
 * already exists at step 0 does not book its stored energy as created.  r and r_evaluated may be
 * NULL (no rolling). */
static inline void jd_contact_keep_reference(jd_contact_state *s, const jd_contact_state *evaluated,
                                             jd_rolling_state *r,
                                             const jd_rolling_state *r_evaluated) {
    for (int d = 0; d < 3; d++) {
        s->f_prev[d] = evaluated->f_prev[d];
        s->ts_prev[d] = evaluated->ts_prev[d];
        s->td_prev[d] = evaluated->td_prev[d];
    }
    s->fd_prev = evaluated->fd_prev;
    s->u_prev = evaluated->u_prev;
    if (r && r_evaluated)
        for (int d = 0; d < 3; d++) r->m_prev[d] = r_evaluated->m_prev[d];
}

/* Work done on a particle by a translating wall during a step [J]: the trapezoidal rule of
 * jd_contact's bookkeeping on the wall's force, F_on_particle = -f, with the force on the wall
 * at the start (f_prev, read from the contact state before the evaluation) and at the end (f)
 * of the step, and the wall velocity v_wall. */
static inline double jd_wall_work(const double f_prev[3], const double f[3],
                                  const double v_wall[3], double dt) {
    return -0.5 * (jd_dot(f_prev, v_wall) + jd_dot(f, v_wall)) * dt;
}

/* Work done on a particle during a step by an external load or a holding constraint [J]: the
 * same trapezoidal rule on the force and torque applied to the particle at the start (prev[0..2]
 * force [N], prev[3..5] torque [N m]) and at the end (now) of the step, with the particle's
 * velocity v [m/s] and angular velocity w [rad/s]. */
static inline double jd_load_work(const double prev[6], const double now[6], const double v[3],
                                  const double w[3], double dt) {
    return 0.5 * (jd_dot(prev, v) + jd_dot(now, v) + jd_dot(prev + 3, w) + jd_dot(now + 3, w)) *
           dt;
}

/* Energy stored in a contact (normal spring + tangential and rolling springs) at its last
 * evaluation [J] (JD_F_ENERGY); zero once the contact has ended. */
static inline double jd_contact_elastic_energy(const jd_contact_state *s) { return s->u_prev; }

/* A wall that vanishes (a scene's `until`, fix wall/jiang `until_step`): whether it is gone from
 * the forces of step `step` [-], until_step the first step without it. */
static inline int jd_wall_gone(int64_t step, int64_t until_step) { return step >= until_step; }

/* The work [J] a vanishing wall does on a contact it leaves: the elastic energy the contact's
 * springs held leaves the system with the wall (JD_F_ENERGY). */
static inline double jd_wall_vanish_work(const jd_contact_state *s) {
    return -jd_contact_elastic_energy(s);
}

/* Moves the energies contact s has dissipated so far (damping, friction; JD_F_ENERGY), weighted
 * by w [-] (1, or 1/2 for a pair that two ranks evaluate), into *damp and *fric [J] and zeroes
 * them in s.  The one harvest of both engines; they call it at different times because their
 * contact lists end differently: LIGGGHTS deletes an ended contact's history without telling the
 * pair, so its styles harvest every contact at every step; the stepper drops an entry only at a
 * neighbour rebuild, so it harvests there, and until then the entry's own accumulators are the
 * record (its observables add them to what was harvested). */
static inline void jd_contact_harvest(jd_contact_state *s, double w, double *damp, double *fric) {
    *damp += w * s->e_damp;
    *fric += w * s->e_fric;
    s->e_damp = s->e_fric = 0.0;
}

#ifdef __cplusplus
}
#endif
#endif /* JDEM_KERNEL_H */
