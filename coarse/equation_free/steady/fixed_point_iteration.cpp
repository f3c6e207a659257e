#include "coarse/equation_free/steady/fixed_point_iteration.hpp"

#include <algorithm>
#include <deque>

#include <fmt/format.h>
#include <Eigen/QR>

#include "core/contracts.hpp"
#include "core/log.hpp"

namespace efdem::coarse {

FixedPointIteration::FixedPointIteration(const FixedPointSettings& settings) : settings_(settings) {
    EFDEM_EXPECTS(settings_.max_iterations >= 0 && settings_.damping > 0.0 &&
                  settings_.damping <= 1.0 && settings_.depth >= 0);
}

SteadySolveRecord FixedPointIteration::solve(CoarseMap& map, const Eigen::VectorXd& x0,
                                             double parameter) const {
    EFDEM_EXPECTS(!map.has_base());
    const long evaluations0 = map.evaluations();
    const double micro0 = map.micro_time();
    const double beta = settings_.damping;
    SteadySolveRecord rec;
    std::deque<Eigen::VectorXd> dx, df;  // the last `depth` differences, oldest first
    Eigen::VectorXd x = x0, x_prev, f_prev;
    while (true) {
        const MapEvaluation e = map.evaluate(x, parameter);
        const double r = e.f.norm();
        const bool growing = r > rec.best_residual;
        rec.add_iterate(x, r, e.noise_norm, e.state_residual_norm, e.state_noise_norm);
        log::info("fixed point {:3d}: |F| = {:.4e} (noise {:.3e})", rec.iterations, r,
                  e.noise_norm);
        // The observer sees every iterate (the last one too); a stop it asks for comes after
        // the stopping rule, so a converged solve is never reported as stopped.
        const std::string stop_asked = settings_.observer ? settings_.observer(rec) : std::string{};
        if (settings_.stop.reached(r, e.noise_norm, rec.reason)) {
            rec.message = fmt::format(
                "{} after {} fixed-point iteration(s): |F| = {:.4e} <= {:.4e}",
                to_string(rec.reason), rec.iterations, r, settings_.stop.threshold(e.noise_norm));
            break;
        }
        if (!stop_asked.empty()) {
            rec.reason = SteadyStopReason::stopped;
            rec.message =
                fmt::format("stopped after {} fixed-point iteration(s) with |F| = {:.4e}: {}",
                            rec.iterations, r, stop_asked);
            break;
        }
        if (rec.iterations >= settings_.max_iterations) {
            rec.reason = SteadyStopReason::max_iterations;
            rec.message = fmt::format(
                "{} fixed-point iterations done with |F| = {:.4e} above {:.4e} (noise "
                "{:.3e}); the slowest coarse mode may be close to 1: try Newton-Krylov",
                rec.iterations, r, settings_.stop.threshold(e.noise_norm), e.noise_norm);
            break;
        }
        if (growing) {
            dx.clear();
            df.clear();
        } else if (settings_.depth > 0 && f_prev.size() > 0) {
            dx.push_back(x - x_prev);
            df.push_back(e.f - f_prev);
            if (static_cast<int>(dx.size()) > settings_.depth) {
                dx.pop_front();
                df.pop_front();
            }
        }
        x_prev = x;
        f_prev = e.f;
        Eigen::VectorXd next = x + beta * e.f;
        if (!dx.empty()) {
            const auto m = static_cast<Eigen::Index>(dx.size());
            Eigen::MatrixXd mdx(x.size(), m), mdf(x.size(), m);
            for (Eigen::Index j = 0; j < m; ++j) {
                mdx.col(j) = dx[static_cast<std::size_t>(j)];
                mdf.col(j) = df[static_cast<std::size_t>(j)];
            }
            const Eigen::VectorXd gamma = mdf.colPivHouseholderQr().solve(e.f);
            next -= (mdx + beta * mdf) * gamma;
        }
        rec.step_lengths.push_back(beta);
        ++rec.iterations;
        x = next;
    }
    rec.evaluations = map.evaluations() - evaluations0;
    rec.micro_time = map.micro_time() - micro0;
    return rec;
}

}  // namespace efdem::coarse
