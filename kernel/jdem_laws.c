/*
 * jdem_laws.c — the set-up half of the rulebook (jdem_laws.h): law-set selection, the pair
 * coefficient table, the names of the laws.
 */
#include "jdem_laws.h"

#include <math.h>
#include <string.h>

_Static_assert(sizeof(jd_contact_state) == JD_CONTACT_STATE_LEN * sizeof(double) &&
                   sizeof(jd_rolling_state) == JD_ROLLING_STATE_LEN * sizeof(double),
               "the kernel's history structs are plain arrays of doubles");
_Static_assert(JD_AT(jd_contact_state, xi) == 0 &&
                   JD_AT(jd_contact_state, flags) == JD_CONTACT_LAWS_LEN - 1 &&
                   JD_AT(jd_rolling_state, theta) == 0 &&
                   sizeof(((jd_rolling_state *)0)->theta) == JD_ROLLING_LAWS_LEN * sizeof(double),
               "the fields the laws carry lead the history structs (the short records)");

_Static_assert(sizeof(jd_bond_state) == JD_BOND_STATE_LEN * sizeof(double) &&
                   JD_AT(jd_bond_state, flags) == JD_BOND_LAWS_LEN - 1 &&
                   JD_AT(jd_bond_state, e_break) == JD_BOND_STATE_LEN - 1,
               "the kernel's bond state is a plain array of doubles, the law's fields first");

const char *const jd_law_names[JD_N_LAWS] = {"damping", "friction", "rolling", "mu_r",
                                             "energy",  "mindlin",  "mepa"};
_Static_assert(JD_F_MEPA == 1u << (JD_N_LAWS - 1), "one name per JD_F_* bit, in bit order");
_Static_assert(JD_AT(jd_contact_state, dp) == JD_CONTACT_ENERGY_LEN,
               "MEPA's history follows the energy record's fields");

#define JD_LAW_SET_CASE(bits) \
    case (bits):              \
        return 1;
int jd_law_set_valid(unsigned bits) {
    switch (bits) {
        JD_LAW_SETS(JD_LAW_SET_CASE)
    default:
        return 0;
    }
}
#undef JD_LAW_SET_CASE

char *jd_law_set_describe(unsigned bits, char *buf, size_t len) {
    if (!len) return buf;
    buf[0] = '\0';
    const char *parts[JD_N_LAWS + 1];
    int n = 0;
    for (int k = 0; k < JD_N_LAWS; k++)
        if (bits & (1u << k)) parts[n++] = jd_law_names[k];
    if (n == 0) parts[n++] = "elastic";
    size_t at = 0;
    for (int k = 0; k < n; k++) {
        const char *p = parts[k];
        if (k > 0 && at + 1 < len) buf[at++] = '+';
        for (; *p && at + 1 < len; p++) buf[at++] = *p;
    }
    buf[at] = '\0';
    return buf;
}

unsigned jd_law_set_select(size_t nm, const double *restitution, const double *friction,
                           const double *rolling_friction, const unsigned char *in_particles,
                           const unsigned char *in_walls, double mu_r, int tangential_rule,
                           int normal_law, int energy) {
    unsigned laws = 0u;
    for (size_t a = 0; a < nm; a++) {
        if (!in_particles[a]) continue;
        for (size_t b = 0; b < nm; b++) {
            if (!in_particles[b] && !(in_walls && in_walls[b])) continue;
            const size_t k = a * nm + b;
            laws |= jd_interaction_laws(restitution[k], friction[k], rolling_friction[k]);
        }
    }
    if ((laws & JD_F_FRICTION) && mu_r != 1.0) laws |= JD_F_MU_R;
    if ((laws & JD_F_FRICTION) && tangential_rule == JD_KT_MINDLIN) laws |= JD_F_MINDLIN;
    if (normal_law == JD_NORMAL_MEPA) laws |= JD_F_MEPA;
    if (energy) laws |= JD_F_ENERGY;
    return laws;
}

/* A material's share of 1/G* (jd_shear_compliance), 0 for a rigid one (E <= 0). */
static double shear_share(double E, double nu) { return E > 0.0 ? jd_shear_compliance(E, nu) : 0.0; }

/* 1/(sum of the shares), 0 when both are rigid. */
static double g_star_of(double share_a, double share_b) {
    const double s = share_a + share_b;
    return s > 0.0 ? 1.0 / s : 0.0;
}

jd_mepa_coeffs jd_mepa_coeffs_of(const jd_mepa_inputs *in, size_t a, size_t b) {
    const double k1 = jd_mepa_series(in->k1[a], in->k1[b]);
    const double k2 = jd_mepa_series(in->k2[a], in->k2[b]);
    const double kadh = jd_mepa_series(in->kadh[a], in->kadh[b]), inv_n = 1.0 / in->n;
    return (jd_mepa_coeffs){.k1 = k1, .k2 = k2, .kadh = kadh, .n = in->n, .depth = in->depth,
                            .x_virgin = pow((k2 - k1) / k2, inv_n),
                            .x_adh = pow((k2 + kadh) / k2, inv_n),
                            .x_end = pow(k2 / (k2 - k1), inv_n)};
}

void jd_pair_coeffs_table(size_t nm, const double *restitution, const double *friction,
                          const double *rolling_friction, const double *E, const double *nu,
                          int damping_map, double mu_r, int xi_limit, const jd_mepa_inputs *mepa,
                          jd_pair_coeffs *out) {
    const size_t nn = nm * nm;
    for (size_t k = 0; k < nn; k++) {
        size_t q = 0;
        while (q < k && restitution[q] != restitution[k]) q++;
        const double gamma = q < k ? out[q].gamma : jd_gamma_for(damping_map, restitution[k]);
        const double share_a = shear_share(E[k / nm], nu[k / nm]);
        const double share_b = shear_share(E[k % nm], nu[k % nm]);
        out[k] = (jd_pair_coeffs){.gamma = gamma, .mu = friction[k], .eta = rolling_friction[k],
                                  .mu_r = mu_r, .xi_limit = xi_limit,
                                  .g_star = g_star_of(share_a, share_b),
                                  .g_wall = g_star_of(share_a, 0.0)};
        if (mepa) out[k].mepa = jd_mepa_coeffs_of(mepa, k / nm, k % nm);
    }
}
