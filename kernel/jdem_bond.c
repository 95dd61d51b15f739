/*
 * jdem_bond.c — set-up functions of the parallel bond (jdem_bond.h): the cross-section of
 * eq. (15) and the frequency bound used by the engines' time-step guards.
 */
#include "jdem_bond.h"
#include "jdem_guard.h"

_Static_assert(sizeof(jd_bond_state) == JD_BOND_STATE_LEN * sizeof(double),
               "jd_bond_state is a flat array of JD_BOND_STATE_LEN doubles");

jd_bond_section jd_bond_section_of(double lambda, double Ra, double Rb) {
    jd_bond_section s;
    s.rbar = lambda * (Ra < Rb ? Ra : Rb);
    const double r2 = s.rbar * s.rbar;
    s.A = JD_PI * r2;
    s.I = 0.25 * JD_PI * r2 * r2;
    s.J = 0.5 * JD_PI * r2 * r2;
    s.inv_A = 1.0 / s.A;
    s.rbar_I = s.rbar / s.I;
    s.rbar_J = s.rbar / s.J;
    return s;
}

double jd_bond_omega2_bound(const jd_bond_params *p, const jd_bond_section *sec, double m_a,
                            double m_b, double I_a, double I_b, double la, double lb) {
    const double Ib = p->bending == JD_BOND_BEND_J_LITERAL ? sec->J : sec->I;
    const double inv_m = 1.0 / m_a + 1.0 / m_b, inv_i = 1.0 / I_a + 1.0 / I_b;
    const double axial = p->kn * sec->A * inv_m;
    const double twist = p->kt * sec->J * inv_i;
    const double shear_bend =
        p->kt * sec->A * (inv_m + la * la / I_a + lb * lb / I_b) + p->kn * Ib * inv_i;
    double w2 = axial > twist ? axial : twist;
    return shear_bend > w2 ? shear_bend : w2;
}

double jd_bond_omega2_pair(const jd_bond_params *p, double R_a, double R_b, double m_a,
                           double m_b, double dist) {
    const jd_bond_section sec = jd_bond_section_of(p->lambda, R_a, R_b);
    const double delta = R_a + R_b - dist;
    const double la = fabs(R_a - 0.5 * delta), lb = fabs(dist - la);
    return jd_bond_omega2_bound(p, &sec, m_a, m_b, jd_sphere_inertia(m_a, R_a),
                                jd_sphere_inertia(m_b, R_b), la, lb);
}

double jd_bond_omega2_rule(const jd_bond_params *p, double R, double m) {
    const double I = jd_sphere_inertia(m, R);
    const jd_bond_section sec = jd_bond_section_of(p->lambda, R, R);
    return JD_GUARD_DEFAULT_COORDINATION * jd_bond_omega2_bound(p, &sec, m, m, I, I, R, R);
}
