#pragma once
/// \file
/// The compact coarse observable of the paper (physics.md §8, Eq. 3; Q17):
///   y(p) = Q_top(p) - Q_L(p) ~ max[a p + b + c e^(d p), 0],
/// Q_top the ICDF of the N/2 highest particles, Q_L that of the light ones; y >= 0, decreasing
/// in p, and zero where demixing is locally complete. (a, b, c, d) = the paper's (A, B, C, D):
/// a, b, c in d_p, d dimensionless (p is dimensionless).

#include <limits>
#include <optional>
#include <string>

#include <Eigen/Core>

#include "coarse/demixing/probability_grid.hpp"

namespace efdem::coarse {

struct CompactParameters {
    double a = 0.0;  ///< A [d_p]
    double b = 0.0;  ///< B [d_p]
    double c = 0.0;  ///< C [d_p]
    double d = 0.0;  ///< D [-]

    /// (a, b, c, d): the coarse vector of a CPI on the compact observable.
    Eigen::Vector4d vector() const { return {a, b, c, d}; }
    static CompactParameters from_vector(const Eigen::Vector4d& v) {
        return {v[0], v[1], v[2], v[3]};
    }
};

enum class CompactFitStatus {
    ok,               ///< converged, parameters identifiable, residual acceptable
    full_demixing,    ///< y = 0 at every node: nothing to fit; parameters are (0, 0, 0, 0)
    ill_conditioned,  ///< y(p) is fitted, but not all four parameters are determined (see
                      ///< message): too few points, or a nearly singular Jacobian; d was held
                      ///< at the previous fit's value when there was one (Q17)
    not_converged,    ///< Levenberg-Marquardt stopped without converging; parameters are the
                      ///< last iterate and must not be used
    poor_fit,         ///< converged, but RMS/max(y) > max_relative_rms: the model does not
                      ///< describe the data
};

struct CompactFitSettings {
    int max_evaluations = 400;  ///< LM function-evaluation budget
    double tolerance = 1e-10;   ///< LM relative tolerance on the residual and the parameters
    /// Condition number of the natural-scale Jacobian (derivatives of f/Y by a/Y, b/Y, c/Y and
    /// d; Y = max y) above which (a, b, c, d) count as not identifiable. It grows without
    /// bound as c -> 0 (d stops mattering) or d -> 0 (c e^(dp) ~ c + c d p duplicates b and
    /// a p).
    double max_condition = 1e6;
    /// Standard error of d above which d counts as not determined by noisy data (d is
    /// dimensionless; p spans [0, 1]).
    double max_d_error = 1.0;
    double max_relative_rms = 0.05;  ///< poor_fit threshold on RMS/max_i y_i
    double d_limit = 50.0;           ///< |d| bound during the search (e^50 ~ 5e21)
};

struct CompactFit {
    CompactFitStatus status = CompactFitStatus::not_converged;
    CompactParameters parameters;
    /// RMS over all m nodes of max[a p + b + c e^(dp), 0] - y [d_p].
    double rms = 0.0;
    int iterations = 0;   ///< LM iterations (Jacobian evaluations), all passes
    int evaluations = 0;  ///< residual evaluations, all passes and the cold-start search
    int n_fitted = 0;     ///< nodes fitted: y > 0, plus the first zero (Q17)
    /// Of the natural-scale Jacobian at the 4-parameter solution (CompactFitSettings); NaN
    /// with fewer than four fitted nodes.
    double condition_number = std::numeric_limits<double>::quiet_NaN();
    /// Standard errors of (a, b, c, d) from the residuals at the solution, s^2 (J^T J)^-1 with
    /// s^2 = SSR/(n_fitted - n_free); NaN for held or undetermined parameters.
    Eigen::Vector4d standard_errors =
        Eigen::Vector4d::Constant(std::numeric_limits<double>::quiet_NaN());
    bool d_held = false;  ///< d was fixed at the previous fit's value
    std::string message;

    /// y(p) is described by the parameters (ok, full_demixing, ill_conditioned). Only ok
    /// promises individually meaningful (a, b, c, d).
    bool usable() const {
        return status == CompactFitStatus::ok || status == CompactFitStatus::full_demixing ||
               status == CompactFitStatus::ill_conditioned;
    }
};

/**
 * \brief Fits y(p) = max[a p + b + c e^(d p), 0] to y_i at the grid nodes p_i (physics.md §8,
 *        Q17) by Levenberg-Marquardt with an analytic Jacobian (Eigen's MINPACK port).
 *
 * Fitted nodes: those with y_i > 0, plus the first node with y_i <= 0. Positive nodes use the
 * residual a p + b + c e^(dp) - y (the unclamped model: no flat, gradient-free region); the
 * zero node uses max[., 0], so it only asks the model to be <= 0 there.
 *
 * Start: `previous` (warm start, the normal case during a CPI run), else a cold start that
 * solves the linear least-squares problem for (a, b, c) on a grid of d and keeps the best.
 * The 4-parameter fit counts as underdetermined when it does not converge, when the
 * natural-scale condition number exceeds max_condition, when the standard error of d exceeds
 * max_d_error, or with fewer than 4 fitted nodes. Then (Q17) d is held at previous->d and
 * (a, b, c) are fitted, when a previous fit is given; without one, the 4-parameter result is
 * reported as ill_conditioned (or not_converged), and below 4 nodes the line a p + b (c = 0) is
 * fitted. Every fallback is named in status and message.
 *
 * \pre y.size() == grid.size() >= 4; y finite.
 */
CompactFit fit_compact(const Eigen::VectorXd& y, const ProbabilityGrid& grid,
                       const std::optional<CompactParameters>& previous = std::nullopt,
                       const CompactFitSettings& settings = {});

/// y(p_i) = max[a p_i + b + c e^(d p_i), 0] at the grid nodes [d_p]. \pre |d| <= 700.
Eigen::VectorXd y_of_p(const CompactParameters& params, const ProbabilityGrid& grid);

/**
 * \brief The light-species ICDF target of compact-observable lifting (physics.md §9):
 *        Q_L*(p_i) = Q_top(p_i) - y(p_i), Q_top from the reused positions [d_p].
 *
 * The result still needs monotone repair and clipping (colour lifting does both).
 * \pre top_icdf.size() == grid.size().
 */
Eigen::VectorXd light_icdf_from_compact(const Eigen::VectorXd& top_icdf,
                                        const CompactParameters& params,
                                        const ProbabilityGrid& grid);

}  // namespace efdem::coarse
