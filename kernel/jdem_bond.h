/*
 * jdem_bond.h — the parallel bond of Potyondy & Cundall (2004) as used by Jiang (2021) §2.3.4
 * (eqs. 14–17): the single source of jdem's bond physics, called by both engines.
 *
 * Pure C11. No I/O, no allocation, no globals, no engine types.  Units SI: m, s, kg, N, N·m, J,
 * Pa, rad.  Equations and choices, with their evidence: docs/model.md §9 ("Parallel bonds").
 *
 * Conventions for one bond between sphere a and sphere b (the same as jdem_kernel.h):
 *   - n is the unit vector from the centre of a to the centre of b.
 *   - delta = R_a + R_b - |x_b - x_a| is the overlap; a bonded pair may be separated (delta < 0).
 *   - The bond acts at x_C = x_a + (R_a - delta/2) n: the contact point while the spheres touch,
 *     the middle of the gap once they separate (PFC's parallel-bond location).
 *     ra = x_C - x_a and rb = x_C - x_b are the lever arms.
 *   - vrel = (v_b + w_b x rb) - (v_a + w_a x ra) is the velocity of b's material point at x_C
 *     relative to a's; wrel = w_b - w_a.
 *   - The kernel returns the force on b (on a: its negative), the torques on a and b about their
 *     centres.
 *
 * The law (incremental, P&C 2004 eqs. 8–12; Jiang eq. 16 with the bending stiffness on I):
 *     Fn += -kn A (vrel.n) dt              normal force, > 0 in compression           [N]
 *     Ft += -kt A vt dt                    shear force on b, vt = vrel - (vrel.n) n    [N]
 *     Mn += -kt J (wrel.n) dt              twisting moment on b about n               [N m]
 *     Mt += -kn I wt dt                    bending moment on b, wt = wrel - (wrel.n) n [N m]
 * with R_bar = lambda min(R_a, R_b), A = pi R_bar^2, I = pi R_bar^4 / 4, J = pi R_bar^4 / 2.
 * Before the increments the stored Ft and Mt are turned into the current plane normal to n
 * (their normal component removed, their length kept), as P&C do.  The force on b is
 * Fn n + Ft, the couple on b is Mn n + Mt (plus optional dashpots, below).
 * Failure (eq. 17): sigma_max = -Fn/A + |Mt| R_bar/I >= sigma_c  -> tension;
 *                   tau_max   = |Ft|/A + |Mn| R_bar/J >= tau_c    -> shear.
 * A broken bond exerts nothing from the step at which it fails; the pair is then an ordinary
 * contact (the engines evaluate the contact law for the pair whenever the spheres overlap, in
 * parallel with the bond while it is intact).
 *
 * Step 0 (LIGGGHTS `setup`, forces evaluated without advancing any history): call jd_bond with
 * dt = 0.  There is no increment, so the force is the stored one (plus the dashpots), nothing is
 * booked, and the energy reference of the first step is the stored state.
 *
 * The hot path (jd_bond) is `static inline` so that each engine inlines it into a loop
 * specialised for its feature set (JD_B_* bits, a compile-time constant at every call site).
 */
#ifndef JDEM_BOND_H
#define JDEM_BOND_H

#include <math.h>

#include "jdem_kernel.h"

#ifdef __cplusplus
extern "C" {
#endif

/* ------------------------------------------------------------------------------------------ */
/* Feature flags of a bond loop.                                                               */
/* ------------------------------------------------------------------------------------------ */
enum {
    JD_B_DAMPING = 1u << 0, /* viscous dashpots on the four relative motions (gamma > 0)      */
    JD_B_ENERGY = 1u << 1   /* stored energy, dissipation and breakage bookkeeping              */
};

/* Which second moment the bending stiffness uses (docs/model.md §9.2). */
typedef enum {
    JD_BOND_BEND_I = 0,      /* Delta Mt = -kn I Delta theta_t, as Potyondy & Cundall (default) */
    JD_BOND_BEND_J_LITERAL = 1 /* -kn J Delta theta_t, as the dissertation prints (= 2 x stiffer) */
} jd_bond_bending;

/* State of a bond after an evaluation. */
typedef enum {
    JD_BOND_INTACT = 0,
    JD_BOND_BROKE_TENSION = 1, /* sigma_max >= sigma_c (and its ratio >= tau_max/tau_c)        */
    JD_BOND_BROKE_SHEAR = 2    /* tau_max >= tau_c (and its ratio > sigma_max/sigma_c)         */
} jd_bond_mode;

/* ------------------------------------------------------------------------------------------ */
/* Parameters of a bond type (Jiang's five, plus damping and the bending option).              */
/* ------------------------------------------------------------------------------------------ */
typedef struct jd_bond_params {
    double kn;      /* normal stiffness per unit area (stress per displacement), >= 0 [N/m^3] */
    double kt;      /* shear stiffness per unit area, >= 0 (0: no load carried) [N/m^3] */
    double sigma_c; /* tensile strength; INFINITY: no tensile failure             [Pa]    */
    double tau_c;   /* shear strength; INFINITY: no shear failure                  [Pa]    */
    double lambda;  /* bond-radius multiplier, R_bar = lambda min(R_a, R_b)        [-]     */
    double gamma;   /* damping ratio of the optional dashpots (JD_B_DAMPING), >= 0 [-]     */
    int bending;    /* jd_bond_bending                                                      */
} jd_bond_params;

/* Cross-section of one bond (eq. 15), from jd_bond_section(). */
typedef struct jd_bond_section {
    double rbar;   /* bond radius lambda min(R_a, R_b)           [m]    */
    double A;      /* area pi rbar^2                              [m^2]  */
    double I;      /* second moment of area pi rbar^4 / 4         [m^4]  */
    double J;      /* polar moment pi rbar^4 / 2                  [m^4]  */
    double inv_A;  /* 1 / A, for the stresses of eq. (17)         [m^-2] */
    double rbar_I; /* rbar / I                                    [m^-3] */
    double rbar_J; /* rbar / J                                    [m^-3] */
} jd_bond_section;

/* ------------------------------------------------------------------------------------------ */
/* Geometry and masses of a bonded pair at the current step (filled by jd_bond_geom_spheres     */
/* and the engine).                                                                            */
/* ------------------------------------------------------------------------------------------ */
typedef struct jd_bond_geom {
    double n[3];   /* unit vector a -> b                                             [-]    */
    double delta;  /* overlap R_a + R_b - |x_b - x_a|; < 0 when separated             [m]    */
    double ra[3];  /* x_C - x_a                                                       [m]    */
    double rb[3];  /* x_C - x_b                                                       [m]    */
    jd_bond_section sec; /* cross-section (constant for the bond's life)                     */
    double m_eff;  /* m_a m_b / (m_a + m_b), for the dashpots (JD_B_DAMPING)          [kg]   */
    double i_eff;  /* I_a I_b / (I_a + I_b), for the dashpots (JD_B_DAMPING)          [kg m^2] */
} jd_bond_geom;

/* ------------------------------------------------------------------------------------------ */
/* Per-bond state: a plain array of doubles, like jd_contact_state, so that LIGGGHTS can store  */
/* and migrate it; jd_bond_state_newton lists the entries that change sign when a and b swap.  */
/* All zero means "no bond"; jd_bond_form() makes a fresh intact bond (all forces zero, as      */
/* Jiang Ch. 5 states for a bond when it forms).                                               */
/* ------------------------------------------------------------------------------------------ */
typedef struct jd_bond_state {
    double fn;        /* normal force, > 0 in compression                                [N]   */
    double ft[3];     /* shear force on b, in the plane normal to n                     [N]   */
    double mn;        /* twisting moment on b about n (the couple on b is mn n)           [N m] */
    double mt[3];     /* bending moment on b, in the plane normal to n                  [N m] */
    double flags;     /* JD_BS_* bits stored as a small integer value                    [-]   */
    /* Energy bookkeeping (JD_B_ENERGY), the trapezoidal rule of jd_contact: */
    double f_prev[3]; /* total force on b at the previous evaluation                     [N]   */
    double ts_prev[3]; /* T_a + T_b, the torques about the centres it applied then       [N m] */
    double td_prev[3]; /* T_b - T_a (the previous lever arms and couple, as jd_contact)   [N m] */
    double u_prev;    /* elastic energy stored at the previous evaluation                [J]   */
    double e_damp;    /* energy dissipated by the dashpots (JD_B_DAMPING)                [J]   */
    double e_break;   /* elastic energy released when the bond broke                     [J]   */
} jd_bond_state;

enum { JD_BS_INTACT = 1, JD_BS_BROKEN = 2 };

#define JD_BOND_STATE_LEN 21 /* doubles in jd_bond_state */
/* 1 where the entry changes sign when a and b swap (vectors "on b"), else 0.  fn and mn do not:
 * the couple mn n on b becomes -mn n on a = mn n' with the swapped normal n' = -n.  The torque
 * sum ts_prev does not either; the difference td_prev does. */
static const int jd_bond_state_newton[JD_BOND_STATE_LEN] = {0, 1, 1, 1, 0, 1, 1, 1, 0, 1, 1,
                                                            1, 0, 0, 0, 1, 1, 1, 0, 0, 0};

/* What one evaluation returns. */
typedef struct jd_bond_result {
    double f[3];      /* force on b (on a: -f); zero once broken                          [N]   */
    double ta[3];     /* torque on a about its centre; zero once broken                   [N m] */
    double tb[3];     /* torque on b about its centre; zero once broken                   [N m] */
    double fn;        /* normal force of the bond, > 0 in compression (at failure: the
                         value that broke it)                                             [N]   */
    double ft;        /* |shear force|                                                    [N]   */
    double mn;        /* |twisting moment|                                                [N m] */
    double mt;        /* |bending moment|                                                 [N m] */
    double sigma_max; /* largest tensile stress on the periphery, eq. (17)                [Pa]  */
    double tau_max;   /* largest shear stress on the periphery, eq. (17)                  [Pa]  */
    int mode;         /* jd_bond_mode                                                           */
} jd_bond_result;

/* ------------------------------------------------------------------------------------------ */
/* Set-up (jdem_bond.c).                                                                       */
/* ------------------------------------------------------------------------------------------ */

/* Cross-section of eq. (15) for radii R_a, R_b [m] and multiplier lambda [-] (with the
 * reciprocals the hot path multiplies by). */
jd_bond_section jd_bond_section_of(double lambda, double Ra, double Rb);

/* Square of an upper bound on the angular frequencies of one bond between two free spheres
 * (masses m [kg], moments of inertia I [kg m^2], lever arms la = |ra|, lb = |rb| [m]) [rad^2/s^2]:
 * the largest of the axial kn A (1/m_a + 1/m_b), the twisting kt J (1/I_a + 1/I_b), and the
 * shear–bending block, bounded by kt A (1/m_a + 1/m_b + la^2/I_a + lb^2/I_b) +
 * kn I_bend (1/I_a + 1/I_b) (lambda_max of a sum <= the sum of lambda_max).  The three blocks
 * decouple by symmetry about n.  Engines add these per particle for the Gershgorin bound of a
 * bonded network (docs/model.md §9.5). */
double jd_bond_omega2_bound(const jd_bond_params *p, const jd_bond_section *sec, double m_a,
                            double m_b, double I_a, double I_b, double la, double lb);

/* jd_bond_omega2_bound of a bond of type p between spheres of radii R_a, R_b [m] and masses m_a,
 * m_b [kg] whose centres are dist [m] apart (lever arms from the bond's contact plane, solid
 * spheres' inertia) [rad^2/s^2]. */
double jd_bond_omega2_pair(const jd_bond_params *p, double R_a, double R_b, double m_a,
                           double m_b, double dist);

/* The bound a bond rule adds to a particle of radius R [m] and mass m [kg] that it may bond:
 * JD_GUARD_DEFAULT_COORDINATION bonds to equal neighbours (the densest packing's
 * coordination) [rad^2/s^2]. */
double jd_bond_omega2_rule(const jd_bond_params *p, double R, double m);

/* The bond law's set of a run (JD_B_*): the dashpots when a bond type has gamma > 0, the energy
 * bookkeeping when asked; one of JD_BOND_LAW_SETS (jdem_laws.h). */
static inline unsigned jd_bond_laws(double gamma) { return gamma > 0.0 ? (unsigned)JD_B_DAMPING : 0u; }

/* ------------------------------------------------------------------------------------------ */
/* Hot path.                                                                                   */
/* ------------------------------------------------------------------------------------------ */

/* Geometry of a bonded pair, touching or separated: fills n, delta, ra, rb of g (not sec, which
 * the engine sets from jd_bond_section_of, nor m_eff, i_eff: jd_bond_set_masses).  Returns 0 when the centres coincide (no normal:
 * the engine reports it), else 1. */
static inline int jd_bond_geom_spheres(const double xa[3], double Ra, const double xb[3],
                                       double Rb, jd_bond_geom *g) {
    const double dx[3] = {xb[0] - xa[0], xb[1] - xa[1], xb[2] - xa[2]};
    const double d = sqrt(jd_dot(dx, dx));
    if (!(d > 0.0)) return 0;
    const double rinv = 1.0 / d;
    g->delta = Ra + Rb - d;
    const double la = Ra - 0.5 * g->delta;
    for (int k = 0; k < 3; k++) {
        g->n[k] = dx[k] * rinv;
        g->ra[k] = la * g->n[k];
        g->rb[k] = g->ra[k] - dx[k];
    }
    return 1;
}

/* The dashpots' effective mass and inertia of g from the particles' masses m [kg] and moments
 * of inertia I [kg m^2] (read only with JD_B_DAMPING). */
static inline void jd_bond_set_masses(jd_bond_geom *g, double m_a, double m_b, double I_a,
                                      double I_b) {
    g->m_eff = m_a * m_b / (m_a + m_b);
    g->i_eff = I_a * I_b / (I_a + I_b);
}

/* A new intact bond: zero forces and moments, zero energy accumulators. */
static inline void jd_bond_form(jd_bond_state *s) {
    double *v = (double *)s;
    for (int k = 0; k < JD_BOND_STATE_LEN; k++) v[k] = 0.0;
    s->flags = (double)JD_BS_INTACT;
}

static inline int jd_bond_intact(const jd_bond_state *s) {
    return ((int)s->flags & JD_BS_INTACT) != 0;
}

/* Elastic energy stored in the bond's springs [J]:
 * Fn^2/(2 kn A) + |Ft|^2/(2 kt A) + Mn^2/(2 kt J) + |Mt|^2/(2 kn I_bend).  A spring of zero
 * stiffness (kn or kt = 0: a bond that carries no load) holds no force and no energy. */
static inline double jd_bond_energy(const jd_bond_params *p, const jd_bond_section *sec,
                                    const jd_bond_state *s) {
    const double Ib = p->bending == JD_BOND_BEND_J_LITERAL ? sec->J : sec->I;
    const int n = p->kn > 0.0, t = p->kt > 0.0;
    return (n ? 0.5 * s->fn * s->fn / (p->kn * sec->A) : 0.0) +
           (t ? 0.5 * jd_dot(s->ft, s->ft) / (p->kt * sec->A) : 0.0) +
           (t ? 0.5 * s->mn * s->mn / (p->kt * sec->J) : 0.0) +
           (n ? 0.5 * jd_dot(s->mt, s->mt) / (p->kn * Ib) : 0.0);
}

/* ------------------------------------------------------------------------------------------ */
/* jd_bond as a composition of small laws, each unit-tested alone (tests/unit/test_laws.c),    */
/* called by jd_bond in the order of docs/model.md §9.                                         */
/* ------------------------------------------------------------------------------------------ */

/* The relative motion at the bond point, split along n and in the plane. */
typedef struct jd_bond_motion {
    double vrel[3], wrel[3]; /* relative velocity [m/s] and angular velocity [rad/s] of b */
    double vn, wn;           /* their components along n                                  */
    double vt[3], wt[3];     /* and in the plane                                          */
} jd_bond_motion;

static JD_ALWAYS_INLINE void jd_bond_kinematics(const jd_bond_geom *g, const jd_kinematics *k,
                                                jd_bond_motion *m) {
    double wxa[3], wxb[3];
    jd_cross(k->wa, g->ra, wxa);
    jd_cross(k->wb, g->rb, wxb);
    for (int d = 0; d < 3; d++) {
        m->vrel[d] = (k->vb[d] + wxb[d]) - (k->va[d] + wxa[d]);
        m->wrel[d] = k->wb[d] - k->wa[d];
    }
    m->vn = jd_dot(m->vrel, g->n);
    m->wn = jd_dot(m->wrel, g->n);
    for (int d = 0; d < 3; d++) {
        m->vt[d] = m->vrel[d] - m->vn * g->n[d];
        m->wt[d] = m->wrel[d] - m->wn * g->n[d];
    }
}

/* The bond's spring stiffnesses: normal and shear kn A, kt A [N/m]; twisting kt J and bending
 * kn I_bend [N m/rad]. */
typedef struct jd_bond_stiffness {
    double Kn, Kt, Ktw, Kb;
} jd_bond_stiffness;

static JD_ALWAYS_INLINE jd_bond_stiffness jd_bond_stiffness_of(const jd_bond_params *p,
                                                               const jd_bond_section *sec) {
    const double Ib = p->bending == JD_BOND_BEND_J_LITERAL ? sec->J : sec->I;
    const jd_bond_stiffness K = {p->kn * sec->A, p->kt * sec->A, p->kt * sec->J, p->kn * Ib};
    return K;
}

/* The stored force and moment vectors turned into the current plane, then the increments of
 * eq. (16). */
static JD_ALWAYS_INLINE void jd_bond_springs(const jd_bond_stiffness *K, const jd_bond_geom *g,
                                             const jd_bond_motion *m, double dt, jd_bond_state *s) {
    jd_rotate_into_plane(s->ft, g->n);
    jd_rotate_into_plane(s->mt, g->n);
    s->fn -= K->Kn * m->vn * dt;
    s->mn -= K->Ktw * m->wn * dt;
    for (int d = 0; d < 3; d++) {
        s->ft[d] -= K->Kt * m->vt[d] * dt;
        s->mt[d] -= K->Kb * m->wt[d] * dt;
    }
}

/* Stresses on the periphery, eq. (17), and the failure they cause: fills out's magnitudes and
 * stresses and returns out->mode (the larger stress/strength ratio; tension on a tie). */
static JD_ALWAYS_INLINE int jd_bond_strength(const jd_bond_params *p, const jd_bond_section *sec,
                                             const jd_bond_state *s, jd_bond_result *out) {
    out->fn = s->fn;
    out->ft = sqrt(jd_dot(s->ft, s->ft));
    out->mn = fabs(s->mn);
    out->mt = sqrt(jd_dot(s->mt, s->mt));
    out->sigma_max = -s->fn * sec->inv_A + out->mt * sec->rbar_I;
    out->tau_max = out->ft * sec->inv_A + out->mn * sec->rbar_J;
    out->mode = JD_BOND_INTACT;
    if (out->sigma_max >= p->sigma_c || out->tau_max >= p->tau_c) {
        const double rs = out->sigma_max / p->sigma_c, rt = out->tau_max / p->tau_c;
        out->mode = rs >= rt ? JD_BOND_BROKE_TENSION : JD_BOND_BROKE_SHEAR;
    }
    return out->mode;
}

/* A bond that failed this step: with JD_B_ENERGY the energy it stored beyond the half of this
 * step's trapezoid its last load still did is lost (as at Luding's end of a contact); the
 * state becomes broken with zero forces, keeping the accumulators; no force on the bodies. */
static JD_ALWAYS_INLINE void jd_bond_break(const unsigned features, const jd_kinematics *k,
                                           double dt, jd_bond_state *s, jd_bond_result *out) {
    if (features & JD_B_ENERGY) s->e_break += s->u_prev - 0.5 * jd_previous_power(s->f_prev, s->ts_prev, s->td_prev, k) * dt;
    const double e_damp = s->e_damp, e_break = s->e_break;
    double *v = (double *)s;
    for (int q = 0; q < JD_BOND_STATE_LEN; q++) v[q] = 0.0;
    s->flags = (double)JD_BS_BROKEN;
    s->e_damp = e_damp;
    s->e_break = e_break;
    for (int d = 0; d < 3; d++) out->f[d] = out->ta[d] = out->tb[d] = 0.0;
}

/* Force f and couple mo on b: the springs, plus with JD_B_DAMPING the dashpots (not part of
 * the bond's stress), 2 gamma sqrt(m K) on each of the four motions. */
static JD_ALWAYS_INLINE void jd_bond_load(const unsigned features, const jd_bond_params *p,
                                          const jd_bond_stiffness *K, const jd_bond_geom *g,
                                          const jd_bond_motion *m, const jd_bond_state *s,
                                          double f[3], double mo[3]) {
    for (int d = 0; d < 3; d++) {
        f[d] = s->fn * g->n[d] + s->ft[d];
        mo[d] = s->mn * g->n[d] + s->mt[d];
    }
    if (features & JD_B_DAMPING) {
        const double cn = 2.0 * p->gamma * sqrt(g->m_eff * K->Kn);
        const double ct = 2.0 * p->gamma * sqrt(g->m_eff * K->Kt);
        const double ctw = 2.0 * p->gamma * sqrt(g->i_eff * K->Ktw);
        const double cb = 2.0 * p->gamma * sqrt(g->i_eff * K->Kb);
        for (int d = 0; d < 3; d++) {
            f[d] -= cn * m->vn * g->n[d] + ct * m->vt[d];
            mo[d] -= ctw * m->wn * g->n[d] + cb * m->wt[d];
        }
    }
}

/* Energy bookkeeping (JD_B_ENERGY): work on the bodies this step by the trapezoidal rule (as
 * jd_contact), the previous load through the levers it was applied with and this step's through
 * this step's (out: its torques, from jd_bond_assemble); with dashpots, what the springs did not
 * store was dissipated.  Without dashpots nothing is booked: the O(dt^2) remainder is the
 * integrator's, and the undamped energy checks see it. */
static JD_ALWAYS_INLINE void jd_bond_energy_book(const unsigned features, const jd_bond_params *p,
                                                 const jd_bond_section *sec,
                                                 const jd_kinematics *k, const jd_bond_motion *m,
                                                 const double f[3], const double mo[3],
                                                 const jd_bond_result *out, double dt,
                                                 jd_bond_state *s) {
    const double u_new = jd_bond_energy(p, sec, s);
    if (features & JD_B_DAMPING) {
        const double w = jd_previous_power(s->f_prev, s->ts_prev, s->td_prev, k) + jd_dot(f, m->vrel) +
                         jd_dot(mo, m->wrel);
        s->e_damp += -0.5 * w * dt - (u_new - s->u_prev);
    }
    s->u_prev = u_new;
    for (int d = 0; d < 3; d++) {
        s->f_prev[d] = f[d];
        s->ts_prev[d] = out->ta[d] + out->tb[d];
        s->td_prev[d] = out->tb[d] - out->ta[d];
    }
}

/* Torques about the centres: the force at x_C plus the couple. */
static JD_ALWAYS_INLINE void jd_bond_assemble(const jd_bond_geom *g, const double f[3],
                                              const double mo[3], jd_bond_result *out) {
    jd_lever_torques t;
    jd_lever_torques_of(g->ra, g->rb, f, &t);
    for (int d = 0; d < 3; d++) {
        out->ta[d] = t.ta[d];
        out->tb[d] = t.tb[d];
        out->f[d] = f[d];
        out->ta[d] -= mo[d];
        out->tb[d] += mo[d];
    }
}

/* One evaluation of an intact bond (docs/model.md §9.3).
 *
 * features: a bond law set (JD_B_* bits, jdem_laws.h JD_BOND_LAW_SETS), a compile-time constant
 *           at the call site.
 * p, g, k:  parameters, geometry (jd_bond_geom_spheres + sec, m_eff, i_eff) and kinematics.
 * dt:       time step [s] (the increments are rate * dt).
 * s:        bond state (intact), updated.  On failure its flags become JD_BS_BROKEN and its
 *           forces zero; the energy it stored goes to e_break (JD_B_ENERGY).
 * out:      force on b, torques, the bond's force and moment magnitudes and stresses.
 * Returns out->mode: JD_BOND_INTACT, or the failure mode.  When both strengths are reached in
 * the same step the mode is the one with the larger stress/strength ratio (tension on a tie). */
static JD_ALWAYS_INLINE int jd_bond(const unsigned features, const jd_bond_params *p,
                                    const jd_bond_geom *g, const jd_kinematics *k, double dt,
                                    jd_bond_state *s, jd_bond_result *out) {
    const jd_bond_stiffness K = jd_bond_stiffness_of(p, &g->sec);
    jd_bond_motion m;
    jd_bond_kinematics(g, k, &m);
    jd_bond_springs(&K, g, &m, dt, s);
    if (jd_bond_strength(p, &g->sec, s, out) != JD_BOND_INTACT) {
        jd_bond_break(features, k, dt, s, out);
        return out->mode;
    }
    double f[3], mo[3];
    jd_bond_load(features, p, &K, g, &m, s, f, mo);
    jd_bond_assemble(g, f, mo, out);
    if (features & JD_B_ENERGY) jd_bond_energy_book(features, p, &g->sec, k, &m, f, mo, out, dt, s);
    return JD_BOND_INTACT;
}

/* Moves the energies bond s has dissipated in its dashpots and released by breaking
 * (JD_B_ENERGY) into *damp and *brk [J] and zeroes them in s: the one harvest of both engines.
 * fix bond/jiang harvests every bond at every step and a broken one before it removes it; the
 * stepper harvests a broken bond when it leaves the list, and reads the others from a copy for
 * its observables (the contact harvest, jdem_kernel.h, says why the times differ). */
static inline void jd_bond_harvest(jd_bond_state *s, double *damp, double *brk) {
    *damp += s->e_damp;
    *brk += s->e_break;
    s->e_damp = s->e_break = 0.0;
}

#ifdef __cplusplus
}
#endif
#endif /* JDEM_BOND_H */
