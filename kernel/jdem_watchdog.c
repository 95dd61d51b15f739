/*
 * jdem_watchdog.c — the watchdog's messages (jdem_watchdog.h), one text for both engines.
 */
#include "jdem_watchdog.h"

#include <stdio.h>

const char *const jd_watchdog_quantities[JD_N_WATCHDOG_QUANTITIES] = {
    "force", "torque", "position", "velocity", "angular velocity"};

void jd_watchdog_nonfinite_message(char *msg, size_t len, long long step, int quantity,
                                   double value, long long id) {
    snprintf(msg, len, "watchdog: step %lld: %s %g for particle(s) %lld is not finite", step,
             jd_watchdog_quantities[quantity], value, id);
}

void jd_watchdog_overlap_message(char *msg, size_t len, long long step, double fraction,
                                 long long id_a, long long id_b, const char *wall, double limit) {
    char with[256];
    if (id_b >= 0)
        snprintf(with, sizeof with, ", %lld", id_b);
    else
        snprintf(with, sizeof with, " against wall '%s'", wall);
    snprintf(msg, len, "watchdog: step %lld: overlap fraction %.6g for particle(s) %lld%s exceeds %g",
             step, fraction, id_a, with, limit);
}

void jd_watchdog_energy_message(char *msg, size_t len, long long step, double jump, long long id,
                                double limit, double total_ref, long long ref_step,
                                double total_now) {
    snprintf(msg, len, "watchdog: step %lld: energy jump %.6g for particle(s) %lld exceeds %g "
             "(total energy %.9g J at step %lld, %.9g J now; the particle named has the largest "
             "kinetic energy)", step, jump, id, limit, total_ref, ref_step, total_now);
}
