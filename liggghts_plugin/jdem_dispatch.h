/* jdem_dispatch.h — maps the run-time law set (JD_F_* bits) of a run to a compile-time constant,
 * so that every call of jd_contact() is specialised for the laws the run uses.
 * JD_DISPATCH(bits, CASE) expands to a switch over the kernel's list of compiled law sets
 * (jdem_laws.h, JD_LAW_LOOPS), where CASE(b) is the caller's macro for one case ("case (b):
 * loop<(b)>(); break;"); no other copy is compiled.  The loop passes
 * jd_law_set_of_loop(b, bits) to the kernel, which adds the run's run-time laws. */
#ifndef JDEM_PLUGIN_DISPATCH_H
#define JDEM_PLUGIN_DISPATCH_H

#include "jdem_laws.h"

/* On the declaration of a force loop templated on the law set: inline every kernel call into
 * it (the kernel's laws are JD_ALWAYS_INLINE; this also takes the engine's helpers along).
 * Inlining does not change the arithmetic (-ffp-contract=off, no fast-math). */
#define JD_SPECIALISED __attribute__((flatten))

#define JD_DISPATCH(bits, CASE)      \
  switch (jd_law_set_loop(bits)) {   \
    JD_LAW_LOOPS(CASE)               \
    default: break;                  \
  }

#endif
