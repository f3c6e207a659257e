#include "coarse/equation_free/steady_solve_record.hpp"

#include <algorithm>

namespace efdem::coarse {

std::string to_string(SteadyStopReason reason) {
    switch (reason) {
        case SteadyStopReason::converged: return "converged";
        case SteadyStopReason::noise_level: return "stopped at the noise level";
        case SteadyStopReason::line_search_failed: return "line search failed";
        case SteadyStopReason::max_iterations: return "iteration limit";
        case SteadyStopReason::stopped: return "stopped";
    }
    return "?";
}

double SteadyStopRule::threshold(double noise) const { return std::max(tolerance, noise_factor * noise); }

bool SteadyStopRule::reached(double r, double noise, SteadyStopReason& reason) const {
    if (r > threshold(noise)) return false;
    reason = noise_factor * noise > tolerance ? SteadyStopReason::noise_level : SteadyStopReason::converged;
    return true;
}

void SteadySolveRecord::add_iterate(const Eigen::VectorXd& y, double residual, double noise_norm) {
    x = y;
    residuals.push_back(residual);
    noise.push_back(noise_norm);
    if (residual < best_residual) {
        best_residual = residual;
        best = y;
    }
}

}  // namespace efdem::coarse
