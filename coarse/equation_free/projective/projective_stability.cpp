#include "coarse/equation_free/projective/projective_stability.hpp"

#include <algorithm>
#include <cmath>

#include "core/contracts.hpp"

namespace efdem::coarse {

namespace {

/// A root of f in [a, b], where f(a) and f(b) have opposite signs.
double bisect(const std::function<double(double)>& f, double a, double b) {
    double fa = f(a);
    for (int it = 0; it < 200 && b - a > 1e-14 * std::max(1.0, std::abs(a)); ++it) {
        const double m = 0.5 * (a + b);
        const double fm = f(m);
        if (fm == 0.0) return m;
        if ((fm < 0.0) == (fa < 0.0)) {
            a = m;
            fa = fm;
        } else {
            b = m;
        }
    }
    return 0.5 * (a + b);
}

/// e^(lambda tbar) h(lambda W/2) with h(u) = (u cosh u - sinh u)/u^2.
double weighted_h(double lambda, double tbar, double window) {
    const double u = 0.5 * lambda * window;
    if (std::abs(u) < 0.5) {
        // h(u) = sum_{n>=1} 2n u^(2n-1)/(2n+1)!; term_{n+1} = term_n u^2/(2n (2n+3)).
        double term = u / 3.0, sum = 0.0;
        for (int n = 1; n < 30 && std::abs(term) > 1e-18 * std::abs(sum); ++n) {
            sum += term;
            term *= u * u / (2.0 * n * (2.0 * n + 3.0));
        }
        return std::exp(lambda * tbar) * sum;
    }
    // e^(lambda tbar) (u cosh u - sinh u) = [e^(lambda tbar + |u|)(u - sgn u) +
    // e^(lambda tbar - |u|)(u + sgn u)]/2. The larger exponent is lambda dt_b for lambda > 0
    // and lambda (dt_b - W) <= 0 for lambda < 0, so nothing overflows.
    const double a = std::abs(u), sgn = u > 0.0 ? 1.0 : -1.0;
    const double value =
        0.5 * (std::exp(lambda * tbar + a) * (u - sgn) + std::exp(lambda * tbar - a) * (u + sgn));
    return value / (u * u);
}

}  // namespace

double pfe_amplification(double rho, int inner_steps, double extrapolation_steps) {
    EFDEM_EXPECTS(inner_steps >= 1 && extrapolation_steps >= 0.0);
    const double m = extrapolation_steps;
    return std::pow(rho, inner_steps - 1) * ((m + 1.0) * rho - m);
}

std::vector<RealInterval> stable_intervals(const std::function<double(double)>& g, double lo,
                                           double hi, std::span<const double> nodes, int n_scan) {
    EFDEM_EXPECTS(lo < hi && n_scan >= 1);
    std::vector<double> x;
    for (int k = 0; k <= n_scan; ++k) x.push_back(lo + (hi - lo) * k / n_scan);
    for (double v : nodes)
        if (v > lo && v < hi) x.push_back(v);
    std::sort(x.begin(), x.end());
    x.erase(std::unique(x.begin(), x.end()), x.end());

    std::vector<double> cuts{lo, hi};
    for (const double level : {1.0, -1.0}) {
        const auto f = [&](double v) { return g(v) - level; };
        double f_prev = f(x[0]);
        if (f_prev == 0.0) cuts.push_back(x[0]);
        for (std::size_t k = 1; k < x.size(); ++k) {
            const double f_k = f(x[k]);
            if (f_k == 0.0)
                cuts.push_back(x[k]);
            else if (f_prev != 0.0 && (f_k < 0.0) != (f_prev < 0.0))
                cuts.push_back(bisect(f, x[k - 1], x[k]));
            f_prev = f_k;
        }
    }
    std::sort(cuts.begin(), cuts.end());
    cuts.erase(std::unique(cuts.begin(), cuts.end()), cuts.end());

    std::vector<RealInterval> stable;
    for (std::size_t k = 0; k + 1 < cuts.size(); ++k) {
        if (std::abs(g(0.5 * (cuts[k] + cuts[k + 1]))) > 1.0) continue;
        if (!stable.empty() && stable.back().hi == cuts[k])
            stable.back().hi = cuts[k + 1];
        else
            stable.push_back({cuts[k], cuts[k + 1]});
    }
    return stable;
}

std::vector<RealInterval> pfe_stable_intervals(int inner_steps, double extrapolation_steps) {
    EFDEM_EXPECTS(inner_steps >= 1 && extrapolation_steps >= 0.0);
    const double k = inner_steps, m = extrapolation_steps;
    const double critical[] = {0.0, (k - 1.0) * m / (k * (m + 1.0))};
    return stable_intervals([&](double rho) { return pfe_amplification(rho, inner_steps, m); },
                            -2.0, 2.0, critical);
}

double slope_gain(const CpiCycle& cycle, double lambda) {
    EFDEM_EXPECTS(cycle.window > 0.0 && lambda * cycle.burst <= 700.0);
    if (cycle.estimator == SlopeEstimator::least_squares) {
        EFDEM_EXPECTS(cycle.window <= cycle.burst);
        const double tbar = cycle.burst - 0.5 * cycle.window;
        return 6.0 / cycle.window * weighted_h(lambda, tbar, cycle.window);
    }
    if (cycle.estimator == SlopeEstimator::increment) {
        EFDEM_EXPECTS(cycle.window <= cycle.burst);
        const double w = cycle.window, x = lambda * w;
        if (x > -1.0) return std::exp(lambda * cycle.burst) * (-std::expm1(-x)) / w;
        // Both exponents <= 0: nothing overflows however fast the mode.
        return (std::exp(lambda * cycle.burst) - std::exp(lambda * (cycle.burst - w))) / w;
    }
    const double period = cycle.window;
    EFDEM_EXPECTS(2.0 * period <= cycle.burst);
    const double x = lambda * period;
    if (x == 0.0) return 0.0;
    if (x > -1.0) {
        // lambda [e^(lambda dt_b/2) (1 - e^(-x))/x]^2, with 1 - e^(-x) = -expm1(-x).
        const double r = std::exp(0.5 * lambda * cycle.burst) * (-std::expm1(-x)) / x;
        return lambda * r * r;
    }
    // [e^(lambda dt_b/2) - e^(lambda (dt_b/2 - T))]^2 / (lambda T^2); both exponents <= 0.
    const double q =
        std::exp(0.5 * lambda * cycle.burst) - std::exp(lambda * (0.5 * cycle.burst - period));
    return q * q / (lambda * period * period);
}

double cpi_amplification(const CpiCycle& cycle, double lambda) {
    EFDEM_EXPECTS(cycle.dt >= 0.0);
    if (cycle.steps == 2) return ab2_cpi_amplification(cycle, lambda);
    return std::exp(lambda * cycle.burst) + cycle.dt * slope_gain(cycle, lambda);
}

double ab2_cpi_amplification(const CpiCycle& cycle, double lambda) {
    EFDEM_EXPECTS(cycle.dt >= 0.0 && cycle.estimator != SlopeEstimator::period_mean);
    const double dt = cycle.dt, a = 0.5 * cycle.window, h = cycle.burst + dt;
    const double w1 = dt * (a + h + 0.5 * dt) / h, w0 = -dt * (a + 0.5 * dt) / h;
    const double s = slope_gain(cycle, lambda);
    const double b = std::exp(lambda * cycle.burst) + s * w1, c = s * w0;  // mu^2 - b mu - c = 0
    const double disc = b * b + 4.0 * c;
    if (disc < 0.0) return std::sqrt(-c);  // complex pair: |mu|^2 = -c
    const double r = std::sqrt(disc);
    return std::max(std::abs(0.5 * (b + r)), std::abs(0.5 * (b - r)));
}

}  // namespace efdem::coarse
