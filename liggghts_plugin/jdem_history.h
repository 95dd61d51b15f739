/* jdem_history.h — moves a contact's kernel state (jd_contact_state, and jd_rolling_state when
 * the run has rolling) between LIGGGHTS' flat per-contact history arrays and the kernel.  Shared
 * by the pair style and the wall fix. */
#ifndef JDEM_PLUGIN_HISTORY_H
#define JDEM_PLUGIN_HISTORY_H

#include <cstring>

#include "jdem_kernel.h"

/* Read the state stored at h (rs: NULL without rolling). */
static inline void jd_load_history(const double *h, jd_contact_state &st, jd_rolling_state *rs) {
  std::memcpy(&st, h, sizeof st);
  if (rs) std::memcpy(rs, h + JD_CONTACT_STATE_LEN, sizeof *rs);
}

/* Write an evaluated state back to h: all of it after a time step; after LIGGGHTS' set-up
 * evaluation (commit false), which must not advance the history, only the energy reference
 * (jd_contact_keep_reference). */
static inline void jd_store_history(double *h, const jd_contact_state &st,
                                    const jd_rolling_state *rs, bool commit) {
  jd_contact_state out = st;
  jd_rolling_state rout;
  if (rs) rout = *rs;
  if (!commit) jd_load_history(h, out, rs ? &rout : NULL);
  if (!commit) jd_contact_keep_reference(&out, &st, rs ? &rout : NULL, rs);
  std::memcpy(h, &out, sizeof out);
  if (rs) std::memcpy(h + JD_CONTACT_STATE_LEN, &rout, sizeof rout);
}

/* The state of one contact during an evaluation: in a time step, the stored history itself
 * (the kernel advances it in place; jd_contact_state and jd_rolling_state are plain doubles,
 * laid out as LIGGGHTS' history array, see the static_asserts in pair_gran_jiang.cpp); in
 * LIGGGHTS' set-up evaluation (commit false), a copy, of which finish() stores back only the
 * energy reference (jd_store_history). */
struct JdHistory {
  jd_contact_state *st;
  jd_rolling_state *rs; /* NULL without rolling */

  JdHistory(double *h, bool rolling, bool commit) : st(NULL), rs(NULL), h_(h), commit_(commit) {
    if (commit) {
      st = reinterpret_cast<jd_contact_state *>(h);
      if (rolling) rs = reinterpret_cast<jd_rolling_state *>(h + JD_CONTACT_STATE_LEN);
    } else {
      st = &st_copy_;
      if (rolling) rs = &rs_copy_;
      jd_load_history(h, st_copy_, rs);
    }
  }
  void finish() {
    if (!commit_) jd_store_history(h_, st_copy_, rs, false);
  }

 private:
  double *h_;
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
