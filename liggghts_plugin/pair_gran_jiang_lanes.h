/* pair_gran_jiang_lanes.h — the pair style's contacts evaluated in SIMD lanes, as the standalone
 * engine evaluates them (stepper/forces.c, batch_evaluate).
 *
 * The pair loop walks LIGGGHTS' neighbour lists as before and tests every pair with LIGGGHTS'
 * rsq < radsum^2; a pair that passes is queued here with copies of what its law reads (the
 * geometry's centre offset, the radii, the particles' prefactors, masses, velocities, the
 * coefficients of its types, its history record).  Every JdPairLanes::N queued pairs, one loop
 * over lanes evaluates the kernel's geometry and law (jd_geom_spheres_fill, jd_contact) on those
 * copies only: the compiler sees arrays of one local object that alias nothing and vectorises
 * it.  The pair loop then applies the lanes in queue order (PairGranJiang::apply_lanes), which is
 * the order in which the one-pair-at-a-time loop applied them: every force, torque, history and
 * sum is the same operation on the same values in the same order, so the results are that
 * loop's bit for bit, and the standalone engine's: the cross-engine suites (cross-engine's piles
 * of 64 spheres, several batches a step, on 1 and 2 ranks, with and without the energy accounts;
 * pour; law-sets) compare the trajectories with build/jdem's.
 *
 * Only the time-step evaluation of a law set without run-time laws takes the lanes; LIGGGHTS'
 * set-up evaluation, compute pair/gran/local and Mindlin's K_t keep the plain loop. */
#ifndef JDEM_PAIR_GRAN_JIANG_LANES_H
#define JDEM_PAIR_GRAN_JIANG_LANES_H

#include "jdem_geometry.h"
#include "jdem_kernel.h"
#include "jdem_laws.h"

template <unsigned F>
struct JdPairLanes {
  enum {
    N = 32, /* contacts per batch: a multiple of the widest vector; the batch stays in L1 */
    HW = (F & JD_F_ENERGY) ? JD_CONTACT_ENERGY_LEN : JD_CONTACT_LAWS_LEN, /* contact record
                                                                       (never MEPA's) */
    RW = (F & JD_F_ROLLING) ? ((F & JD_F_ENERGY) ? JD_ROLLING_STATE_LEN : JD_ROLLING_LAWS_LEN) : 0,
    RW_ROWS = RW > 0 ? RW : 1
  };
  int n; /* queued pairs */

  /* the queue: LIGGGHTS' atoms i, j of each pair, its history record and touch flag */
  int i[N], j[N];
  double *hist[N];
  int *touch[N];

  /* what the law reads, copied at queueing: dx = x_j - x_i [m], rsq = |dx|^2 [m^2], radii [m],
   * Hertz prefactors [N/m^1.5], masses [kg], velocities [m/s] and angular velocities [rad/s] of
   * i (a) and j (b), the coefficients of the pair's types, and the history record (rec: the
   * contact record's HW doubles, roll: the rolling record's RW) */
  double dx[3][N], rsq[N], ri[N], rj[N], kpi[N], kpj[N], mi[N], mj[N];
  double va[3][N], wa[3][N], vb[3][N], wb[3][N];
  double gamma[N], mu[N], eta[N], mu_r[N];
  int xi_limit[N];
  double rec[HW][N], roll[RW_ROWS][N];

  /* what the law returns: contact (jd_geom_spheres_fill's verdict), carries (jd_contact's),
   * the overlap [m], the force on j [N] and the torques on i and j [N m]; the history after
   * the step in rec and roll */
  int contact[N], carries[N];
  double delta[N], f[3][N], ta[3][N], tb[3][N];
};

/* The lanes [0, L.n): geometry and law on the queued copies, dt [s].  No data-dependent branch:
 * a lane whose geometry is no contact (its centres exactly radsum apart after the rounding of
 * sqrt, or coincident) computes a meaningless law, possibly NaN or infinite, that apply_lanes
 * discards (no floating-point trap is ever enabled: the build's -fno-trapping-math). */
template <unsigned F>
static inline void jd_pair_lanes_evaluate(JdPairLanes<F> &__restrict L, double dt) {
  typedef JdPairLanes<F> Lanes;
  for (int b = 0; b < L.n; b++) {
    const double dx[3] = {L.dx[0][b], L.dx[1][b], L.dx[2][b]};
    const double ri = L.ri[b], rj = L.rj[b], mi = L.mi[b], mj = L.mj[b];
    jd_contact_geom g;
    L.contact[b] = jd_geom_spheres_fill(dx, L.rsq[b], ri, rj, &g);
    g.r_roll = jd_rolling_radius(ri, rj);
    jd_geom_pair_material(F, &g, L.kpi[b], L.kpj[b], mi, mj, jd_sphere_inertia(mi, ri),
                          jd_sphere_inertia(mj, rj));
    jd_kinematics k;
    for (int d = 0; d < 3; d++) {
      k.va[d] = L.va[d][b];
      k.wa[d] = L.wa[d][b];
      k.vb[d] = L.vb[d][b];
      k.wb[d] = L.wb[d][b];
    }
    jd_pair_coeffs co;
    co.gamma = L.gamma[b];
    co.mu = L.mu[b];
    co.eta = L.eta[b];
    co.mu_r = L.mu_r[b];
    co.xi_limit = L.xi_limit[b];
    co.g_star = 0.0; /* Mindlin's K_t (a run-time law) never takes the lanes */
    co.g_wall = 0.0;
    double h[Lanes::HW], r[Lanes::RW_ROWS];
    /* unrolled whole, as jd_record_load (GCC peels at most 16 iterations by itself): the loop
     * over lanes stays the one that is vectorised */
#pragma GCC unroll 32
    for (int q = 0; q < Lanes::HW; q++) h[q] = L.rec[q][b];
#pragma GCC unroll 32
    for (int q = 0; q < Lanes::RW; q++) r[q] = L.roll[q][b];
    jd_contact_state st;
    jd_rolling_state rs;
    jd_record_load(h, Lanes::HW, r, Lanes::RW, &st, (F & JD_F_ROLLING) ? &rs : NULL);
    jd_contact_result out;
    L.carries[b] = jd_contact(F, &co, &g, &k, dt, &st, (F & JD_F_ROLLING) ? &rs : NULL, &out);
    jd_record_store(h, Lanes::HW, r, Lanes::RW, &st, &rs);
#pragma GCC unroll 32
    for (int q = 0; q < Lanes::HW; q++) L.rec[q][b] = h[q];
#pragma GCC unroll 32
    for (int q = 0; q < Lanes::RW; q++) L.roll[q][b] = r[q];
    L.delta[b] = g.delta;
    for (int d = 0; d < 3; d++) {
      L.f[d][b] = out.f[d];
      L.ta[d][b] = out.ta[d];
      L.tb[d][b] = out.tb[d];
    }
  }
}

#endif
