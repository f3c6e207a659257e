#include "coarse/equation_free/steady/newton_krylov.hpp"

#include <algorithm>
#include <utility>

#include <fmt/format.h>

#include "core/contracts.hpp"
#include "core/log.hpp"

namespace efdem::coarse {

namespace {
/// Armijo constant of the sufficient decrease |G(y + s d)| <= (1 - c s) |G(y)|: small, so that
/// any real decrease along a descent direction is accepted (Kelley 2003, ch. 8).
constexpr double kArmijo = 1e-4;
/// The GMRES residual need not go below this fraction of the stopping threshold: the Newton
/// step then lands within half of it, leaving the other half to the nonlinearity.
constexpr double kKrylovFloor = 0.5;
}  // namespace

NewtonKrylov::NewtonKrylov(const NewtonKrylovSettings& settings) : settings_(settings) {
    EFDEM_EXPECTS(settings_.max_iterations >= 0 && settings_.max_krylov >= 1 &&
                  settings_.forcing > 0.0 && settings_.forcing < 1.0 &&
                  settings_.max_backtracks >= 0);
}

SystemEvaluation NewtonKrylov::choose_start(NewtonSystem*& system, Eigen::VectorXd& y,
                                            SystemEvaluation e, const FallbackGuess& fallback,
                                            SteadySolveRecord& rec) const {
    NewtonSystem& other = fallback.system != nullptr ? *fallback.system : *system;
    EFDEM_EXPECTS(fallback.y.size() == other.dimension() && fallback.ratio >= 0.0);
    const double r = e.g.norm();
    rec.first_guess_residual = r;
    // Only a noisy first guess is in doubt: a noise-free map's secant predictor is as good as
    // the branch's smoothness makes it, and would be compared at every point for nothing.
    const double threshold = settings_.stop.threshold(e.noise_norm);
    if (e.noise_norm <= 0.0 || r <= fallback.ratio * threshold) return e;
    system->end();
    SystemEvaluation f = other.begin(fallback.y);
    rec.fallback_residual = f.g.norm();
    rec.from_fallback = rec.fallback_residual < r;
    log::info(
        "newton   0: |G| = {:.4e} at the first guess ({:.3g} x the stopping threshold), {:.4e} at "
        "the "
        "fallback guess: starting from the {}",
        r, r / threshold, rec.fallback_residual, rec.from_fallback ? "fallback" : "first guess");
    if (rec.from_fallback) {
        y = fallback.y;
        system = &other;
        return f;
    }
    other.end();
    return system->begin(y);  // afresh: the kept micro state is the fallback's
}

SteadySolveRecord NewtonKrylov::solve(NewtonSystem& first_system, const Eigen::VectorXd& y0,
                                      const FallbackGuess* fallback) const {
    EFDEM_EXPECTS(y0.size() == first_system.dimension());
    const long evaluations0 = first_system.evaluations();
    const double micro0 = first_system.micro_time();
    SteadySolveRecord rec;
    NewtonSystem* solving = &first_system;  // the fallback's own system, if it wins
    Eigen::VectorXd y = y0;
    while (true) {
        SystemEvaluation e = solving->begin(y);
        if (fallback != nullptr && rec.residuals.empty())
            e = choose_start(solving, y, std::move(e), *fallback, rec);
        NewtonSystem& system = *solving;
        const double r = e.g.norm();
        rec.add_iterate(y, r, e.noise_norm, e.state_residual, e.state_noise);
        log::info("newton {:3d}: |F| = {:.4e} (noise {:.3e})", rec.iterations, r, e.noise_norm);
        // The observer sees every iterate (the last one too); a stop it asks for comes after
        // the stopping rule, so a converged solve is never reported as stopped.
        const std::string stop_asked = settings_.observer ? settings_.observer(rec) : std::string{};
        if (settings_.stop.reached(r, e.noise_norm, rec.reason)) {
            rec.message = fmt::format(
                "{} after {} Newton step(s): |F| = {:.4e} <= {:.4e} (tolerance {:.3e}, "
                "{} x noise {:.3e})",
                to_string(rec.reason), rec.iterations, r, settings_.stop.threshold(e.noise_norm),
                settings_.stop.tolerance, settings_.stop.noise_factor, e.noise_norm);
            system.end();
            break;
        }
        if (!stop_asked.empty()) {
            rec.reason = SteadyStopReason::stopped;
            rec.message = fmt::format("stopped after {} Newton step(s) with |F| = {:.4e}: {}",
                                      rec.iterations, r, stop_asked);
            system.end();
            break;
        }
        if (rec.iterations >= settings_.max_iterations) {
            rec.reason = SteadyStopReason::max_iterations;
            rec.message = fmt::format(
                "{} Newton steps done with |F| = {:.4e} above {:.4e} (noise {:.3e}); try "
                "more iterations, a longer tau or more realizations",
                rec.iterations, r, settings_.stop.threshold(e.noise_norm), e.noise_norm);
            system.end();
            break;
        }
        GmresSettings gs;
        gs.max_iterations = settings_.max_krylov;
        gs.relative_tolerance = settings_.forcing;
        gs.absolute_tolerance = kKrylovFloor * settings_.stop.threshold(e.noise_norm);
        const GmresResult lin = gmres(
            [&system](const Eigen::VectorXd& v) { return system.jacobian_times(v); }, -e.g, gs);
        rec.krylov_iterations.push_back(lin.iterations);
        rec.gmres_residuals.push_back(lin.residuals);
        double s = 1.0;
        bool accepted = false;
        double r_trial = r;
        for (int b = 0; b <= settings_.max_backtracks; ++b, s *= 0.5) {
            r_trial = system.trial(y + s * lin.x).g.norm();
            if (r_trial <= (1.0 - kArmijo * s) * r) {
                accepted = true;
                break;
            }
        }
        log::info(
            "newton {:3d}: {} GMRES products (linear residual {:.3e}), step {:.4g}, trial |F| = "
            "{:.4e}",
            rec.iterations, lin.iterations, lin.residuals.back(), accepted ? s : 0.0, r_trial);
        system.end();
        if (!accepted) {
            rec.reason = SteadyStopReason::line_search_failed;
            rec.message = fmt::format(
                "line search failed at Newton step {}: no step down to {:.3g} of the GMRES step "
                "decreased |F| = "
                "{:.4e} (noise {:.3e}, {:.3g} x the noise){}",
                rec.iterations, s, r, e.noise_norm, e.noise_norm > 0 ? r / e.noise_norm : 0.0,
                lin.converged
                    ? ""
                    : "; GMRES did not converge: the derivatives may be too noisy (try a larger "
                      "difference step, more realizations)");
            break;
        }
        rec.step_lengths.push_back(s);
        ++rec.iterations;
        y += s * lin.x;
    }
    rec.evaluations = solving->evaluations() - evaluations0;
    rec.micro_time = solving->micro_time() - micro0;
    return rec;
}

}  // namespace efdem::coarse
