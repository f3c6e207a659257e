#pragma once
/// \file
/// The micro model as the projective integrator sees it: a coarse time-stepper that can run a
/// burst, restricting as it goes, and lift a coarse vector back to the micro level
/// (physics.md §10 steps i-v; EquationFreeGit's burst/restrict/lift seams). The integrator
/// never sees particles: an ensemble of DEM realizations and a toy ODE look the same.

#include <cstddef>
#include <limits>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace efdem::coarse {

/// The restricted samples of one burst, in time order.
struct BurstSamples {
    /// Sample times [sqrt(d_p/g)], strictly increasing.
    std::vector<double> t;
    /// Restricted (ensemble-mean) coarse vector at each time, all of one size (e.g. the light
    /// ICDF on the p-grid [d_p]).
    std::vector<Eigen::VectorXd> x;
    /// A scalar that shows the travelling-wave phase at each time (e.g. the centre-of-mass
    /// height [d_p]). Needed by the DT = k T integrator; may stay empty otherwise.
    std::vector<double> phase_signal;
    /// The members' own coarse vectors at each time (R x dim, row r = realization r, in
    /// realization order), whose mean is x: what the statistical error of the ensemble slope
    /// is measured from (member_slope_standard_error()). Either empty (the stepper has no
    /// members, or cannot restrict one on its own) or one matrix per sample.
    std::vector<Eigen::MatrixXd> members;
    /// The members' own phase signals at each time (R values, realization order), whose mean is
    /// phase_signal: what the drift of a fast transient is judged from (phase_drift.hpp).
    /// Either empty or one vector per sample.
    std::vector<Eigen::VectorXd> member_phase;
    /// The members' own expansion signal at each time (for the DEM: the mean particle height,
    /// which the bed's expansion moves and demixing does not): what the end of a fast transient
    /// is judged from (phase_drift.hpp). Either empty (member_phase is used) or one per sample.
    std::vector<Eigen::VectorXd> member_expansion;

    std::size_t size() const { return t.size(); }
};

/**
 * \brief A coarse time-stepper: the micro model behind run / lift / time.
 *
 * In an MPI ensemble every call is collective (every rank calls it with the same arguments);
 * the implementation restricts each realization and reduces to the ensemble mean.
 */
class CoarseStepper {
  public:
    virtual ~CoarseStepper() = default;

    /// Micro clock [sqrt(d_p/g)].
    virtual double time() const = 0;

    /**
     * \brief Runs the micro model for `duration` [sqrt(d_p/g)] and appends to `out` one
     *        restricted sample at the end of each of the stepper's own sampling intervals.
     *
     * The stepper alone decides the sampling interval. The last sample must be taken at the
     * end of the run, i.e. at time() on return: the integrator projects from it. No sample is
     * taken at the start of the run (right after a lift the state is not yet healed).
     */
    virtual void run(double duration, BurstSamples& out) = 0;

    /**
     * \brief Lifts every realization to the coarse vector `target` and sets the micro clock to
     *        `new_time` [sqrt(d_p/g)].
     *
     * `target` has already been through the integrator's repair hook (monotone, inside the
     * feasible range, if the caller installed one).
     */
    virtual void lift(const Eigen::VectorXd& target, double new_time) = 0;

    /**
     * \brief Lifts the members apart (cpi.lift = own): member k (row k of the samples'
     *        BurstSamples::members) to its own coarse vector now plus the jump's increment
     *        (target minus the members' mean now) plus `member_steps.row(k)` minus the rows'
     *        mean, so that the members' mean still lands on `target`; sets the micro clock to
     *        `new_time`.
     *
     * A member whose row is not finite moves by the common increment alone; so do all when the
     * rows do not match the members (the ensemble changed since the samples). Only steppers
     * that restrict their members can (lifts_apart()); the default is a contract violation.
     */
    virtual bool lifts_apart() const { return false; }
    /// Why the last lift() or lift_apart() could not put the micro model at its target (a lift
    /// that moves particles whose overlaps did not relax), or empty (the default: lifts always
    /// succeed). The adaptive integrator handles a failed lift as a rejected jump: back to the
    /// kept state, the next jump shorter.
    virtual std::string lift_failure() const { return {}; }
    /// The last lift's error in X: RMS over X's entries of (the micro model's X after the lift
    /// - the target) [X's units], 0 when a lift puts the micro model exactly at its target (the
    /// default). The adaptive integrator handles a lift whose error exceeds the jump's tolerance
    /// as a failed lift (docs/error_control.md, "A lift that misses its target").
    virtual double lift_error() const { return 0.0; }
    virtual void lift_apart(const Eigen::VectorXd& target, const Eigen::MatrixXd& member_steps,
                            double new_time);

    /**
     * \brief The time of the first sample from which the micro model has been at an end state,
     *        one it never leaves by itself (every realization at rest: a DEM bed the gas no
     *        longer moves), up to the last sample; NaN when it is not (the default: never).
     *
     * Lifts that hold realizations at rest keep such a state. cpi.finish = steady ends a run
     * there.
     */
    virtual double end_state_since() const { return std::numeric_limits<double>::quiet_NaN(); }
    /// Whether some realization was at rest at the last sample (default: never). A partly
    /// stopped ensemble is not judged steady from its slope: the stopped members' zero slopes
    /// would hide the others' drift in their spread.
    virtual bool any_at_rest() const { return false; }

    /// \name Going back: reject-and-redo of adaptive projective integration.
    /// keep_state() keeps the whole micro state (every realization, the random streams, the
    /// clock) in memory; the samples taken from then on are provisional. return_to_kept_state()
    /// puts the micro model back exactly as it was kept and discards those samples (what the
    /// redo runs is bit for bit what a run that never went further would run);
    /// confirm_kept_state() makes them final and forgets the kept state. The work done stays
    /// counted either way. Steppers that cannot (can_keep_state() false) may leave the
    /// defaults, which are contract violations to call.
    ///@{
    virtual bool can_keep_state() const { return false; }
    virtual void keep_state();
    virtual void return_to_kept_state();
    virtual void confirm_kept_state();
    ///@}
};

}  // namespace efdem::coarse
