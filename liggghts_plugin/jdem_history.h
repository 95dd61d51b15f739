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

#endif
