/* jdem_servo.c — the servo wall's law and the boundary stress (jdem_servo.h has the definitions). */
#include "jdem_servo.h"

#include <math.h>
#include <stdio.h>

jd_servo_status jd_servo_check(const jd_servo_spec *s, char *msg, size_t msglen) {
    if (!(s->target > 0.0) || !isfinite(s->target)) {
        snprintf(msg, msglen, "servo target %g Pa has the wrong sign; valid: a compressive "
                              "stress > 0 (the wall pushes on the sample)",
                 s->target);
        return JD_SERVO_BAD_TARGET;
    }
    if (!(s->gain > 0.0) || !isfinite(s->gain)) {
        snprintf(msg, msglen, "servo gain %g is not valid; valid: a number > 0 [m/(s Pa)]",
                 s->gain);
        return JD_SERVO_BAD_VALUE;
    }
    if (!(s->tolerance >= 0.0) || !isfinite(s->tolerance)) {
        snprintf(msg, msglen, "servo tolerance %g is not valid; valid: a number >= 0 [Pa]",
                 s->tolerance);
        return JD_SERVO_BAD_VALUE;
    }
    if (!(s->max_speed > 0.0)) {
        snprintf(msg, msglen, "servo max_speed %g is not valid; valid: a number > 0 [m/s], or .inf",
                 s->max_speed);
        return JD_SERVO_BAD_VALUE;
    }
    if (s->hold_steps < 1) {
        snprintf(msg, msglen, "servo hold %lld steps is not valid; valid: at least 1 step",
                 (long long)s->hold_steps);
        return JD_SERVO_BAD_VALUE;
    }
    if (msglen > 0)
        msg[0] = '\0';
    return JD_SERVO_OK;
}

double jd_servo_stress(const double force[3], const double normal[3], double area) {
    return -(force[0] * normal[0] + force[1] * normal[1] + force[2] * normal[2]) / area;
}

double jd_servo_speed(const jd_servo_spec *s, jd_servo_state *st, double measured) {
    if (st->done)
        return 0.0;
    const double error = s->target - measured;
    if (fabs(error) <= s->tolerance) {
        if (++st->held >= s->hold_steps)
            st->done = 1;
        return 0.0;
    }
    st->held = 0;
    const double speed = s->gain * error;
    return speed > s->max_speed ? s->max_speed : speed < -s->max_speed ? -s->max_speed : speed;
}

double jd_servo_gain_limit(double stiffness, double area, double dt) {
    return area / (stiffness * dt);
}

void jd_stress_tensor(size_t n, const double *x, const double *f, const double centre[3],
                      double volume, double sigma[9]) {
    for (int k = 0; k < 9; k++)
        sigma[k] = 0.0;
    for (size_t c = 0; c < n; c++)
        for (int i = 0; i < 3; i++)
            for (int j = 0; j < 3; j++)
                sigma[3 * i + j] += (x[3 * c + i] - centre[i]) * f[3 * c + j];
    for (int k = 0; k < 9; k++)
        sigma[k] /= volume;
}
