/*
 * unit.h — shared by the unit-test files: cmocka includes, the relative-error assertion, and the
 * suite entry points that main.c runs.  Each tests/unit/test_*.c defines one run_*_tests().
 */
#ifndef JDEM_TEST_UNIT_H
#define JDEM_TEST_UNIT_H

#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

/* |actual - expected| <= tol |expected| (tol absolute when expected is 0). */
#define assert_rel(actual, expected, tol)                                                          \
    do {                                                                                           \
        const double a_ = (actual), e_ = (expected), t_ = (tol);                                   \
        const double err_ = e_ != 0.0 ? fabs(a_ - e_) / fabs(e_) : fabs(a_);                       \
        if (!(err_ <= t_))                                                                         \
            fail_msg("%s = %.17g, expected %.17g (error %.3g > %.3g)", #actual, a_, e_, err_, t_); \
    } while (0)

int run_kernel_tests(void);
int run_geometry_tests(void);
int run_h5md_tests(void);
int run_watchdog_tests(void);
int run_guard_tests(void);
int run_bond_tests(void);
int run_laws_tests(void);
int run_h5md_bonds_tests(void);
int run_h5md_output_tests(void); /* test_h5md_output.c */
int run_hugepages_tests(void);

#endif
