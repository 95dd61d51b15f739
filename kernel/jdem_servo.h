/*
 * jdem_servo.h — the servo-controlled wall of Jiang (2021) Sec. 2.7.2 and the boundary stress
 * tensor of eq. (45): one rule for both engines' compression tests.
 *
 * Pure C11. No I/O, no allocation, no globals.  docs/mixing.md explains the scene keys and the
 * defaults of the Ch. 4 campaign; units are SI (m, s, N, Pa).
 *
 * Sign conventions.  A servo wall has a unit normal n pointing into the sample (its active side).
 * Its measured stress is the normal force the particles exert on it per unit area, positive in
 * compression: sigma = -(F . n) / A, F the sum of the particles' forces on the wall.  The wall
 * velocity is returned as a speed along n: positive moves the wall into the sample (compressing).
 *
 * The law (the seed's V = alpha |sigma_meas - sigma_req|, towards reducing the difference):
 *
 *     e = sigma_req - sigma_meas,    speed = 0                        if |e| <= tolerance,
 *                                    speed = clamp(alpha e, -v_max, v_max) otherwise,
 *
 * so the wall advances while the stress is too low and retreats while it is too high.  Hold: the
 * test is complete ("done") once |e| <= tolerance has held for hold_steps consecutive steps; an
 * excursion beyond the tolerance before then restarts the count (and the wall moves again).  Once
 * done the wall stays where it is.
 *
 * For a linear bed of stiffness k [N/m] under a wall of area A, one step changes the error by the
 * factor 1 - alpha k dt / A: the error decays without overshoot for alpha <= A / (k dt)
 * (jd_servo_gain_limit), oscillates beyond it and diverges beyond twice it.  The measured force
 * also holds the damping of the wall's contacts, which sees the wall's own speed: with C [N s/m]
 * their summed damping coefficient, a speed error is multiplied by -alpha C / A each step, so
 * alpha must also stay below A / C, or the wall chatters between +-v_max (docs/model.md sec. 10).
 */
#ifndef JDEM_KERNEL_SERVO_H
#define JDEM_KERNEL_SERVO_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/* The description of one servo wall, fixed for a run (the resolved scene's `servo:` entry). */
typedef struct jd_servo_spec {
    double target;      /* required normal stress sigma_req, > 0 (compression)          [Pa]     */
    double gain;        /* alpha, > 0                                                   [m/(s Pa)] */
    double tolerance;   /* |e| at or below which the wall stops, >= 0                   [Pa]     */
    double max_speed;   /* v_max, > 0 (INFINITY: no cap)                                [m/s]    */
    int64_t hold_steps; /* consecutive steps within tolerance that complete the test, >= 1 [-]   */
} jd_servo_spec;

/* The state of a servo wall during a run (zero-initialised at the start). */
typedef struct jd_servo_state {
    int64_t held; /* consecutive steps within tolerance so far                        [-]   */
    int done;     /* 1 once held reached hold_steps: the wall holds for good          [-]   */
} jd_servo_state;

/* Result codes of jd_servo_check. */
typedef enum {
    JD_SERVO_OK = 0,
    JD_SERVO_BAD_TARGET,    /* target <= 0 (the wrong sign: a servo wall only pushes) or not finite */
    JD_SERVO_BAD_GAIN,      /* gain <= 0 or not finite                                   */
    JD_SERVO_BAD_TOLERANCE, /* tolerance < 0 or not finite                               */
    JD_SERVO_BAD_MAX_SPEED, /* max_speed <= 0 (or NaN)                                   */
    JD_SERVO_BAD_HOLD       /* hold_steps < 1                                            */
} jd_servo_status;

/* Check a description.  Returns JD_SERVO_OK, or the code of the first bad value (in the order
 * above, so that the engines can name its key) with a one-line message in msg naming the value
 * and what would be valid (the engines prefix the scene file and key). */
jd_servo_status jd_servo_check(const jd_servo_spec *s, char *msg, size_t msglen);

/* The hold of a test in steps: a duration hold > 0 [s] at time step dt > 0 [s] is
 * ceil(hold / dt) steps, at least 1. */
int64_t jd_servo_hold_steps(double hold, double dt);

/* Area [m^2] of a planar convex quadrilateral with corners p in order around its edge: half
 * the norm of the cross product of its diagonals. */
double jd_servo_area(const double p[4][3]);

/* Measured stress of a wall [Pa], > 0 in compression: -(F . n) / area, with F [N] the particles'
 * total force on the wall, n its unit normal into the sample, area > 0 [m^2]. */
double jd_servo_stress(const double force[3], const double normal[3], double area);

/* The wall's speed along n for this step [m/s] from the measured stress [Pa]; updates the hold
 * count and `done` in st (the header comment gives the law). */
double jd_servo_speed(const jd_servo_spec *s, jd_servo_state *st, double measured);

/* The largest gain [m/(s Pa)] for which a linear bed of stiffness k > 0 [N/m] under a wall of
 * area > 0 [m^2] reaches the target without overshoot at time step dt > 0 [s]: area / (k dt). */
double jd_servo_gain_limit(double stiffness, double area, double dt);

/* Boundary stress tensor, eq. (45): sigma_ij = (1/V) sum_k (x_k - c)_i f_k,j over n contacts,
 * with x [3n] the contact points [m], f [3n] the forces the particles exert on the walls there
 * [N] (so the tensor is positive in compression), c the sample centre [m] (the sum is independent
 * of c only when the forces balance) and V > 0 the current sample volume [m^3].  sigma is [9],
 * row-major (sigma[3 i + j]) [Pa]. */
/* The sample box of the stress tensor, bounded by n >= 1 plane walls with corners p [12 n] (4
 * per wall, at their current positions) [m] and unit normals nrm [3 n] into the sample: along
 * each axis d the box runs from the highest wall facing +d (n_d >= 1 - 1e-9) to the lowest
 * facing -d, and on a side without such a wall to the extreme corner.  Returns its centre [m]
 * and volume [m^3] (0 when the walls leave no room). */
void jd_servo_box(size_t n, const double *p, const double *nrm, double centre[3],
                  double *volume);

void jd_stress_tensor(size_t n, const double *x, const double *f, const double centre[3],
                      double volume, double sigma[9]);

#ifdef __cplusplus
}
#endif

#endif
