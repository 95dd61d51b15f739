/*
 * jdem_laws.h — the rulebook both engines apply around the contact law (docs/adding_a_law.md):
 *   - the list of valid law sets, which every force-loop dispatcher expands (JD_LAW_SETS);
 *   - which law set a run needs, from the interactions that can occur (jd_law_set_select);
 *   - the coefficients of every pair of materials (jd_pair_coeffs_table);
 *   - the layout of the per-contact history record a law set keeps (jd_record_*).
 * The stepper (stepper/sim.c, forces.c) and the LIGGGHTS styles (liggghts_plugin/) call these
 * and decide nothing of their own.  Pure C11: no I/O, no allocation, no globals.
 */
#ifndef JDEM_KERNEL_LAWS_H
#define JDEM_KERNEL_LAWS_H

#include <stddef.h>

#include "jdem_bond.h"
#include "jdem_kernel.h"

#ifdef __cplusplus
extern "C" {
#endif

/* ------------------------------------------------------------------------------------------ */
/* The valid law sets.  X(bits) once per set, bits a constant expression of JD_F_* flags; a    */
/* dispatcher expands JD_LAW_LOOPS(X) into its cases (a switch, template instantiations), so   */
/* that each compiled set has one specialised copy of the force loops and no other copy is     */
/* compiled.  A new law set is one line of JD_LAW_SETS_WITH.  mu_R modifies the tangential     */
/* law only, so JD_F_MU_R comes with JD_F_FRICTION; so does JD_F_MINDLIN, which changes the    */
/* tangential spring only (JD_LAW_SETS_TANGENTIAL); every set exists with and without the      */
/* energy bookkeeping.                                                                         */
/* ------------------------------------------------------------------------------------------ */
#define JD_LAW_SETS_TANGENTIAL(X, E)                                           \
    X((E) | JD_F_FRICTION)                                                     \
    X((E) | JD_F_DAMPING | JD_F_FRICTION)                                      \
    X((E) | JD_F_FRICTION | JD_F_ROLLING)                                      \
    X((E) | JD_F_DAMPING | JD_F_FRICTION | JD_F_ROLLING)                       \
    X((E) | JD_F_FRICTION | JD_F_MU_R)                                         \
    X((E) | JD_F_DAMPING | JD_F_FRICTION | JD_F_MU_R)                          \
    X((E) | JD_F_FRICTION | JD_F_ROLLING | JD_F_MU_R)                          \
    X((E) | JD_F_DAMPING | JD_F_FRICTION | JD_F_ROLLING | JD_F_MU_R)
#define JD_LAW_SETS_WITH(X, E)                                                 \
    X((E) | 0u)                                                                \
    X((E) | JD_F_DAMPING)                                                      \
    X((E) | JD_F_ROLLING)                                                      \
    X((E) | JD_F_DAMPING | JD_F_ROLLING)                                       \
    JD_LAW_SETS_TANGENTIAL(X, E)
#define JD_LAW_LOOPS(X) JD_LAW_SETS_WITH(X, 0u) JD_LAW_SETS_WITH(X, JD_F_ENERGY)
#define JD_LAW_SETS_RUN_TIME(X, M)                                             \
    JD_LAW_SETS_TANGENTIAL(X, (M) | JD_F_MINDLIN)                              \
    JD_LAW_SETS_TANGENTIAL(X, (M) | JD_F_ENERGY | JD_F_MINDLIN)
#define JD_LAW_SETS(X)                                                         \
    JD_LAW_LOOPS(X)                                                            \
    JD_LAW_SETS_RUN_TIME(X, 0u)                                                \
    JD_LAW_SETS_WITH(X, JD_F_MEPA)                                             \
    JD_LAW_SETS_WITH(X, JD_F_MEPA | JD_F_ENERGY)                               \
    JD_LAW_SETS_RUN_TIME(X, JD_F_MEPA)

/* The laws no compiled loop is specialised for: Mindlin's K_t changes one scalar per contact
 * (jd_tangential_stiffness), so compiling the tangential copies twice is not worth it
 * (docs/performance.md, "Build time"); MEPA's normal law is a model choice few runs make, and
 * compiling every set once more for it would double the build.  The plugin's scalar loops take
 * the bits as a branch (jd_law_set_of_loop); the stepper's SIMD lanes would turn them into
 * selects that every run pays, so a run with one takes the stepper's reference loops.
 * JD_LAW_LOOPS holds every law set without these bits. */
#define JD_F_RUN_TIME (JD_F_MINDLIN | JD_F_MEPA)

/* The compiled loop that runs law set bits: a dispatcher switches on this and expands
 * JD_LAW_LOOPS; the loop then passes jd_law_set_of_loop to the kernel. */
static inline unsigned jd_law_set_loop(unsigned bits) { return bits & ~(unsigned)JD_F_RUN_TIME; }

/* The law set inside the compiled loop `loop` (a literal of JD_LAW_LOOPS) of a run whose law
 * set is bits: the loop's constant bits and the run-time ones of bits (JD_F_MINDLIN only in a
 * loop with friction, which it comes with). */
#define jd_law_set_of_loop(loop, bits)                                           \
    ((loop) | ((bits) & (unsigned)JD_F_MEPA) |                                   \
     (((loop) & JD_F_FRICTION) ? (bits) & (unsigned)JD_F_MINDLIN : 0u))

/* Every JD_F_* bit, for masking a law set. */
#define JD_F_ALL \
    (JD_F_DAMPING | JD_F_FRICTION | JD_F_ROLLING | JD_F_MU_R | JD_F_ENERGY | JD_F_MINDLIN | JD_F_MEPA)

/* The bond law's sets (kernel/jdem_bond.h, JD_B_*), expanded the same way by the bond loops. */
#define JD_BOND_LAW_SETS(X) X(0u) X(JD_B_DAMPING) X(JD_B_ENERGY) X(JD_B_DAMPING | JD_B_ENERGY)

/* 1 when bits is one of JD_LAW_SETS, else 0. */
int jd_law_set_valid(unsigned bits);

/* The names of the JD_F_* bits, in bit order, as the engines report a law set ("damping",
 * "friction", "rolling", "mu_r", "energy", "mindlin", "mepa"). */
#define JD_N_LAWS 7
extern const char *const jd_law_names[JD_N_LAWS];

/* The law set as text: the names of its bits joined by '+', or "elastic" for none; into buf
 * (len bytes, always terminated; truncated if too short).  Returns buf. */
char *jd_law_set_describe(unsigned bits, char *buf, size_t len);

/* ------------------------------------------------------------------------------------------ */
/* Which laws a run evaluates.                                                                 */
/* ------------------------------------------------------------------------------------------ */

/* The laws one interaction needs, from the inputs both engines read: the dashpots and Luding's
 * end when its restitution is below 1, the tangential law when its friction is above 0, the
 * rolling law when its rolling friction is above 0. */
static inline unsigned jd_interaction_laws(double restitution, double friction,
                                           double rolling_friction) {
    return (restitution < 1.0 ? (unsigned)JD_F_DAMPING : 0u) |
           (friction > 0.0 ? (unsigned)JD_F_FRICTION : 0u) |
           (rolling_friction > 0.0 ? (unsigned)JD_F_ROLLING : 0u);
}

/* The law set of a run over nm materials: the union of the laws of every interaction that can
 * occur, that is of a material a that some particle has (in_particles[a] != 0) against a
 * material b that some particle or wall has (in_particles[b] or in_walls[b]; in_walls may be
 * NULL: no walls); restitution, friction and rolling_friction are nm x nm, row-major.  Then,
 * when the run has friction, JD_F_MU_R if mu_r != 1 and JD_F_MINDLIN if tangential_rule is
 * JD_KT_MINDLIN (jd_tangential_rule); JD_F_MEPA if normal_law is JD_NORMAL_MEPA
 * (jd_normal_law); JD_F_ENERGY when energy is set.  The result is always one of JD_LAW_SETS. */
unsigned jd_law_set_select(size_t nm, const double *restitution, const double *friction,
                           const double *rolling_friction, const unsigned char *in_particles,
                           const unsigned char *in_walls, double mu_r, int tangential_rule,
                           int normal_law, int energy);

/* MEPA's inputs as both engines read them (Del Cid's LIGGGHTS inputs LoadingStiffness,
 * UnloadingStiffness, CohesiveStiffness per material, NPower, and her hard-coded plasticity
 * depth 0.1). */
typedef struct jd_mepa_inputs {
    const double *k1;   /* per material, > 0                                            [N/m^n] */
    const double *k2;   /* per material, > k1                                            [N/m^n] */
    const double *kadh; /* per material, >= 0                                            [N/m^n] */
    double n;           /* exponent, > 0                                                 [-]     */
    double depth;       /* plastic overlap cap as a fraction of R*, > 0                  [-]     */
} jd_mepa_inputs;

/* The MEPA coefficients of a pair of materials a, b: each stiffness the series combination
 * k_a k_b/(k_a + k_b) of Del Cid's code (0 when both are 0), and the derived ratios. */
jd_mepa_coeffs jd_mepa_coeffs_of(const jd_mepa_inputs *in, size_t a, size_t b);

/* The coefficients of every ordered pair of nm materials into out (nm x nm, row-major, like the
 * three input tables): gamma from the restitution by the damping map (jd_gamma_for, mapped once
 * per distinct value: the exact mapping costs up to ~50 ms), mu, eta, the run's mu_r and
 * xi_limit, and Mindlin's G* from the materials' Young's moduli E [Pa] and Poisson's ratios nu
 * (nm each): g_star of the pair, g_wall of the first material against a rigid wall; MEPA's
 * coefficients (jd_mepa_coeffs_of) when mepa is not NULL, else zero.  A material
 * with E <= 0 (no elastic properties: a wall-only material) counts as rigid; G* of two rigid
 * materials is 0 (no such contact exists). */
void jd_pair_coeffs_table(size_t nm, const double *restitution, const double *friction,
                          const double *rolling_friction, const double *E, const double *nu,
                          int damping_map, double mu_r, int xi_limit, const jd_mepa_inputs *mepa,
                          jd_pair_coeffs *out);

/* ------------------------------------------------------------------------------------------ */
/* The history record a law set keeps per contact.                                             */
/* A contact record is jd_contact_state whole with JD_F_MEPA (its plastic overlap comes last), */
/* its first JD_CONTACT_ENERGY_LEN doubles with JD_F_ENERGY, else only the fields the laws     */
/* carry from step to step, which lead the struct (xi[3], flags); a rolling record (only with  */
/* JD_F_ROLLING) is jd_rolling_state whole with JD_F_ENERGY, else its leading theta[3].  The   */
/* stepper keeps the two in separate arrays; LIGGGHTS in one per-contact array, the rolling    */
/* record after the contact record.                                                            */
/* ------------------------------------------------------------------------------------------ */
#define JD_CONTACT_LAWS_LEN 4 /* xi[3], flags */
#define JD_ROLLING_LAWS_LEN 3 /* theta[3] */

/* The index of a field in a history struct of doubles. */
#define JD_AT(type, field) ((int)(offsetof(type, field) / sizeof(double)))

static inline int jd_contact_record_len(unsigned features) {
    return (features & JD_F_MEPA)     ? JD_CONTACT_STATE_LEN
           : (features & JD_F_ENERGY) ? JD_CONTACT_ENERGY_LEN
                                      : JD_CONTACT_LAWS_LEN;
}
static inline int jd_rolling_record_len(unsigned features) {
    return (features & JD_F_ROLLING)
               ? ((features & JD_F_ENERGY) ? JD_ROLLING_STATE_LEN : JD_ROLLING_LAWS_LEN)
               : 0;
}

/* LIGGGHTS' sign-flip flag of entry k of a combined record whose contact record holds hw
 * doubles (1: a vector component that changes sign when the bodies swap). */
static inline int jd_record_newton(int hw, int k) {
    return k < hw ? jd_contact_state_newton[k] : jd_rolling_state_newton[k - hw];
}

/* A contact's records (h: hw doubles; r: rw doubles, may be NULL when rw is 0) as the kernel's
 * structs, the fields they do not keep zero (rs may be NULL: no rolling struct wanted). */
static JD_ALWAYS_INLINE void jd_record_load(const double *h, int hw, const double *r, int rw,
                                            jd_contact_state *st, jd_rolling_state *rs) {
    double *a = (double *)st;
    /* unrolled whole (GCC peels at most 16 iterations by itself), so that an engine's loop over
     * contacts around it stays the one that is vectorised */
#pragma GCC unroll 32
    for (int k = 0; k < JD_CONTACT_STATE_LEN; k++) a[k] = k < hw ? h[k] : 0.0;
    if (rs) {
        double *b = (double *)rs;
        for (int k = 0; k < JD_ROLLING_STATE_LEN; k++) b[k] = k < rw ? r[k] : 0.0;
    }
}

/* The kept fields of st (and of rs, when rw > 0) into the records. */
static JD_ALWAYS_INLINE void jd_record_store(double *h, int hw, double *r, int rw,
                                             const jd_contact_state *st,
                                             const jd_rolling_state *rs) {
    const double *a = (const double *)st, *b = (const double *)rs;
    for (int k = 0; k < hw; k++) h[k] = a[k];
    for (int k = 0; k < rw; k++) r[k] = b[k];
}

/* The records of a contact whose bodies separated, as jd_contact_separate leaves the structs
 * (every field zero but the dissipation accumulators e_damp and e_fric, which the engines
 * harvest), written in place. */
static JD_ALWAYS_INLINE void jd_record_separate(double *h, int hw, double *r, int rw) {
    for (int k = 0; k < hw; k++)
        if (k != JD_AT(jd_contact_state, e_damp) && k != JD_AT(jd_contact_state, e_fric)) h[k] = 0.0;
    for (int k = 0; k < rw; k++) r[k] = 0.0;
}

/* A bond's record: jd_bond_state whole with JD_B_ENERGY, else its leading law fields (fn, ft,
 * mn, mt, flags). */
#define JD_BOND_LAWS_LEN 9
static inline int jd_bond_record_len(unsigned bond_features) {
    return (bond_features & JD_B_ENERGY) ? JD_BOND_STATE_LEN : JD_BOND_LAWS_LEN;
}

/* A bond record of sw doubles as the kernel's struct (the energy fields zero when not kept), and
 * back.  Field by field, not through a double *: GCC then keeps the struct in registers instead
 * of copying it through the stack. */
static JD_ALWAYS_INLINE jd_bond_state jd_bond_record_load(const double *a, int sw) {
    const int full = sw == JD_BOND_STATE_LEN;
    jd_bond_state st;
    st.fn = a[JD_AT(jd_bond_state, fn)];
    st.mn = a[JD_AT(jd_bond_state, mn)];
    st.flags = a[JD_AT(jd_bond_state, flags)];
    for (int d = 0; d < 3; d++) {
        st.ft[d] = a[JD_AT(jd_bond_state, ft) + d];
        st.mt[d] = a[JD_AT(jd_bond_state, mt) + d];
        st.f_prev[d] = full ? a[JD_AT(jd_bond_state, f_prev) + d] : 0.0;
        st.ts_prev[d] = full ? a[JD_AT(jd_bond_state, ts_prev) + d] : 0.0;
        st.td_prev[d] = full ? a[JD_AT(jd_bond_state, td_prev) + d] : 0.0;
    }
    st.u_prev = full ? a[JD_AT(jd_bond_state, u_prev)] : 0.0;
    st.e_damp = full ? a[JD_AT(jd_bond_state, e_damp)] : 0.0;
    st.e_break = full ? a[JD_AT(jd_bond_state, e_break)] : 0.0;
    return st;
}

static JD_ALWAYS_INLINE void jd_bond_record_store(double *a, int sw, const jd_bond_state *st) {
    a[JD_AT(jd_bond_state, fn)] = st->fn;
    a[JD_AT(jd_bond_state, mn)] = st->mn;
    a[JD_AT(jd_bond_state, flags)] = st->flags;
    for (int d = 0; d < 3; d++) {
        a[JD_AT(jd_bond_state, ft) + d] = st->ft[d];
        a[JD_AT(jd_bond_state, mt) + d] = st->mt[d];
    }
    if (sw == JD_BOND_STATE_LEN) {
        for (int d = 0; d < 3; d++) {
            a[JD_AT(jd_bond_state, f_prev) + d] = st->f_prev[d];
            a[JD_AT(jd_bond_state, ts_prev) + d] = st->ts_prev[d];
            a[JD_AT(jd_bond_state, td_prev) + d] = st->td_prev[d];
        }
        a[JD_AT(jd_bond_state, u_prev)] = st->u_prev;
        a[JD_AT(jd_bond_state, e_damp)] = st->e_damp;
        a[JD_AT(jd_bond_state, e_break)] = st->e_break;
    }
}

#ifdef __cplusplus
}
#endif
#endif /* JDEM_KERNEL_LAWS_H */
