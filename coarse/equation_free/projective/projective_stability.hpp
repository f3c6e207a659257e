#pragma once
/// \file
/// Linear stability of projective integration (physics.md §10, §11.1): amplification factors of
/// one outer step for a mode dX/dt = lambda X, and the real intervals where they are <= 1 in
/// magnitude. Times in sqrt(d_p/g), rates lambda in 1/sqrt(d_p/g).

#include <functional>
#include <span>
#include <vector>

namespace efdem::coarse {

/**
 * \brief Projective forward Euler amplification (Gear & Kevrekidis 2003; physics.md §11.1):
 *        sigma(rho) = rho^(K-1) [(M + 1) rho - M].
 *
 * K inner forward-Euler steps of size h (rho = 1 + h lambda each), then extrapolation over M h
 * with the two-point slope of the last two inner values: y_{n+1} = (M+1) y_{n,K} - M y_{n,K-1}.
 * \pre inner_steps K >= 1, extrapolation_steps M >= 0.
 */
double pfe_amplification(double rho, int inner_steps, double extrapolation_steps);

/// A closed real interval [lo, hi].
struct RealInterval {
    double lo = 0.0;
    double hi = 0.0;
};

/**
 * \brief The sub-intervals of [lo, hi] where |g(x)| <= 1, for a continuous amplification g.
 *
 * The boundaries are the roots of g - 1 and g + 1, found separately by sign changes on a scan
 * of n_scan equal steps plus `nodes`, each refined by bisection to ~1e-14 relative; each piece
 * between consecutive roots is then classified at its midpoint. A root is missed only if g - 1
 * or g + 1 changes sign twice between two scan nodes: give the critical points of g as `nodes`
 * (then g is monotone between nodes and nothing is missed), or a finer scan.
 * \pre lo < hi, n_scan >= 1.
 */
std::vector<RealInterval> stable_intervals(const std::function<double(double)>& g, double lo,
                                           double hi, std::span<const double> nodes = {},
                                           int n_scan = 4000);

/**
 * \brief Stable real rho of projective forward Euler: {rho : |sigma(rho)| <= 1}.
 *
 * Exact up to bisection round-off: all real roots of sigma -+ 1 lie in |rho| < 2 (Cauchy bound
 * 1 + max(M, 1)/(M + 1)), and sigma is monotone between its critical points 0 and
 * (K-1) M/(K (M+1)), which are scan nodes. Reproduces the physics.md §11.1 table.
 * \pre K >= 1, M >= 0.
 */
std::vector<RealInterval> pfe_stable_intervals(int inner_steps, double extrapolation_steps);

/// How the coarse slope is estimated from a burst.
enum class SlopeEstimator {
    least_squares,  ///< least-squares line over the last `window` of the burst
    increment,      ///< (X(dt_b) - X(dt_b - W))/W over the last `window` (cpi.slope_fit)
    period_mean     ///< (mean over last period - mean over the one before)/T, T = `window`
};

/// One coarse projective cycle: lift at t = 0, burst to t = burst, jump by dt from the raw
/// end-of-burst value: X_next = X(burst) + dt s.
struct CpiCycle {
    SlopeEstimator estimator = SlopeEstimator::least_squares;
    double burst = 20.0;  ///< dt_b: lift to end of burst [sqrt(d_p/g)]
    double window =
        10.0;          ///< W (least squares, increment) or the period T (period mean) [sqrt(d_p/g)]
    double dt = 80.0;  ///< DT: projective step [sqrt(d_p/g)]
    /// 1: forward Euler from this burst's slope; 2: Adams-Bashforth 2 from this and the
    /// previous burst's (least squares or increment, each placed at its window's middle; every
    /// cycle alike).
    int steps = 1;
};

/**
 * \brief The slope the estimator returns for X(t) = e^(lambda t) (physics.md §10), S(lambda).
 *
 * * least_squares (continuous window [dt_b - W, dt_b], centre tbar = dt_b - W/2):
 *   S = 12 e^(lambda tbar) [(W/lambda) cosh(lambda W/2) - (2/lambda^2) sinh(lambda W/2)] / W^3
 *     = (6/W) e^(lambda tbar) h(u),  h(u) = (u cosh u - sinh u)/u^2,  u = lambda W/2.
 *   For |u| < 1/2, h is summed from its series sum_{n>=1} 2n u^(2n-1)/(2n+1)! (the closed form
 *   cancels), so S -> lambda e^(lambda tbar) smoothly; for larger |u| the exponentials are
 *   combined so that nothing overflows for any lambda < 0.
 * * increment (window [dt_b - W, dt_b]): S = e^(lambda dt_b) (1 - e^(-lambda W)) / W, via expm1
 *   for lambda W > -1. Larger for fast modes than least squares' (the increment's end points see
 *   them undamped): at dt_b = 20, W = 18, DT = 80, G(-0.5) = 1.63 against least squares' 0.85.
 * * period_mean (periods [dt_b - 2T, dt_b - T] and [dt_b - T, dt_b]):
 *   S = e^(lambda dt_b) (1 - e^(-lambda T))^2 / (lambda T^2), via expm1 near lambda = 0.
 *
 * \pre window > 0; W <= dt_b (least squares, increment) or 2T <= dt_b (period mean);
 *      lambda dt_b <= 700.
 */
double slope_gain(const CpiCycle& cycle, double lambda);

/**
 * \brief Amplification of one cycle, G(lambda) = e^(lambda dt_b) + DT S(lambda)
 *        (exact: e^(lambda (dt_b + DT))). The scheme damps the mode iff |G| <= 1.
 *
 * Paper case (a), dt_b = 20, W = 10, DT = 80: |G| > 1 for lambda in (-0.182, -0.031);
 * G(-0.001) = 0.901, G(-0.003) = 0.712, G(-0.01) = 0.130 (physics.md §10).
 * \pre as slope_gain(); dt >= 0.
 */
double cpi_amplification(const CpiCycle& cycle, double lambda);

/**
 * \brief Amplification of projective Adams-Bashforth 2 (cycle.steps = 2): the largest |mu| of
 *        mu^2 - (e^(lambda dt_b) + S W_1) mu - S W_0 = 0.
 *
 * Each cycle lifts y_n, measures s_n = S(lambda) y_n at the window centre tau_n (W/2 before the
 * end of the burst) and jumps y_{n+1} = e^(lambda dt_b) y_n + W_1 s_n + W_0 s_{n-1} with the
 * weights of the line through (tau_{n-1}, s_{n-1}), (tau_n, s_n), tau_n - tau_{n-1} =
 * dt_b + DT: W_1 = DT (a + h + DT/2)/h, W_0 = -DT (a + DT/2)/h, a = W/2, h = dt_b + DT
 * (docs/error_control.md). Reduces to |G| of forward Euler as the previous slope's weight -> 0.
 * \pre as cpi_amplification(), estimator least_squares.
 */
double ab2_cpi_amplification(const CpiCycle& cycle, double lambda);

}  // namespace efdem::coarse
