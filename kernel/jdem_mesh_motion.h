/*
 * jdem_mesh_motion.h — how a mesh wall moves and how fast its surface goes: a rigid
 * translation, a rigid rotation about a fixed axis, or a conveyor surface (the triangles stay,
 * the surface slides along itself).
 *
 * LIGGGHTS moves a mesh with its own code (fix move/mesh linear and rotate, fix mesh/surface
 * surface_vel); these functions do the same arithmetic, operation for operation, so that the
 * standalone engine's triangles and wall velocities equal LIGGGHTS' bit for bit and the two
 * engines open the same contacts with the same forces:
 *   - a step moves every corner incrementally, as move/mesh does (not from the start
 *     position): translation adds velocity * dt; rotation turns corner - origin by the unit
 *     quaternion of the angle omega dt (two quaternion products, then adds origin back; the
 *     subtraction and addition are skipped when the origin is (0, 0, 0), as LIGGGHTS skips them);
 *   - the corners' velocities after the step: the translation velocity, or (omega axis) x
 *     (corner - origin) at the moved corner;
 *   - a spinning surface's corner velocity (surface_ang_vel): omega axis x (corner - origin),
 *     its normal part removed and rescaled as a conveyor's;
 *   - a conveyor's corner velocity: the surface velocity's component tangential to the
 *     triangle, rescaled to the surface velocity's magnitude.  Where the surface velocity is
 *     normal to a triangle (its tangential part below 1e-12 of it) the triangle is at rest;
 *     LIGGGHTS rescales the rounding remainder to full speed in an arbitrary direction there
 *     (for instance on the end faces of a belt), the one place where the engines differ.
 * A mesh that moves has the velocities of its motion at every evaluation, the first (step 0)
 * included; LIGGGHTS' set-up evaluation sees a moving mesh at rest (move/mesh sets them at its
 * first step), which differs only for a sphere touching a moving mesh at time 0.
 *
 * Pure C11.  No I/O, no allocation, no globals.  Units SI.
 */
#ifndef JDEM_KERNEL_MESH_MOTION_H
#define JDEM_KERNEL_MESH_MOTION_H

#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

enum { JD_MESH_STILL = 0, JD_MESH_TRANSLATING = 1, JD_MESH_ROTATING = 2 };

typedef struct jd_mesh_motion {
    int kind;            /* JD_MESH_STILL, JD_MESH_TRANSLATING or JD_MESH_ROTATING             */
    double velocity[3];  /* translating: the mesh's velocity                             [m/s] */
    double origin[3];    /* rotating: a point of the axis                                  [m] */
    double axis[3];      /* rotating: the unit axis (the given axis times 1/|axis|)            */
    double axis_q[3];    /* the unit axis normalised once more, as move/mesh builds its
                          * quaternion from it                                                 */
    double omega;        /* rotating: 2 pi / period, signed (right hand about axis)  [rad/s] */
} jd_mesh_motion;

/* A mesh at rest. */
void jd_mesh_motion_still(jd_mesh_motion *m);

/* A translation at velocity v [m/s] (fix move/mesh ... linear vx vy vz). */
void jd_mesh_motion_translating(jd_mesh_motion *m, const double v[3]);

/* A rotation about the axis through origin [m] along axis (any length > 0), one turn per
 * period [s] (non-zero; negative turns the other way) (fix move/mesh ... rotate origin ...
 * axis ... period ...).  Returns 0, or -1 when axis is (0, 0, 0) or period is 0 or not finite. */
int jd_mesh_motion_rotating(jd_mesh_motion *m, const double origin[3], const double axis[3],
                            double period);

/* One time step dt [s] of the motion: the n corners corner[k] [m] moved in place. */
void jd_mesh_motion_step(const jd_mesh_motion *m, double dt, size_t n, double (*corner)[3]);

/* The velocity v[k] [m/s] of the moving mesh at its n corners corner[k] [m] (where they are
 * now); zero for a mesh at rest. */
void jd_mesh_motion_velocity(const jd_mesh_motion *m, size_t n, const double (*corner)[3],
                             double (*v)[3]);

/* The conveyor velocity [m/s] of the three corners of triangle t[3][3] [m] for a surface
 * velocity u [m/s]: u minus its component along the triangle's unit normal
 * ((t1 - t0)/|t1 - t0| x (t2 - t1)/|t2 - t1|, normalised), rescaled to |u|, or zero when that
 * remainder is below 1e-12 |u|; the same at the three corners. */
void jd_mesh_conveyor_velocity(const double u[3], const double t[3][3], double v[3][3]);

/* The velocity [m/s] of the three corners of triangle t[3][3] [m] of a surface spinning at
 * omega [rad/s] about the axis through origin [m] along axis (any length > 0), the triangles
 * staying in place (LIGGGHTS' fix mesh/surface surface_ang_vel, operation for operation): at
 * corner c, w = -omega (t_c - origin) x axis/|axis|, minus its component along the triangle's
 * unit normal (jd_mesh_conveyor_velocity's), rescaled to |w| (left as it is when nothing
 * remains).  For a surface of revolution about the axis, w is tangential already. */
void jd_mesh_spin_velocity(const double origin[3], const double axis[3], double omega,
                           const double t[3][3], double v[3][3]);

#ifdef __cplusplus
}
#endif

#endif
