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
        return JD_SERVO_BAD_GAIN;
    }
    if (!(s->tolerance >= 0.0) || !isfinite(s->tolerance)) {
        snprintf(msg, msglen, "servo tolerance %g is not valid; valid: a number >= 0 [Pa]",
                 s->tolerance);
        return JD_SERVO_BAD_TOLERANCE;
    }
    if (!(s->max_speed > 0.0)) {
        snprintf(msg, msglen, "servo max_speed %g is not valid; valid: a number > 0 [m/s], or .inf",
                 s->max_speed);
        return JD_SERVO_BAD_MAX_SPEED;
    }
    if (s->hold_steps < 1) {
        snprintf(msg, msglen, "servo hold %lld steps is not valid; valid: at least 1 step",
                 (long long)s->hold_steps);
        return JD_SERVO_BAD_HOLD;
    }
    if (msglen > 0)
        msg[0] = '\0';
    return JD_SERVO_OK;
}

int64_t jd_servo_hold_steps(double hold, double dt) {
    const double steps = ceil(hold / dt);
    return steps < 1.0 ? 1 : (int64_t)steps;
}

double jd_servo_area(const double p[4][3]) {
    const double a[3] = {p[2][0] - p[0][0], p[2][1] - p[0][1], p[2][2] - p[0][2]};
    const double b[3] = {p[3][0] - p[1][0], p[3][1] - p[1][1], p[3][2] - p[1][2]};
    const double c[3] = {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2],
                         a[0] * b[1] - a[1] * b[0]};
    return 0.5 * sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]);
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

/* A wall faces an axis when its normal is that axis to within this much of its length. */
#define JD_BOX_FACING (1.0 - 1e-9)

void jd_servo_box(size_t n, const double *p, const double *nrm, double centre[3],
                  double *volume) {
    *volume = 1.0;
    for (int d = 0; d < 3; d++) {
        double lo = INFINITY, hi = -INFINITY, face_lo = -INFINITY, face_hi = INFINITY;
        for (size_t k = 0; k < n; k++) {
            for (int c = 0; c < 4; c++) {
                lo = fmin(lo, p[12 * k + 3 * c + d]);
                hi = fmax(hi, p[12 * k + 3 * c + d]);
            }
            if (nrm[3 * k + d] >= JD_BOX_FACING) face_lo = fmax(face_lo, p[12 * k + d]);
            if (nrm[3 * k + d] <= -JD_BOX_FACING) face_hi = fmin(face_hi, p[12 * k + d]);
        }
        if (isfinite(face_lo)) lo = face_lo;
        if (isfinite(face_hi)) hi = face_hi;
        centre[d] = 0.5 * (lo + hi);
        *volume *= fmax(hi - lo, 0.0);
    }
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
