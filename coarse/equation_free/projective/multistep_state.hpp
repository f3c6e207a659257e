#pragma once
/// \file
/// MultistepState: everything the multistep integrator carries from one step to the next, by
/// name — what a checkpoint stores (each field a named HDF5 dataset under /driver/integrator,
/// checkpoint format 4: mpi_driver/checkpoint_data/checkpoint_format.hpp) and what
/// ProjectiveIntegrator::save_state/restore_state exchange. Checkpoint formats 2 and 3 stored it
/// as a positional vector and three lines of text (from_layout() reads them).

#include <limits>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "coarse/equation_free/estimators/slope_pool.hpp"
#include "coarse/equation_free/projective/multistep_projection.hpp"
#include "coarse/equation_free/projective/stability_monitor.hpp"
#include "coarse/equation_free/projective/step_size_controller.hpp"
#include "coarse/equation_free/projective/trajectory_budget.hpp"

namespace efdem::coarse {

/// The multistep integrator's totals since the start of the run.
struct MultistepTotals {
    long attempts = 0;  ///< jumps tried
    long accepted = 0;  ///< jumps kept
    long rejected = 0;  ///< jumps redone
    long direct = 0;    ///< bursts run without a jump because the tolerance allowed < dt_min
    double dt_taken = 0, dt_tolerance = 0, dt_tolerance_2r = 0,
           dt_tolerance_4r = 0;              ///< sums over kept jumps
    double statistical = 0, truncation = 0;  ///< sums over kept jumps
};

struct MultistepState {
    double t_end = 0.0;              ///< end of the last accepted burst
    Eigen::VectorXd x_end;           ///< X there (empty before the first burst)
    std::vector<SlopeNode> history;  ///< accepted slopes, oldest first (at most steps + 1)
    /// history.front() is the first burst's earlier window: for the curvature, not projected
    /// from.
    bool curvature_only_front = false;
    DecayRateEstimate decay;            ///< from the last accepted burst
    DtLimit hold_kind = DtLimit::none;  ///< fast_transient or in_phase_wave: no jump from it
    std::string hold;                   ///< why (empty: a jump may start there)
    StepSizeState controller;           ///< last kept DT, the rejection cap, rejections in a row
    MultistepTotals totals;
    /// The slope pool (slope_pool.hpp): the last accepted bursts' slopes, oldest first, and how
    /// much of each one's noise the kept jumps put into the state. Empty in checkpoints written
    /// before it (formats 1-3 and early format 4): pooling then starts afresh.
    std::vector<PooledBurst> pool;
    /// The healing of the next burst (cpi.healing_auto changes it); NaN in checkpoints written
    /// before it: the configured cpi.healing.
    double healing = std::numeric_limits<double>::quiet_NaN();
    /// The last lift's error in X, which the next jump plans for (PlanInput::lift_reserve);
    /// NaN in checkpoints written before it: none.
    double lift_reserve = std::numeric_limits<double>::quiet_NaN();
    /// cpi.window_auto: the window of the next burst, the running fast-noise constant and the
    /// bursts it was measured on (window_noise.hpp); NaN / 0 in checkpoints of runs without it
    /// (or written before it).
    double window = std::numeric_limits<double>::quiet_NaN();
    double window_fast_time2 = std::numeric_limits<double>::quiet_NaN();
    int window_measurements = 0;
    /// cpi.lift = own: each member's slope minus the ensemble slope over the last accepted
    /// burst's window (R x dim); empty in checkpoints of runs without it (or written before it).
    Eigen::MatrixXd member_deviation;
    /// cpi.accuracy: the trajectory's error budget (trajectory_budget.hpp); sigma NaN in
    /// checkpoints of runs without it (or written before it).
    TrajectoryBudgetState budget;
    /// The realizations of the last accepted burst (cpi.curvature = pooled: the significance
    /// test's degrees of freedom); 0 in checkpoints written before it: unknown until the next
    /// burst, so the first jump after such a restart adds no curvature.
    int realizations = 0;

    /// Field by field, values compared with == (NaN never equal, as in a vector of doubles).
    bool operator==(const MultistepState& other) const;

    /**
     * \brief The state from the positional layout checkpoint formats 2 and 3 stored
     *        (/driver/integrator, /driver/integrator_text), layouts 2 and 3 (3 added
     *        curvature_only_front as the last value).
     *
     * reals: [layout, n, m, t_end, dt_last, dt_cap, consecutive_rejections, decay ok, rate,
     * ratio, delay], x_end (m), n x (tau, slope (m), se (m)), totals (attempts, accepted,
     * rejected, direct, dt_taken, dt_tolerance, dt_tolerance_2r, dt_tolerance_4r, statistical,
     * truncation), layout 3: curvature_only_front. text: decay message, hold kind, hold (three
     * lines). Throws std::invalid_argument on a malformed layout.
     */
    static MultistepState from_layout(const std::vector<double>& reals, const std::string& text);
};

}  // namespace efdem::coarse
