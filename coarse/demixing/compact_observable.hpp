#pragma once
/// \file
/// CompactObservable: the paper's compact coarse variables (A, B, C, D) of
/// y(p) = Q_top(p) - Q_L(p) ~ max[A p + B + C e^(D p), 0] (physics.md §8, Eq. 3), fitted to
/// the ensemble-mean y at every sample, warm-started from the previous sample's fit.
///
/// Lifting: each realization's target is Q_L*(p) = Q_top,r(p) - y(p; X), with Q_top,r from
/// that realization's own (reused) positions (§9). A sample whose fit is not usable (y = 0 at
/// full demixing, no convergence, a poor fit) yields a vector of NaN and a status: the
/// integrator then rejects the burst and the run loop falls back to the full ICDF.
///
/// No per-realization X (restricts_members() is false, so a compact step records no slope
/// standard error): that would take one Levenberg-Marquardt fit per realization per sample on
/// the root, R times the restriction's cost, and the fit of the mean is not the mean of the
/// members' fits (the fit is nonlinear), so their spread would not be that of the slope used.

#include <optional>

#include "coarse/demixing/compact_fit.hpp"
#include "coarse/demixing/ensemble_observable.hpp"

namespace efdem::coarse {

class CompactObservable final : public EnsembleObservable {
  public:
    explicit CompactObservable(ProbabilityGrid grid, CompactFitSettings settings = {})
        : grid_(grid), settings_(settings) {}
    std::string_view name() const override { return "compact"; }
    std::string_view label() const override { return "compact (A,B,C,D)"; }
    Eigen::Index dimension() const override { return 4; }
    ReferenceIcdf reference() const override { return ReferenceIcdf::top_half; }
    Eigen::VectorXd restrict_ensemble(const Eigen::MatrixXd& icdf,
                                      const Eigen::MatrixXd& top) override;
    Eigen::VectorXd lift_target(const Eigen::VectorXd& x,
                                const Eigen::VectorXd& top) const override;
    int status() const override { return static_cast<int>(last_.status); }
    std::string status_message() const override { return last_.message; }
    std::string failure_message() const override { return last_failure_; }
    const CompactFit& last_fit() const { return last_; }
    /// The warm start of the next fit: (a, b, c, d) of the last usable one, or empty.
    std::vector<double> saved_state() const override;
    void restore_state(const std::vector<double>& state) override;

  private:
    ProbabilityGrid grid_;
    CompactFitSettings settings_;
    std::optional<CompactParameters> previous_;
    CompactFit last_;
    std::string last_failure_;
};

}  // namespace efdem::coarse
