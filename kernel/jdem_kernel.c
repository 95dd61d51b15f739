/*
 * jdem_kernel.c — set-up functions of the contact kernel: damping mappings and time-step
 * bounds.  Called once per run (per species pair), never inside a force loop.
 * See jdem_kernel.h for the contracts and docs/model.md for the derivations.
 */
#include "jdem_kernel.h"

double jd_gamma_jiang2021(double e) {
    if (e >= 1.0) return 0.0;
    const double l = log(e);
    return -l / sqrt(JD_PI * JD_PI + l * l);
}

/* Dimensionless Hertz impact with the seed's damping: x'' = -x^1.5 - 2 gamma x^0.25 x',
 * x(0) = 0, x'(0) = 1 (mass, stiffness prefactor and approach speed scaled to one; the scaling is
 * exact because C_n = 2 gamma sqrt(m k) delta^0.25).  The force is f = x^1.5 + 2 gamma x^0.25 x'. */
static void jd_impact_rhs(double gamma, double x, double v, double *dx, double *dv) {
    const double xp = x > 0.0 ? x : 0.0;
    *dx = v;
    *dv = -(xp * sqrt(xp) + 2.0 * gamma * sqrt(sqrt(xp)) * v);
}

double jd_restitution_for_gamma(double gamma) {
    if (gamma <= 0.0) return 1.0;
    /* The undamped contact lasts 3.218 time units; damping shortens it.  h = 2e-5 keeps the
     * RK4 error near the x^0.25 singularity at first touch below 1e-7 in e. */
    const double h = 2e-5;
    double x = 0.0, v = 1.0;
    for (long i = 0; i < 2000000; i++) {
        double k1x, k1v, k2x, k2v, k3x, k3v, k4x, k4v;
        jd_impact_rhs(gamma, x, v, &k1x, &k1v);
        jd_impact_rhs(gamma, x + 0.5 * h * k1x, v + 0.5 * h * k1v, &k2x, &k2v);
        jd_impact_rhs(gamma, x + 0.5 * h * k2x, v + 0.5 * h * k2v, &k3x, &k3v);
        jd_impact_rhs(gamma, x + h * k3x, v + h * k3v, &k4x, &k4v);
        const double xn = x + h / 6.0 * (k1x + 2.0 * k2x + 2.0 * k3x + k4x);
        const double vn = v + h / 6.0 * (k1v + 2.0 * k2v + 2.0 * k3v + k4v);
        if (xn <= 0.0) { /* left the contact with positive force all along */
            const double s = x / (x - xn);
            return -(v + s * (vn - v));
        }
        const double fn = xn * sqrt(xn) + 2.0 * gamma * sqrt(sqrt(xn)) * vn;
        if (vn < 0.0 && fn <= 0.0) { /* Luding's end of collision */
            const double f0 = x * sqrt(x) + 2.0 * gamma * sqrt(sqrt(x)) * v;
            const double s = f0 > 0.0 ? f0 / (f0 - fn) : 0.0;
            return -(v + s * (vn - v));
        }
        x = xn;
        v = vn;
    }
    return -v; /* not reached for finite gamma */
}

double jd_gamma_exact(double e) {
    if (e >= 1.0) return 0.0;
    if (!(e > 0.0)) return INFINITY;
    /* e(gamma) decreases monotonically from 1 (gamma = 0) towards 0 (gamma -> infinity). */
    double lo = 0.0, hi = 1.0;
    while (jd_restitution_for_gamma(hi) > e && hi < 1e6) {
        lo = hi;
        hi *= 2.0;
    }
    /* Secant steps safeguarded by bisection (Illinois variant). */
    double flo = 1.0 - e, fhi = jd_restitution_for_gamma(hi) - e;
    int side = 0;
    for (int it = 0; it < 100; it++) {
        double mid = (lo * fhi - hi * flo) / (fhi - flo);
        if (!(mid > lo && mid < hi)) mid = 0.5 * (lo + hi);
        const double fm = jd_restitution_for_gamma(mid) - e;
        if (fabs(fm) < 1e-12 || hi - lo < 1e-13 * hi) return mid;
        if ((fm > 0.0) == (flo > 0.0)) {
            lo = mid;
            flo = fm;
            if (side == -1) fhi *= 0.5;
            side = -1;
        } else {
            hi = mid;
            fhi = fm;
            if (side == 1) flo *= 0.5;
            side = 1;
        }
    }
    return 0.5 * (lo + hi);
}

double jd_gamma_for(int damping_map, double e) {
    return damping_map == JD_DAMP_EXACT ? jd_gamma_exact(e) : jd_gamma_jiang2021(e);
}

double jd_rayleigh_step(double R, double rho, double E, double nu) {
    const double G = E / (2.0 * (1.0 + nu));
    return JD_PI * R * sqrt(rho / G) / (0.1631 * nu + 0.876605);
}

/* For x'' = -x^1.5, x(0) = 0, x'(0) = 1: x_max = (5/4)^(2/5) and the contact lasts
 * 2 x_max (2/5) B(2/5, 1/2) in the time unit (m/k)^(2/5) v^(-1/5). */
double jd_hertz_contact_time(double m_eff, double k_n, double v) {
    const double beta = tgamma(0.4) * tgamma(0.5) / tgamma(0.9);
    const double tau = 2.0 * pow(1.25, 0.4) * 0.4 * beta;
    return tau * pow(m_eff / k_n, 0.4) * pow(v, -0.2);
}

double jd_hertz_peak_overlap(double m_eff, double k_n, double v) {
    return pow(1.25 * m_eff * v * v / k_n, 0.4); /* 1/2 m v^2 = 2/5 k d^2.5 */
}

/* Loading along k1 d^n from speed v: 1/2 m v^2 = k1 d^(n+1)/(n+1) at the peak, reached after
 * d_pk/v times the integral of (1 - x^(n+1))^(-1/2) over [0, 1], (1/(n+1)) B(1/(n+1), 1/2).
 * Unloading along k2 is taken as a quarter period at the branch's tangent stiffness at the
 * peak, n k2 d_pk^(n-1), its stiffest: exact for n = 1, shorter than the true unloading for
 * n > 1.  The peak ignores the k2 branch past the virgin branch's end: there the estimate's
 * peak is deeper (for n > 1 a stiffer tangent, which only tightens the Verlet bound) and its
 * loading longer than the true impact's, so the contact-time bound is then not conservative
 * (docs/model.md §13). */
double jd_mepa_impact_time(double m_eff, double k1, double k2, double n, double v,
                           double *peak_overlap) {
    const double p = 1.0 / (n + 1.0);
    const double d = pow((n + 1.0) * m_eff * v * v / (2.0 * k1), p);
    const double load = d / v * p * tgamma(p) * tgamma(0.5) / tgamma(p + 0.5);
    const double unload = 0.5 * JD_PI * sqrt(m_eff / (n * k2 * pow(d, n - 1.0)));
    *peak_overlap = d;
    return load + unload;
}

double jd_hertz_peak_force(double m_eff, double k_n, double v) {
    const double d = jd_hertz_peak_overlap(m_eff, k_n, v);
    return k_n * d * sqrt(d);
}
