#include "coarse/equation_free/steady/steady_solve_record.hpp"

#include <algorithm>
#include <cmath>

namespace efdem::coarse {

std::string to_string(SteadyStopReason reason) {
    switch (reason) {
        case SteadyStopReason::converged:
            return "converged";
        case SteadyStopReason::noise_level:
            return "stopped at the noise level";
        case SteadyStopReason::line_search_failed:
            return "line search failed";
        case SteadyStopReason::max_iterations:
            return "iteration limit";
        case SteadyStopReason::stopped:
            return "stopped";
    }
    return "?";
}

double SteadyStopRule::threshold(double noise) const {
    return std::max(tolerance, noise_factor * noise);
}

bool SteadyStopRule::reached(double r, double noise, SteadyStopReason& reason) const {
    if (r > threshold(noise)) return false;
    reason = noise_factor * noise > tolerance ? SteadyStopReason::noise_level
                                              : SteadyStopReason::converged;
    return true;
}

double SteadySolveRecord::best_state_residual() const {
    if (residuals.empty() || state_residuals.size() != residuals.size()) return best_residual;
    const auto k = std::min_element(residuals.begin(), residuals.end()) - residuals.begin();
    return state_residuals[static_cast<std::size_t>(k)];
}

void SteadySolveRecord::add_iterate(const Eigen::VectorXd& y, double residual, double noise_norm,
                                    double residual_in_state, double noise_in_state) {
    x = y;
    residuals.push_back(residual);
    noise.push_back(noise_norm);
    state_residuals.push_back(std::isnan(residual_in_state) ? residual : residual_in_state);
    state_noise.push_back(std::isnan(noise_in_state) ? noise_norm : noise_in_state);
    if (residual < best_residual) {
        best_residual = residual;
        best = y;
    }
}

}  // namespace efdem::coarse
