/*
 * jdem_inlet.h — the conveyor inlet of Jiang (2021) Sec. 2.7.3: one rule for both engines.
 *
 * Pure C11. No I/O, no allocation, no globals.  Both engines (the stepper and the LIGGGHTS fix)
 * call these functions on the same description, so the particle stream (ids, insertion steps,
 * positions, velocities, order) is identical by construction.  docs/mixing.md explains the
 * design and the scene keys; units are SI (m, s, m/s).
 *
 * The stream.  A section of n particles (positions relative to the section's origin) rides a belt
 * at the constant velocity v.  Copy c of the section sits one period L behind copy c - 1 along
 * the belt direction u = v/|v|; at step k (time t_k = k dt) particle p of copy c would be at
 *
 *     x(c, p, k) = b(c, p) + v t_k,      b(c, p) = (origin + rel_p) - (offset + c L) u,
 *
 * each component evaluated in exactly that order (the sums left to right; the library is built
 * with -ffp-contract=off, so no fused multiply-add changes a bit).  The particle takes part in
 * nothing until its centre crosses the inlet plane (point P, normal N pointing into the domain);
 * from its crossing step on it is an ordinary particle, placed at x(c, p, k*) with velocity v.
 *
 * Crossing step.  With the signed distance of the rigid motion
 *
 *     s(c, p, k) = a(c, p) + k w,   a(c, p) = N.(origin + rel_p - P) - (offset + c L) (N.u),
 *                                    w = (N.v) dt,
 *
 * (N.q = N_x q_x + N_y q_y + N_z q_z, left to right), the crossing step k*(c, p) is the smallest
 * integer k >= 0 with s(c, p, k) >= 0.  Because w > 0 (a checked condition) and k w is rounded
 * monotonically, s is non-decreasing in k in floating point too, so k* is well defined whatever
 * the round-off; it is found from the estimate ceil(-a/w) and corrected by evaluating s itself.
 * N need not be a unit vector: only the sign of s matters.
 *
 * Ids and order.  Particle p of copy c has id first_id + c n + p.  The particles inserted at
 * one step are inserted in increasing id (copy, then position in the section).  A particle of a
 * bonded group (spec.group_of, "Bonded groups of a section" below) is inserted at its group's
 * start step instead of its own crossing step; every other one at its crossing step.
 *
 * Stop rule.  Copies are inserted whole: copy c belongs to the stream if c < max_sections (when
 * max_sections > 0) and its start step (the smallest k* of its particles) is < stop_step.  A
 * deposit-height rule is measured by the engine with jd_inlet_deposit_top at the steps
 * jd_inlet_height_due names, and jd_inlet_height_stop then lowers jd_inlet_stream.stop_step to
 * the next step: copies already started are completed, no new copy starts.
 */
#ifndef JDEM_KERNEL_INLET_H
#define JDEM_KERNEL_INLET_H

#include <stddef.h>
#include <stdint.h>

#include "jdem_bond.h"

#ifdef __cplusplus
extern "C" {
#endif

/* No step limit: the stream ends by max_sections or by the engine's deposit-height rule. */
#define JD_INLET_NO_STOP INT64_MAX

/* A particle that never crosses (past the stop rule): its step is JD_INLET_NEVER. */
#define JD_INLET_NEVER INT64_MAX

/* The overlap_tol of a generated section: the round-off of a lattice of touching spheres, as the
 * scene reader's start-overlap rule (docs/scenes.md "Start overlaps"). */
#define JD_INLET_OVERLAP_TOL 1e-6

/* The default max_insert_overlap: any overlap with a particle already in the domain skips the
 * insertion, as LIGGGHTS' insertion fixes do with `overlapcheck yes` (their default). */
#define JD_INLET_MAX_INSERT_OVERLAP 0.0

/* The description of one inlet, fixed for a run (the resolved scene's `inlets:` entry). */
typedef struct jd_inlet_spec {
    size_t n;               /* particles per section, >= 1                                 [-]   */
    const double *rel;      /* [3n] positions relative to the section origin               [m]   */
    const double *radius;   /* [n] radii, > 0                                              [m]   */
    const int32_t *species; /* [n] material index of each particle (copied to the output)  [-]   */
    double origin[3];       /* position of copy 0's origin at t = 0 (before offset)         [m]   */
    double velocity[3];     /* belt velocity v, non-zero; every inserted particle's velocity [m/s] */
    double plane_point[3];  /* a point P of the inlet plane                                [m]   */
    double plane_normal[3]; /* normal N of the plane, towards the domain (any length > 0)  [-]   */
    double period;          /* L: distance between copies along u, > 0 (unused if max_sections = 1) [m] */
    double offset;          /* distance copy 0 is set back along u from origin, >= 0       [m]   */
    double dt;              /* time step, > 0                                              [s]   */
    int64_t first_id;       /* id of particle 0 of copy 0, > 0                             [-]   */
    int64_t max_sections;   /* copies in the stream, >= 1, or 0 for no limit               [-]   */
    int64_t stop_step;      /* no copy starts at or after this step, > 0, or JD_INLET_NO_STOP [-] */
    double overlap_tol;     /* overlap allowed between section particles (of one copy, or of
                               neighbouring copies), fraction of the smaller radius, >= 0:
                               JD_INLET_OVERLAP_TOL, or for cells cut from a deposit the largest
                               contact overlap it may hold (the watchdog's limit)      [-]   */
    double max_insert_overlap; /* the insertion rule of "Insertion into an occupied place"
                               below: the largest overlap, fraction of the smaller radius, with a
                               particle already in the domain at which a particle is still
                               inserted, >= 0; INFINITY: always inserted             [-]   */
    /* Bonded groups (see "Bonded groups of a section" below); n_groups = 0 (and NULL arrays):
     * none, every particle is inserted at its own crossing step. */
    size_t n_groups;             /* groups of the section                              [-]   */
    const size_t *group_first;   /* [n_groups + 1]: group g's members are
                                    group_member[group_first[g] .. group_first[g + 1])  [-]   */
    const size_t *group_member;  /* section indices, increasing within a group         [-]   */
    const int32_t *group_of;     /* [n] the group of each particle, or -1: in none     [-]   */
} jd_inlet_spec;

/* Result codes of jd_inlet_check. */
typedef enum {
    JD_INLET_OK = 0,
    JD_INLET_EMPTY,          /* n = 0 or a NULL array                                          */
    JD_INLET_BAD_VALUE,      /* a radius, dt, period, offset, id or limit out of range or NaN   */
    JD_INLET_NO_NORMAL,      /* plane normal of zero length                                     */
    JD_INLET_NEVER_CROSSES,  /* N.v <= 0: the belt is parallel to the plane or moves away      */
    JD_INLET_ALREADY_INSIDE, /* a particle of copy 0 is on the domain side at step 0           */
    JD_INLET_OVERLAP,        /* two particles of one copy overlap                               */
    JD_INLET_PERIOD_OVERLAP, /* a particle overlaps one of a neighbouring copy across L         */
    JD_INLET_NO_STOP_RULE,   /* max_sections = 0 and stop_step = JD_INLET_NO_STOP (the engine
                                must then have a deposit-height rule: pass allow_unbounded)    */
    JD_INLET_BAD_GROUP       /* group arrays missing or inconsistent (an index >= n, a particle
                                in two groups, an empty group, group_of not matching)          */
} jd_inlet_status;

/* Check a description.  Returns JD_INLET_OK, or a code with a one-line message in msg (naming
 * the value, the particle indices (0-based, in the section) and what would be valid) that the
 * engines prefix with the scene file and key.  allow_unbounded = 1 accepts a stream without a
 * step or section limit (the engine stops it by deposit height).  O(n^2) in the section size. */
jd_inlet_status jd_inlet_check(const jd_inlet_spec *s, int allow_unbounded, char *msg,
                               size_t msglen);

/* Signed distance s(c, p, k) of the header comment [m times |N|]. */
double jd_inlet_signed_distance(const jd_inlet_spec *s, int64_t copy, size_t p, int64_t step);

/* Crossing step k*(c, p) of the header comment (the stop rule is not applied here). */
int64_t jd_inlet_crossing_step(const jd_inlet_spec *s, int64_t copy, size_t p);

/* Start step of copy c: the smallest crossing step of its particles. O(n). */
int64_t jd_inlet_section_start(const jd_inlet_spec *s, int64_t copy);

/* One inserted particle. */
typedef struct jd_inlet_particle {
    int64_t id;          /* first_id + c n + p                                       [-]   */
    int64_t copy;        /* c                                                        [-]   */
    size_t index;        /* p, its position in the section                           [-]   */
    int64_t step;        /* the crossing step k*, at which it becomes a particle     [-]   */
    double position[3];  /* x(c, p, k*)                                              [m]   */
    double velocity[3];  /* the belt velocity v                                      [m/s] */
    double radius;       /* [m] */
    int32_t species;     /* [-] */
} jd_inlet_particle;

/* Particle p of copy c at its crossing step (the stop rule is not applied here). */
void jd_inlet_particle_at_crossing(const jd_inlet_spec *s, int64_t copy, size_t p,
                                   jd_inlet_particle *out);

/* Particle p of copy c at an arbitrary step k (>= 0): id, copy and index as at its crossing,
 * step = k, position x(c, p, k) of the rigid belt motion (the same sums, in the same order, as
 * at its crossing) [m], velocity v [m/s]. */
void jd_inlet_particle_at_step(const jd_inlet_spec *s, int64_t copy, size_t p, int64_t step,
                               jd_inlet_particle *out);

/* ---- Bonded groups of a section (Jiang (2021) Ch. 5: the 2 x 2 x 8 blocks) ----
 *
 * A group is a set of section particles bonded to one another.  Rule: in every copy a group is
 * inserted whole at its start step, the smallest crossing step k* of its members: every member
 * is placed at x(c, p, start) (the members not yet across the plane still at their rigid belt
 * positions), so no bond ever joins an inserted particle to one not yet inserted.  The copy's
 * bonds are formed at that step, unstressed (the belt is rigid: every bond has its section
 * length), between the ids the stream's id rule gives.  The spec's group arrays (n_groups,
 * group_first, group_member, group_of) name the groups; jd_inlet_stream/jd_inlet_pop then insert
 * each member at jd_inlet_insertion_step.  The engine forms the bonds (the stepper: the
 * resolved section's bonds of every copy whose group was popped at the step). */

/* Start step of a group of copy c: the smallest k*(c, p) over members[0 .. n_members) (indices
 * in the section); JD_INLET_NEVER when n_members = 0.  O(n_members). */
int64_t jd_inlet_group_start(const jd_inlet_spec *s, int64_t copy, const size_t *members,
                             size_t n_members);

/* The ids of the bond joining section particles i and j (i != j) in copy c, the smaller first
 * (the order of the resolved `bonds:` entries): first_id + c n + min(i, j), then the larger. */
void jd_inlet_bond_ids(const jd_inlet_spec *s, int64_t copy, size_t i, size_t j, int64_t ids[2]);

/* The section's bonds in the one order both engines resolve them to: each pair [2 n_bonds] of
 * section indices turned smaller first, and the bonds sorted by (smaller, larger) in place, their
 * types [n_bonds] moved with them (heap sort: no allocation; the order of equal pairs is
 * unspecified, and equal pairs are an error).  Returns the index k > 0 of the first bond whose
 * pair repeats bond k - 1's, or n_bonds when every pair is bonded once.  O(n_bonds log n_bonds). */
size_t jd_inlet_sort_bonds(size_t n_bonds, int32_t *pair, int32_t *type);

/* The groups of a section from its bonds (pairs [2 n_bonds] of section indices < n): the
 * connected components of the bond graph, numbered in the order of their smallest member; a
 * particle in no bond is in no group.  Fills group_of [n] (-1: none), group_first [n_groups + 1]
 * (the caller gives room for n + 1) and group_member [n] (each group's members increasing), with
 * parent [n] as work space, and returns n_groups: the spec's group arrays.  O(n + n_bonds). */
size_t jd_inlet_groups(size_t n, size_t n_bonds, const int32_t *pair, int32_t *parent,
                       int32_t *group_of, size_t *group_first, size_t *group_member);

/* For the time-step guard (kernel/jdem_guard.h, bond_omega2): the largest over the section's
 * particles of the sum of jd_bond_omega2_pair over its bonds, each at its section length
 * (the length it is formed at) [rad^2/s^2].  pair [2 n_bonds] as for jd_inlet_groups;
 * params[type[b]] the parameters of bond b's type; mass [n] the section particles' masses [kg];
 * work [n].  0 without bonds. */
double jd_inlet_bond_omega2(const jd_inlet_spec *s, const double *mass, size_t n_bonds,
                            const int32_t *pair, const int32_t *type,
                            const jd_bond_params *const *params, double *work);

/* The step at which particle p of copy c is inserted (the stop rule is not applied here): the
 * start step of its group (s->group_of[p] >= 0), else its own crossing step k*.  O(group size). */
int64_t jd_inlet_insertion_step(const jd_inlet_spec *s, int64_t copy, size_t p);

/* The state of a stream during a run: one cursor per section particle (an array of n that the
 * engine allocates), the next copy of that particle due and its step.  The engine compares the
 * current step with next_step only, so particles not yet inserted cost nothing per step. */
typedef struct jd_inlet_cursor {
    int64_t copy; /* the next copy of this section particle to insert             [-] */
    int64_t step; /* its crossing step, or JD_INLET_NEVER when its stream is over [-] */
} jd_inlet_cursor;

typedef struct jd_inlet_stream {
    jd_inlet_cursor *cursor; /* [n], owned by the engine                                  */
    int64_t started;         /* copies started so far (admitted by the stop rule)     [-] */
    int64_t stop_step;       /* copy of the spec's; the engine lowers it to stop by height [-] */
    int64_t next_step;       /* the smallest cursor step: nothing to do before it     [-] */
    int64_t inserted;        /* particles inserted so far                             [-] */
    int64_t skipped;         /* particles not inserted: their place was occupied      [-] */
} jd_inlet_stream;

/* Initialise a stream (cursor: an array of s->n entries). */
void jd_inlet_stream_init(const jd_inlet_spec *s, jd_inlet_stream *st, jd_inlet_cursor *cursor);

/* Insert the particles due at `step` (call it whenever step == st->next_step; a step with nothing
 * due returns 0): each at jd_inlet_insertion_step, at its position x(c, p, step).  Writes at most cap particles in insertion order (increasing id) and returns
 * how many it wrote; when more than cap are due, the rest stay due (call again with the same
 * step).  Updates st->next_step. */
size_t jd_inlet_pop(const jd_inlet_spec *s, jd_inlet_stream *st, int64_t step,
                    jd_inlet_particle *out, size_t cap);

/* Copies of the stream that start at or before step `last` and are admitted by its limits:
 * max_sections and stop_step (the spec's, or a stream's lowered one, jd_inlet_height_stop)
 * [-].  build/jdem sizes its buffers by it, and the progress estimate counts its copies. */
int64_t jd_inlet_copies_by(const jd_inlet_spec *s, int64_t stop_step, int64_t last);

/* The work the stream still brings until step `last` [particle-steps]: for every particle not
 * yet inserted (cursor[p].copy up to copies - 1, copies from jd_inlet_copies_by) whose insertion
 * step k <= last, last - k steps of it in the domain.  One particle's copies cross one period
 * apart in time (a rigid motion), so its share is summed in closed form as an arithmetic series
 * between its first and last pending insertion step.  The steps themselves are whole (k is the
 * first step at or past the crossing), so each term may be off by less than one step: the sum is
 * within the number of pending insertions it counts of the exact one (exact when a period is a
 * whole number of steps).
 * A progress line's ETA divides the work left (this plus the particles present times the steps
 * left) by the measured particle-steps per second.  O(n) jd_inlet_insertion_step calls. */
double jd_inlet_pending_particle_steps(const jd_inlet_spec *s, const jd_inlet_cursor *cursor,
                                       int64_t copies, int64_t last);

/* ---- Insertion into an occupied place ----
 *
 * The pending stream is rigid and takes part in nothing, so a particle already in the domain can
 * sit where a pending one is about to cross: one knocked back against the belt, or one that lags
 * behind the belt as its block tips over the plane (docs/mixing.md 1.1).  Inserting the pending
 * particle there would start a contact at an arbitrary overlap, with the elastic energy of it.
 * Rule (LIGGGHTS' overlap check of its insertion fixes): a particle due at a step whose position
 * overlaps a particle already in the domain by more than spec.max_insert_overlap times the
 * smaller radius is not inserted, and neither is any other member of its bonded group in that
 * copy.  It is skipped for good: the stream goes on with its next copy, and the skipped particles
 * are counted (jd_inlet_stream.skipped).  The engine calls, at every step with particles due:
 *   jd_inlet_worst_overlaps on all of the step's due particles (of one inlet) against the
 *   particles in the domain before the step's insertions, jd_inlet_skip_groups, then
 *   jd_inlet_book_skipped, and inserts the rest. */

/* The overlap of spheres (a, ra) and (b, rb) as a fraction of the smaller radius:
 * (ra + rb - |a - b|) / min(ra, rb); <= 0 when they are apart.  Positions [m], radii [m]. */
double jd_inlet_overlap_fraction(const double a[3], double ra, const double b[3], double rb);

/* For each due particle q (n_due of them), the largest overlap fraction worst[q] with the n
 * particles (x [3n] [m], radius [n] [m]) and the index with[q] of that particle (the first of
 * equal ones); worst[q] = -INFINITY and with[q] = SIZE_MAX when none is within reach.  Only
 * the particles in the box of the due particles (widened by each one's own radius) are
 * compared.  O(n + candidates n_due). */
void jd_inlet_worst_overlaps(const jd_inlet_particle *due, size_t n_due, size_t n, const double *x,
                             const double *radius, double *worst, size_t *with);

/* The skip decision of the due particles (in pop order: increasing id): skip[q] = 1 when
 * worst[q] > s->max_insert_overlap or when another due member of q's bonded group in the same
 * copy has it; 0 otherwise.  Returns the number skipped.  O(n_due) without groups, O(n_due^2)
 * at worst with them. */
size_t jd_inlet_skip_groups(const jd_inlet_spec *s, const jd_inlet_particle *due, size_t n_due,
                            const double *worst, unsigned char *skip);

/* The engines report the first JD_INLET_REPORTED skips of a run on their error stream, then
 * count the rest (observable skipped_particles). */
#define JD_INLET_REPORTED 10

/* Why a due particle is skipped, the text both engines report after "skips particle id I: "
 * (worst, with_id: its jd_inlet_worst_overlaps value and the id of that particle), then the
 * limit, and for the JD_INLET_REPORTED-th (nth) skip the note that the rest are only counted. */
int jd_inlet_skip_reason(char *buf, size_t len, double worst, int64_t with_id,
                         double max_insert_overlap, int64_t nth);

/* Book n_skipped particles that jd_inlet_pop returned but the engine did not insert. */
void jd_inlet_book_skipped(jd_inlet_stream *st, size_t n_skipped);

/* ---- The stop rules both engines apply, and the insertion record ---- */

/* Stop rule `time`: no copy starts at or after step ceil(time/dt); JD_INLET_NO_STOP when that
 * step is beyond int64 (time > 0 and dt > 0 [s]). */
int64_t jd_inlet_stop_step_of_time(double time, double dt);

/* Stop rule `deposit_height`: it is checked at the steps every, 2 every, ... (step > 0), on the
 * state of the step after that step's insertions (so the particles inserted at it count). */
int jd_inlet_height_due(int64_t step, int64_t every);

/* The deposit's top [m]: the largest x_z + R over the n particles (x, v: [3n] in particle order;
 * radius: [n]) whose speed is below below_speed [m/s] (|v|^2 < below_speed^2); -INFINITY when
 * none is.  An engine spread over ranks takes the maximum of the ranks' tops. */
double jd_inlet_deposit_top(size_t n, const double *x, const double *v, const double *radius,
                            double below_speed);

/* A top at or above height [m] found at `step` stops the stream from the next step on: no copy
 * starts after `step` (copies already started are completed). */
void jd_inlet_height_stop(jd_inlet_stream *st, int64_t step, double top, double height);

/* The insertion record (`jdem run --inlet-record`, fix jdem/inlet `record`): a CSV file with this
 * header line, then one line per inserted particle in insertion order. */
#define JD_INLET_RECORD_HEADER "id,step,x,y,z,vx,vy,vz\n"

/* Longest record line, with its newline and terminating NUL [bytes]. */
#define JD_INLET_RECORD_LINE_MAX 256

/* The record line of one inserted particle ("id,step,x,y,z,vx,vy,vz\n", the numbers to 17
 * significant digits: they read back bit for bit) into buf of len bytes; returns its length. */
int jd_inlet_record_line(const jd_inlet_particle *p, char *buf, size_t len);

#ifdef __cplusplus
}
#endif

#endif
