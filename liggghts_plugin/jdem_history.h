/* jdem_history.h — moves a contact's kernel state (jd_contact_state, and jd_rolling_state when
 * the run has rolling) between LIGGGHTS' flat per-contact history arrays and the kernel.  Shared
 * by the pair style and the wall fix.
 *
 * Two layouts of the stored history (doubles per contact), the kernel's records (jdem_laws.h,
 * jd_contact_record_len):
 *  - with the energy accounts (pair_style gran/jiang energy yes): jd_contact_state up to its
 *    energy fields (JD_CONTACT_ENERGY_LEN; the whole of it, JD_CONTACT_STATE_LEN, with MEPA's
 *    plastic overlap), then the whole jd_rolling_state when rolling is on;
 *  - without them (energy no): only what the laws carry from one step to the next, xi[3] and
 *    flags (JD_CONTACT_LAWS_LEN; with MEPA the whole state), then theta[3] with rolling
 *    (JD_ROLLING_LAWS_LEN): 4 or 7 doubles instead of 17 or 23.  LIGGGHTS' fix contacthistory copies the history of every
 *    neighbour pair at each neighbour build and the pair loop streams all of it every step, so
 *    the shorter record is less memory traffic (docs/liggghts.md, "Cost").
 * jd_contact() reads and writes the energy fields only under JD_F_ENERGY (jd_contact_separate
 * zeroes them always), so a loop without JD_F_ENERGY evaluates a local jd_contact_state filled
 * from the law fields and stores those back: the same arithmetic on the same values. */
#ifndef JDEM_PLUGIN_HISTORY_H
#define JDEM_PLUGIN_HISTORY_H

#include <cstring>

#include "jdem_kernel.h"
#include "jdem_laws.h"

/* The laws whose records a contact's history holds: the energy bookkeeping's (keyword energy
 * yes), the rolling law's (keyword rolling on) and MEPA's (keyword normal_law mepa).  The layout
 * of each record is the kernel's (jdem_laws.h): the contact record, then the rolling record. */
static inline unsigned jd_history_laws(bool energy, bool rolling, bool mepa) {
  return (energy ? (unsigned)JD_F_ENERGY : 0u) | (rolling ? (unsigned)JD_F_ROLLING : 0u) |
         (mepa ? (unsigned)JD_F_MEPA : 0u);
}
/* Doubles of the contact record, which is where the rolling part starts. */
static inline int jd_history_contact_len(bool energy, bool mepa) {
  return jd_contact_record_len(jd_history_laws(energy, false, mepa));
}
static inline int jd_history_len(bool energy, bool rolling, bool mepa) {
  const unsigned laws = jd_history_laws(energy, rolling, mepa);
  return jd_contact_record_len(laws) + jd_rolling_record_len(laws);
}
/* LIGGGHTS' sign-flip flag of entry k of the record (the kernel's). */
static inline int jd_history_newton(bool energy, bool mepa, int k) {
  return jd_record_newton(jd_history_contact_len(energy, mepa), k);
}

/* Read the state stored at h, whose contact record holds hw doubles (the rest of st zero; rs:
 * NULL without rolling; energy-accounts layout). */
static inline void jd_load_history(const double *h, int hw, jd_contact_state &st,
                                   jd_rolling_state *rs) {
  jd_record_load(h, hw, h + hw, rs ? JD_ROLLING_STATE_LEN : 0, &st, rs);
}

/* Write an evaluated state back to h (energy-accounts layout, hw doubles of contact record):
 * all of it after a time step; after LIGGGHTS' set-up evaluation (commit false), which must not
 * advance the history, only the energy reference (jd_contact_keep_reference). */
static inline void jd_store_history(double *h, int hw, const jd_contact_state &st,
                                    const jd_rolling_state *rs, bool commit) {
  jd_contact_state out = st;
  jd_rolling_state rout;
  if (rs) rout = *rs;
  if (!commit) jd_load_history(h, hw, out, rs ? &rout : NULL);
  if (!commit) jd_contact_keep_reference(&out, &st, rs ? &rout : NULL, rs);
  jd_record_store(h, hw, h + hw, rs ? JD_ROLLING_STATE_LEN : 0, &out, rs ? &rout : NULL);
}

/* The state of one contact during an evaluation by a loop with feature bits F.
 *  - With JD_F_ENERGY (energy-accounts layout): in a time step, the stored history itself (the
 *    kernel advances it in place; the states are plain doubles laid out as LIGGGHTS' history
 *    array); in LIGGGHTS' set-up evaluation (commit false), a copy, of which finish() stores
 *    back only the energy reference (jd_store_history).
 *  - Without: a local state holding the law fields of the record (either layout: the rolling
 *    part starts at roll_at), the energy fields zero; finish() stores the law fields back after
 *    a time step, nothing after the set-up evaluation. */
template <unsigned F>
struct JdHistory {
  enum { RW = (F & JD_F_ROLLING) ? JD_ROLLING_LAWS_LEN : 0 }; /* the short rolling record */
  jd_contact_state *st;
  jd_rolling_state *rs; /* NULL without rolling */

  /* h: the record; roll_at: offset of its rolling part, the contact record's length.  With the
   * energy accounts in a time step the kernel works on the record in place: it reads and writes
   * a field of jd_contact_state beyond the record (MEPA's dp) only when the run has MEPA, whose
   * record holds the whole state. */
  JdHistory(double *h, int roll_at, bool commit)
      : st(&st_copy_), rs((F & JD_F_ROLLING) ? &rs_copy_ : NULL), h_(h), roll_at_(roll_at),
        commit_(commit) {
    if (F & JD_F_ENERGY) {
      if (commit) {
        st = reinterpret_cast<jd_contact_state *>(h);
        if (F & JD_F_ROLLING) rs = reinterpret_cast<jd_rolling_state *>(h + roll_at);
      } else {
        jd_load_history(h, roll_at, st_copy_, rs);
      }
      return;
    }
    /* the laws' fields (xi, flags) of either layout, or MEPA's whole state (its dp comes last),
     * each with its length a constant so that the copies unroll */
    if (roll_at == JD_CONTACT_STATE_LEN)
      jd_record_load(h, JD_CONTACT_STATE_LEN, h + roll_at, RW, &st_copy_, rs);
    else
      jd_record_load(h, JD_CONTACT_LAWS_LEN, h + roll_at, RW, &st_copy_, rs);
  }
  void finish() {
    if (F & JD_F_ENERGY) {
      if (!commit_) jd_store_history(h_, roll_at_, st_copy_, rs, false);
      return;
    }
    if (!commit_) return;
    if (roll_at_ == JD_CONTACT_STATE_LEN)
      jd_record_store(h_, JD_CONTACT_STATE_LEN, h_ + roll_at_, RW, &st_copy_, rs);
    else
      jd_record_store(h_, JD_CONTACT_LAWS_LEN, h_ + roll_at_, RW, &st_copy_, rs);
  }

 private:
  double *h_;
  int roll_at_;
  bool commit_;
  jd_contact_state st_copy_;
  jd_rolling_state rs_copy_;
};

/* Small vector updates of the force loops, component by component. */
static inline void jd_copy3(double a[3], const double b[3]) {
  a[0] = b[0];
  a[1] = b[1];
  a[2] = b[2];
}
static inline void jd_add3(double a[3], const double b[3]) {
  a[0] += b[0];
  a[1] += b[1];
  a[2] += b[2];
}
static inline void jd_sub3(double a[3], const double b[3]) {
  a[0] -= b[0];
  a[1] -= b[1];
  a[2] -= b[2];
}

#endif
