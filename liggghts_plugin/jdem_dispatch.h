/* jdem_dispatch.h — maps the run-time feature bits (JD_F_*) of a run to a compile-time constant,
 * so that every call of jd_contact() is specialised for the laws the run uses (DESIGN.md: "leave
 * out what a scene does not need").  JD_DISPATCH(bits, CALL) expands to a switch whose cases
 * invoke CALL(literal) for the 32 combinations of the five JD_F_* bits. */
#ifndef JDEM_PLUGIN_DISPATCH_H
#define JDEM_PLUGIN_DISPATCH_H

#include "jdem_kernel.h"

#define JD_ALL_FEATURES 31u

/* On the declaration of a force loop templated on the feature bits: inline every kernel call
 * into it.  jd_contact() is too large for GCC's inliner at -O2, so without this each loop would
 * call one generic out-of-line copy that tests the feature bits at run time (measured with
 * callgrind: a single `jd_contact` symbol for all 32 instantiations).  Inlining does not change
 * the arithmetic (-ffp-contract=off, no fast-math). */
#define JD_SPECIALISED __attribute__((flatten))

#define JD_DISPATCH_CASE(b, CALL) \
  case (b): CALL(b); break;
#define JD_DISPATCH(bits, CALL)                                                           \
  switch ((bits) & JD_ALL_FEATURES) {                                                     \
    JD_DISPATCH_CASE(0u, CALL) JD_DISPATCH_CASE(1u, CALL) JD_DISPATCH_CASE(2u, CALL)      \
    JD_DISPATCH_CASE(3u, CALL) JD_DISPATCH_CASE(4u, CALL) JD_DISPATCH_CASE(5u, CALL)      \
    JD_DISPATCH_CASE(6u, CALL) JD_DISPATCH_CASE(7u, CALL) JD_DISPATCH_CASE(8u, CALL)      \
    JD_DISPATCH_CASE(9u, CALL) JD_DISPATCH_CASE(10u, CALL) JD_DISPATCH_CASE(11u, CALL)    \
    JD_DISPATCH_CASE(12u, CALL) JD_DISPATCH_CASE(13u, CALL) JD_DISPATCH_CASE(14u, CALL)   \
    JD_DISPATCH_CASE(15u, CALL) JD_DISPATCH_CASE(16u, CALL) JD_DISPATCH_CASE(17u, CALL)   \
    JD_DISPATCH_CASE(18u, CALL) JD_DISPATCH_CASE(19u, CALL) JD_DISPATCH_CASE(20u, CALL)   \
    JD_DISPATCH_CASE(21u, CALL) JD_DISPATCH_CASE(22u, CALL) JD_DISPATCH_CASE(23u, CALL)   \
    JD_DISPATCH_CASE(24u, CALL) JD_DISPATCH_CASE(25u, CALL) JD_DISPATCH_CASE(26u, CALL)   \
    JD_DISPATCH_CASE(27u, CALL) JD_DISPATCH_CASE(28u, CALL) JD_DISPATCH_CASE(29u, CALL)   \
    JD_DISPATCH_CASE(30u, CALL) JD_DISPATCH_CASE(31u, CALL) default: break;               \
  }

#endif
