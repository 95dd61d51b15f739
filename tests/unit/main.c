/* main.c — runs every unit-test suite of tests/unit; exit status is the number of failures. */
#include "unit.h"

int run_inlet_tests(void);
int run_servo_tests(void);
int run_mesh_tests(void);
int run_mesh_motion_tests(void);

int main(void) {
    int failed = 0;
    failed += run_kernel_tests();
    failed += run_laws_tests();
    failed += run_geometry_tests();
    failed += run_h5md_tests();
    failed += run_watchdog_tests();
    failed += run_guard_tests();
    failed += run_bond_tests();
    failed += run_h5md_bonds_tests();
    failed += run_h5md_output_tests();
    failed += run_hugepages_tests();
    failed += run_inlet_tests();
    failed += run_servo_tests();
    failed += run_mesh_tests();
    failed += run_mesh_motion_tests();
    return failed;
}
