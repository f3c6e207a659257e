#include "coarse/equation_free/steady/steady_run.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

#include <fmt/format.h>

#include "coarse/equation_free/ensemble_statistics.hpp"
#include "coarse/equation_free/steady/fixed_point_iteration.hpp"
#include "coarse/equation_free/steady/fixed_point_system.hpp"
#include "coarse/equation_free/steady/newton_krylov.hpp"
#include "core/contracts.hpp"
#include "core/log.hpp"

namespace efdem::coarse {

double mean_height(const Eigen::VectorXd& x) {
    return x.size() > 0 ? x.mean() : 0.0;
}

double mean_height_error_bound(double noise_norm, Eigen::Index n) {
    return n > 0 ? noise_norm / std::sqrt(static_cast<double>(n)) : 0.0;
}

SteadyRun::SteadyRun(const SteadyRunSettings& settings, CoarseStepper& stepper, RepairHook repair,
                     std::function<void(double)> set_parameter, CoarseCoordinates coordinates)
    : coordinates_(std::move(coordinates)),
      settings_(settings),
      stepper_(stepper),
      repair_(std::move(repair)),
      set_parameter_(std::move(set_parameter)) {
    EFDEM_EXPECTS(settings_.warmup > 0.0);
    EFDEM_EXPECTS(!settings_.continuation || set_parameter_);
}

Eigen::VectorXd SteadyRun::state(const Eigen::VectorXd& y, Eigen::Index n) const {
    if (!coordinates_) return y;
    Eigen::VectorXd out = y;
    out.head(n) = coordinates_.to_state(y.head(n));
    return out;
}

Eigen::VectorXd SteadyRun::solver_point(const Eigen::VectorXd& x) const {
    return coordinates_ ? coordinates_.from_state(x) : x;
}

IterateObserver SteadyRun::observer_in_states(Eigen::Index n) const {
    if (!iterate_observer_ || !coordinates_) return iterate_observer_;
    return [this, n](const SteadySolveRecord& rec) {
        SteadySolveRecord view = rec;
        view.x = state(rec.x, n);
        if (rec.best.size() > 0) view.best = state(rec.best, n);
        return iterate_observer_(view);
    };
}

SteadyRunOutcome SteadyRun::header() const {
    SteadyRunOutcome out;
    out.continuation = settings_.continuation;
    out.solver = settings_.solver == SteadyRunSettings::Solver::newton ? "newton" : "anderson";
    out.tau = settings_.map.tau;
    out.coordinates = coordinates_ ? coordinates_.name : "heights";
    out.parameter = settings_.parameter;
    out.parameter_scale = settings_.parameter_scale;
    out.difference_step = difference_step_;
    out.difference_step_origin = difference_step_origin_;
    return out;
}

double SteadyRun::difference_step(const BurstSamples& warm) {
    difference_step_ = settings_.map.difference_step;
    if (settings_.solver == SteadyRunSettings::Solver::anderson) {
        difference_step_origin_ = "unused: steady.solver = anderson takes no derivatives";
        return difference_step_;
    }
    if (!settings_.difference_step_from_noise) {
        difference_step_origin_ = "steady.difference_step";
        return difference_step_;
    }
    if (warm.members.empty() || warm.members.back().rows() < 2) {
        difference_step_origin_ =
            "default (fewer than two realizations: no noise to derive it from)";
        log::info(
            "steady: difference step h = {:g}, the default: with fewer than two realizations there "
            "is no "
            "noise to derive it from",
            difference_step_);
        return difference_step_;
    }
    const Eigen::MatrixXd& last = warm.members.back();
    const double noise =
        ensemble_standard_error(coordinates_ ? coordinates_.rows_from_state(last) : last).norm();
    if (!(noise > 0.0)) {
        difference_step_origin_ =
            "default (the realizations agree exactly: no noise to derive it from)";
        return difference_step_;
    }
    // A perturbation of norm 1 in log gaps changes a gap by up to a factor e; in heights a
    // quarter of |X| moves the nodes by about a quarter of their mean: beyond either the
    // response is no longer a derivative.
    const double cap = coordinates_ ? 1.0 : 0.25 * warm.x.back().norm();
    const double wanted = settings_.difference_noise_multiple * noise;
    difference_step_ = std::min(wanted, cap);
    difference_step_origin_ =
        fmt::format("{:g} x the noise norm {:.4g} at the end of the warm-up{}",
                    settings_.difference_noise_multiple, noise,
                    wanted > cap ? fmt::format(", capped at {:.3g}", cap) : std::string{});
    log::info("steady: difference step h = {:.4g} ({}; set steady.difference_step to choose it)",
              difference_step_, difference_step_origin_);
    if (wanted > cap)
        log::warn(
            "steady: the noise asks for a difference step of {:.3g}, more than the {:.3g} at which "
            "the "
            "coarse map's response stops being a derivative: J v will be noisy; more realizations "
            "lower "
            "the noise (as 1/sqrt(R)){}",
            wanted, cap,
            coordinates_ ? ", and steady.coordinates = heights measures it in d_p" : "");
    return difference_step_;
}

SteadyRunOutcome SteadyRun::run() {
    SteadyRunOutcome out = header();
    if (settings_.continuation) set_parameter_(settings_.parameter_start);
    BurstSamples warm;
    stepper_.run(settings_.warmup, warm);
    EFDEM_ASSERT(warm.size() >= 1);
    out.x0 = warm.x.back();
    out.warmup_end = stepper_.time();
    log::info("steady: warm-up of {:g} done at t = {:.6g}; initial guess: mean height {:.4g}",
              settings_.warmup, out.warmup_end, mean_height(out.x0));

    std::function<void(double)> hook;
    if (settings_.continuation) {
        const double scale = settings_.parameter_scale;
        hook = [this, scale](double lambda) { set_parameter_(lambda * scale); };
    }
    CoarseMapSettings map_settings = settings_.map;
    map_settings.difference_step = difference_step(warm);
    out.difference_step = difference_step_;
    out.difference_step_origin = difference_step_origin_;
    CoarseMap map(stepper_, map_settings, hook);
    if (repair_) map.set_repair(repair_);
    if (coordinates_) map.set_coordinates(coordinates_);
    if (settings_.continuation)
        continue_branch(map, out);
    else
        solve_steady(map, out);
    out.repairs = map.repairs();
    out.largest_repair = map.largest_repair();
    out.evaluations = map.evaluations();
    out.micro_time = map.micro_time();
    if (out.repairs > 0)
        log::warn(
            "steady: the repair changed {} of {} lifted points (largest change {:.3g}): a "
            "difference it "
            "touched is biased. steady.coordinates = gaps keeps every lift monotone; a smaller "
            "steady.difference_step (h = {:.3g} now) does too, but only while the products' noise, "
            "~1.4 x the noise of F / h, stays well below |J v|",
            out.repairs, out.evaluations, out.largest_repair, out.difference_step);
    return out;
}

void SteadyRun::solve_steady(CoarseMap& map, SteadyRunOutcome& out) {
    if (settings_.solver == SteadyRunSettings::Solver::newton) {
        NewtonKrylovSettings ns = settings_.newton;
        ns.observer = observer_in_states(out.x0.size());
        FixedPointSystem system(map, out.x0.size());
        out.solve = NewtonKrylov(ns).solve(system, solver_point(out.x0));
    } else {
        FixedPointSettings fs = settings_.fixed_point;
        fs.observer = observer_in_states(out.x0.size());
        out.solve = FixedPointIteration(fs).solve(map, solver_point(out.x0));
    }
    out.converged = out.solve.converged();
    // The spectrum at the answer, and at the best iterate of a solve that ran out of iterations
    // or line search (what the user gets, and the eigenvalues say why it was hard); not after
    // a stop the caller asked for (a budget spent, a signal).
    const bool spectrum =
        settings_.eigenvalues > 0 && out.solve.reason != SteadyStopReason::stopped;
    if (spectrum) {
        SpectrumSettings ss = settings_.spectrum;
        ss.eigenvalues = settings_.eigenvalues;
        out.spectrum = coarse_spectrum(map, out.converged ? out.solve.x : out.solve.best,
                                       ss);  // in u: same eigenvalues
        for (const CoarseEigenvalue& e : out.spectrum.leading)
            log::info(
                "steady: eigenvalue mu = {:.5g}{:+.3g}i, rate log|mu|/tau = {:.4g} (residual "
                "{:.2g}, products' "
                "noise {:.2g})",
                e.mu.real(), e.mu.imag(), e.rate, e.residual, e.noise);
    }
    // Report in the coarse vector.
    const Eigen::Index n = out.x0.size();
    out.solve.x = state(out.solve.x, n);
    if (out.solve.best.size() > 0) out.solve.best = state(out.solve.best, n);
    out.end_status =
        out.converged
            ? fmt::format("completed: {}", out.solve.message)
            : fmt::format("not converged: {}; best |F| = {:.4e} (noise {:.3e} at the start)",
                          out.solve.message, out.solve.best_state_residual(),
                          out.solve.state_noise.empty() ? 0.0 : out.solve.state_noise.front());
}

Branch SteadyRun::unscaled(const Branch& branch) const {
    Branch b = branch;
    for (BranchPoint& p : b.points) {
        p.parameter *= settings_.parameter_scale;
        p.x = state(p.x, p.x.size());
    }
    return b;
}

void SteadyRun::continue_branch(CoarseMap& map, SteadyRunOutcome& out) {
    ContinuationSettings cs = settings_.branch;
    cs.corrector.observer = observer_in_states(out.x0.size());
    if (point_observer_) cs.on_point = [this](const Branch& b) { point_observer_(unscaled(b)); };
    PseudoArclengthContinuation continuation(map, cs);
    const double direction = settings_.parameter_end >= settings_.parameter_start ? 1.0 : -1.0;
    out.branch = unscaled(continuation.run(
        solver_point(out.x0), settings_.parameter_start / settings_.parameter_scale, direction));
    out.converged = !out.branch.points.empty();
    if (!out.converged) {  // the first point's residual history and best iterate, in X
        out.solve = out.branch.first_solve;
        out.solve.x = state(out.solve.x, out.solve.x.size());
        if (out.solve.best.size() > 0)
            out.solve.best = state(out.solve.best, out.solve.best.size());
    }
    const std::size_t n = out.branch.points.size();
    out.end_status =
        out.converged ? fmt::format("completed: {} branch point(s) from {} = {:.4g} to {:.4g}; {}",
                                    n, out.parameter, out.branch.points.front().parameter,
                                    out.branch.points.back().parameter, out.branch.end_reason)
                      : fmt::format("not converged: {}", out.branch.end_reason);
}

}  // namespace efdem::coarse
