#pragma once
/// \file
/// The coarse time-tau map of equation-free steady-state computation (docs/steady_states.md):
/// Phi_tau(X; lambda) = restrict(run tau(lift X)), the last sample of one burst, and
/// F(X) = Phi_tau(X) - X, whose zeros are the coarse steady states. Directional derivatives
/// are differences of two evaluations from the *same* micro state and random streams (common
/// random numbers, CRN), so that most of the ensemble noise cancels in the difference.
///
/// The map keeps one *base* at a time: begin() keeps the micro state (CoarseStepper::
/// keep_state) and evaluates Phi at the base point from it; evaluate_from_base() and
/// derivative() evaluate other points from that same kept state; end() forgets it, and the
/// micro model continues from where the last evaluation ended (a healed state for the next
/// base). Every evaluation costs tau of micro time (times the ensemble size for an ensemble),
/// counted in micro_time().
///
/// \code
/// coarse::CoarseMap phi(stepper, {.tau = 40, .difference_step = 1e-2});
/// const coarse::MapEvaluation& base = phi.begin(x);      // F = base.f, noise base.noise_norm
/// const Eigen::VectorXd jv = phi.derivative(v) - v;      // J_F v with CRN
/// phi.end();
/// \endcode

#include <functional>
#include <limits>
#include <string>

#include <Eigen/Core>

#include "coarse/equation_free/coarse_stepper.hpp"
#include "coarse/equation_free/repair_report.hpp"

namespace efdem::coarse {

struct CoarseMapSettings {
    /// Micro time of one evaluation [sqrt(d_p/g)] (> 0; a multiple of the stepper's sampling
    /// interval).
    double tau = 1.0;
    /// Length h of the difference step in the coarse space (> 0): J v is measured as
    /// (Phi(X + h v/|v|) - Phi(X)) |v| / h. Round-off wants it large next to sqrt(machine eps)
    /// |X|; the curvature of Phi wants it small; for an ensemble it must also be large next to
    /// what CRN leaves of the noise.
    double difference_step = 1e-6;
    /// Evaluate derivatives and trial points from the base's kept micro state (requires
    /// CoarseStepper::can_keep_state(), a contract). Off: from whatever micro state the
    /// previous evaluation left, i.e. with fresh noise (kept only for comparisons).
    bool common_random_numbers = true;
};

/// Coordinates the solver works in, u, and the coarse vector X = to_state(u) the stepper
/// lifts and restricts (e.g. an ICDF's first node and the logs of its gaps, in which every u is
/// a monotone ICDF: coarse/demixing/icdf_gap_coordinates.hpp). Φ in u is
/// from_state(Φ(to_state(u))); each member's restriction is mapped the same way, so the
/// noise is measured in u. The steady states are the same points, and at a steady state the
/// eigenvalues of dΦ/du and dΦ/dX are the same (similar matrices).
struct CoarseCoordinates {
    std::function<Eigen::VectorXd(const Eigen::VectorXd&)> to_state;
    std::function<Eigen::VectorXd(const Eigen::VectorXd&)> from_state;
    std::string name = "heights";  ///< for the record
    explicit operator bool() const { return static_cast<bool>(to_state); }
    /// from_state of every row (one member's coarse vector per row).
    Eigen::MatrixXd rows_from_state(const Eigen::MatrixXd& rows) const;
};

/// One evaluation of the map.
struct MapEvaluation {
    Eigen::VectorXd x;     ///< the lifted point
    double parameter = 0;  ///< the parameter it was evaluated at (0 without a parameter hook)
    Eigen::VectorXd phi;   ///< Phi_tau(x): the restricted sample at the end of the burst
    Eigen::VectorXd f;     ///< F = phi - x
    /// Standard error of each component of phi from the members' spread at the last sample
    /// (sqrt(var/R)); zeros when the stepper reports no members or only one.
    Eigen::VectorXd standard_error;
    /// Each member's restriction at the burst's last sample, in the map's coordinates (one row
    /// per member; empty when the stepper reports no members).
    Eigen::MatrixXd members;
    /// |standard_error|_2: the expected norm of the noise in phi (and F), what the stopping
    /// rule compares |F| with.
    double noise_norm = 0;
    /// |F| and the noise norm in the stepper's coordinates X (the ICDF's heights [d_p]), for the
    /// record: equal to |f| and noise_norm unless the map works in other coordinates.
    double state_residual_norm = 0;
    double state_noise_norm = 0;
};

class CoarseMap {
  public:
    /// `set_parameter` (may be empty) is called with the parameter before every lift: the
    /// map is then Phi_tau(X; lambda) (continuation). \pre settings.tau > 0,
    /// settings.difference_step > 0, and can_keep_state() when common_random_numbers is on.
    CoarseMap(CoarseStepper& stepper, const CoarseMapSettings& settings,
              std::function<void(double)> set_parameter = {});

    /// Keeps the micro state and evaluates Phi at (x, parameter) from it. \pre no base.
    const MapEvaluation& begin(const Eigen::VectorXd& x, double parameter = 0.0);
    /// Phi at another point from the base's kept micro state (with CRN). \pre a base.
    MapEvaluation evaluate_from_base(const Eigen::VectorXd& x, double parameter);
    /// dPhi(X; lambda) [v; dparameter] at the base by a one-sided difference from the base's
    /// micro state; the step h is taken along (v, dparameter)/|(v, dparameter)|, backwards when
    /// the forward point's parameter lies outside set_parameter_bounds().
    /// Zero for a zero direction (no evaluation). \pre a base; dparameter = 0 without a hook.
    Eigen::VectorXd derivative(const Eigen::VectorXd& v, double dparameter = 0.0);
    /// The noise of the last derivative(): |SE| of the mean of the members' own differences
    /// (Phi_r(X + h v) - Phi_r(X)) |v|/h, i.e. what common random numbers left of the noise in
    /// that product (0 without members, or before the first derivative).
    double derivative_noise() const { return derivative_noise_; }
    /// Forgets the kept state; the micro model continues from the last evaluation's end.
    void end();
    /// Phi at (x, parameter) from the current micro state, no base involved.
    MapEvaluation evaluate(const Eigen::VectorXd& x, double parameter = 0.0);

    /// Makes every lifted point liftable (e.g. an ICDF monotone and inside the heights the
    /// particles occupy: IcdfObservable::repair_hook). The map is still Phi of the unrepaired
    /// point (F = Phi - x with the solver's x); a repair changes what is lifted, so it biases a
    /// difference it touches: repairs() counts the evaluations it changed, for the record.
    /// A report with feasible == false is a contract violation (a non-finite iterate).
    void set_repair(RepairHook repair) { repair_ = std::move(repair); }
    /// Solve in other coordinates (see CoarseCoordinates); every x, phi and f of this map is
    /// then in u. \pre both maps set.
    void set_coordinates(CoarseCoordinates coordinates) { coordinates_ = std::move(coordinates); }
    /// Where the micro model may be run (default: anywhere): a difference is taken backwards
    /// rather than leave it (derivative()); callers ask parameter_in_bounds() before a point.
    void set_parameter_bounds(double lo, double hi) {
        parameter_lo_ = lo;
        parameter_hi_ = hi;
    }
    bool parameter_in_bounds(double p) const { return parameter_lo_ <= p && p <= parameter_hi_; }
    long repairs() const { return repairs_; }
    /// The largest change a repair made to a lifted point so far [unit of x].
    double largest_repair() const { return largest_repair_; }

    bool has_base() const { return has_base_; }
    const MapEvaluation& base() const { return base_; }
    const CoarseMapSettings& settings() const { return settings_; }
    bool has_parameter() const { return static_cast<bool>(set_parameter_); }
    /// Micro time run by all evaluations so far [sqrt(d_p/g)] (per member of an ensemble).
    double micro_time() const { return micro_time_; }
    long evaluations() const { return evaluations_; }

  private:
    /// Lift, run tau, restrict: one evaluation from the current micro state.
    MapEvaluation run_once(const Eigen::VectorXd& x, double parameter);
    /// Back to the base's kept state, kept again for the next evaluation (CRN on).
    void rewind();

    CoarseStepper& stepper_;
    CoarseMapSettings settings_;
    std::function<void(double)> set_parameter_;
    RepairHook repair_;
    CoarseCoordinates coordinates_;
    long repairs_ = 0;
    double largest_repair_ = 0;
    double parameter_lo_ = -std::numeric_limits<double>::infinity();
    double parameter_hi_ = std::numeric_limits<double>::infinity();
    double derivative_noise_ = 0;
    MapEvaluation base_;
    bool has_base_ = false;
    double micro_time_ = 0;
    long evaluations_ = 0;
};

}  // namespace efdem::coarse
