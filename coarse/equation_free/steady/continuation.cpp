#include "coarse/equation_free/steady/continuation.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "coarse/equation_free/krylov/gmres.hpp"
#include "coarse/equation_free/steady/arclength_system.hpp"
#include "coarse/equation_free/steady/fixed_point_system.hpp"
#include "core/contracts.hpp"
#include "core/log.hpp"

namespace efdem::coarse {

std::vector<FoldEstimate> Branch::folds() const {
    std::vector<FoldEstimate> out;
    for (std::size_t k = 1; k + 1 < points.size(); ++k) {
        const double d0 = points[k].parameter - points[k - 1].parameter;
        const double d1 = points[k + 1].parameter - points[k].parameter;
        if (d0 * d1 >= 0) continue;
        const auto chord = [this](std::size_t a) {
            const BranchPoint& p = points[a];
            const BranchPoint& q = points[a + 1];
            return std::sqrt((q.x - p.x).squaredNorm() +
                             (q.parameter - p.parameter) * (q.parameter - p.parameter));
        };
        // Parabola through (0, l0), (s1, l1), (s2, l2) in Newton form; its vertex.
        const double s1 = chord(k - 1), s2 = s1 + chord(k);
        const double l0 = points[k - 1].parameter, l1 = points[k].parameter,
                     l2 = points[k + 1].parameter;
        const double a1 = (l1 - l0) / s1,
                     a2 = ((l2 - l1) / (s2 - s1) - a1) / s2;  // l = l0 + a1 s + a2 s (s - s1)
        const double s_vertex = (a2 * s1 - a1) / (2 * a2);
        out.push_back({k, l0 + a1 * s_vertex + a2 * s_vertex * (s_vertex - s1)});
    }
    return out;
}

PseudoArclengthContinuation::PseudoArclengthContinuation(CoarseMap& map,
                                                         const ContinuationSettings& settings)
    : map_(map), settings_(settings), newton_(settings.corrector) {
    EFDEM_EXPECTS(map_.has_parameter() && !map_.has_base());
    EFDEM_EXPECTS(settings_.evaluation_min <= settings_.parameter_min &&
                  settings_.parameter_max <= settings_.evaluation_max);
    EFDEM_EXPECTS(0.0 < settings_.min_step && settings_.min_step <= settings_.step &&
                  settings_.step <= settings_.max_step && settings_.max_points >= 1 &&
                  settings_.target_iterations >= 1 && settings_.fallback_ratio >= 0.0);
}

BranchPoint PseudoArclengthContinuation::make_point(const SteadySolveRecord& rec, Eigen::Index n,
                                                    double step, double micro_before) {
    BranchPoint p;
    p.x = rec.x.head(n);
    p.parameter = rec.x.size() > n ? rec.x[n] : 0.0;
    p.residual = rec.state_residuals.back();
    p.noise = rec.state_noise.back();
    p.newton_iterations = rec.iterations;
    p.step = step;
    p.from_fallback = rec.from_fallback;
    if (settings_.stability) {
        const CoarseSpectrum s = coarse_spectrum(map_, p.x, settings_.spectrum, p.parameter);
        p.has_leading = !s.leading.empty();
        if (p.has_leading) p.leading = s.leading.front();
    }
    p.micro_time = map_.micro_time() - micro_before;
    log::info(
        "branch point: parameter = {:.6g}, |F| = {:.3e}, {} Newton step(s){}{}",
        p.parameter * settings_.display_scale, p.residual, p.newton_iterations,
        p.from_fallback ? " from the last point" : "",
        p.has_leading
            ? fmt::format(", leading mu = {:.6g}{:+.3g}i (residual {:.2g}, products' noise {:.2g})",
                          p.leading.mu.real(), p.leading.mu.imag(), p.leading.residual,
                          p.leading.noise)
            : std::string{});
    return p;
}

Eigen::VectorXd PseudoArclengthContinuation::first_tangent(const Eigen::VectorXd& x, double lambda,
                                                           double direction) {
    const Eigen::Index n = x.size();
    map_.begin(x, lambda);
    const Eigen::VectorXd f_lambda = map_.derivative(Eigen::VectorXd::Zero(n), 1.0);
    GmresSettings gs;
    gs.max_iterations = settings_.corrector.max_krylov;
    gs.relative_tolerance = settings_.corrector.forcing;
    const GmresResult z = gmres(
        [this](const Eigen::VectorXd& v) -> Eigen::VectorXd { return map_.derivative(v) - v; },
        -f_lambda, gs);
    map_.end();
    Eigen::VectorXd t(n + 1);
    t.head(n) = z.x;
    t[n] = 1.0;
    return (direction >= 0 ? 1.0 : -1.0) * t.normalized();
}

std::pair<double, bool> PseudoArclengthContinuation::predictor_step(double ds, double lambda,
                                                                    double t_lambda) const {
    const double speed = std::abs(t_lambda);
    if (settings_.max_parameter_step > 0.0 && ds * speed > settings_.max_parameter_step)
        ds = settings_.max_parameter_step / speed;
    if (t_lambda == 0.0) return {ds, false};
    const double bound = t_lambda > 0.0 ? settings_.parameter_max : settings_.parameter_min;
    const double to_bound = (bound - lambda) / t_lambda;  // arclength to the end it heads for
    if (to_bound <= ds) return {std::max(to_bound, 0.0), true};
    return {ds, false};
}

std::string PseudoArclengthContinuation::range_end(const char* what, double lambda) const {
    const double k = settings_.display_scale;
    return fmt::format("{} the parameter range [{:.6g}, {:.6g}] at {:.6g}", what,
                       settings_.parameter_min * k, settings_.parameter_max * k, lambda * k);
}

Branch PseudoArclengthContinuation::run(const Eigen::VectorXd& x0, double lambda0,
                                        double direction) {
    const long evaluations0 = map_.evaluations();
    const double micro0 = map_.micro_time();
    const Eigen::Index n = x0.size();
    Branch branch;
    // No corrector (nor difference) runs the micro model beyond one parameter step outside the
    // range, nor where it cannot run at all.
    const double margin = settings_.max_parameter_step > 0.0
                              ? settings_.max_parameter_step
                              : settings_.parameter_max - settings_.parameter_min;
    map_.set_parameter_bounds(std::max(settings_.parameter_min - margin, settings_.evaluation_min),
                              std::min(settings_.parameter_max + margin, settings_.evaluation_max));
    double before = map_.micro_time();
    FixedPointSystem first(map_, n, lambda0);
    SteadySolveRecord rec = newton_.solve(first, x0);
    branch.first_solve = rec;
    if (!rec.converged()) {
        branch.end_reason =
            fmt::format("the first point at parameter = {:.6g} did not converge: {}",
                        lambda0 * settings_.display_scale, rec.message);
    } else {
        SteadySolveRecord with_lambda = rec;
        with_lambda.x.conservativeResize(n + 1);
        with_lambda.x[n] = lambda0;
        branch.points.push_back(make_point(with_lambda, n, 0.0, before));
        Eigen::VectorXd y(n + 1);
        y << branch.points.back().x, lambda0;
        if (settings_.on_point) settings_.on_point(branch);
        Eigen::VectorXd t = first_tangent(branch.points.back().x, lambda0, direction);
        double ds = settings_.step;
        if (settings_.parameter_step > 0.0)
            ds = std::clamp(settings_.parameter_step / std::max(std::abs(t[n]), 1e-12),
                            settings_.min_step, settings_.max_step);
        branch.end_reason = fmt::format("{} points (the limit)", settings_.max_points);
        while (static_cast<int>(branch.points.size()) < settings_.max_points) {
            before = map_.micro_time();
            const auto [step, lands] = predictor_step(ds, y[n], t[n]);
            if (step < settings_.min_step) {  // on the end of the range, heading out of it
                branch.end_reason = range_end("reached the end of", y[n]);
                break;
            }
            const Eigen::VectorXd predicted = y + step * t;
            // The last point is solved at the end of the range itself: its constraint row is
            // lambda = end instead of the arclength (regular unless a fold sits exactly there).
            const Eigen::VectorXd hold_lambda = Eigen::VectorXd::Unit(n + 1, n);
            ArclengthSystem system(map_, lands ? hold_lambda : t, predicted);
            // The fallback: the last point at the predicted parameter, corrected with lambda held
            // there (its constraint row is 0 at the start; in the arclength row of a noisy
            // tangent it would be -ds |t_X|^2, which the line search would trade against |F|).
            FallbackGuess held{y, settings_.fallback_ratio, nullptr};
            held.y[n] = predicted[n];
            ArclengthSystem natural(map_, hold_lambda, held.y);
            held.system = &natural;
            rec = newton_.solve(system, predicted, &held);
            if (rec.reason == SteadyStopReason::stopped) {
                branch.end_reason = fmt::format("stopped after parameter = {:.6g}: {}",
                                                y[n] * settings_.display_scale, rec.message);
                break;
            }
            if (!rec.converged()) {
                ds = step * 0.5;
                if (ds < settings_.min_step) {
                    branch.end_reason = fmt::format(
                        "the step fell below {:.3g} after parameter = {:.6g}: {}",
                        settings_.min_step, y[n] * settings_.display_scale, rec.message);
                    break;
                }
                continue;
            }
            t = (rec.x - y).normalized();
            y = rec.x;
            branch.points.push_back(make_point(rec, n, step, before));
            if (settings_.on_point) settings_.on_point(branch);
            if (y[n] < settings_.parameter_min || y[n] > settings_.parameter_max) {
                branch.end_reason = range_end("left", y[n]);
                break;
            }
            if (lands) {
                branch.end_reason = range_end("reached the end of", y[n]);
                break;
            }
            const double factor = std::clamp(
                static_cast<double>(settings_.target_iterations) / std::max(1, rec.iterations), 0.5,
                2.0);
            ds = std::clamp(step * factor, settings_.min_step, settings_.max_step);
        }
    }
    branch.micro_time = map_.micro_time() - micro0;
    branch.evaluations = map_.evaluations() - evaluations0;
    return branch;
}

}  // namespace efdem::coarse
