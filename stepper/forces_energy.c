/*
 * forces_energy.c — the force loops of the law sets with energy bookkeeping (JD_F_ENERGY),
 * instantiated from forces.c's loops in a translation unit of their own, so that a parallel
 * make compiles them beside forces.c's other half (forces.c, sim_force_loops_energy).  The
 * sanitizer build's one loop with run-time features (JD_ONE_FORCE_LOOP) is all in forces.c.
 */
#ifndef JD_ONE_FORCE_LOOP
#define JD_FORCE_LOOPS_ENERGY
#include "forces.c"
#endif
