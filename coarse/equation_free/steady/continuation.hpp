#pragma once
/// \file
/// Pseudo-arclength continuation of coarse steady states in one scalar parameter lambda
/// (Keller 1977; docs/steady_states.md), on a CoarseMap whose hook sets the parameter on the
/// micro model:
///
///   first point: Newton-Krylov on F(X; lambda_0) = 0; tangent t = (z, 1)/|(z, 1)| with
///                F_X z = -F_lambda (GMRES on CRN differences), oriented by `direction`;
///   predictor:   y_pred = y_k + ds t (t: the secant (y_k - y_{k-1})/|.| after the first step,
///                which keeps its orientation through a fold);
///   corrector:   Newton-Krylov on [F(X; lambda); t . (y - y_pred)] = 0 (ArclengthSystem),
///                from y_pred or, when |G(y_pred)| is above fallback_ratio x the stopping
///                threshold of a noisy map and the last point at the predicted parameter,
///                (X_k, lambda_pred), is closer to steady, from that with lambda held there
///                (row e_lambda instead of t: a noisy tangent can overshoot the branch);
///   guard:       no corrector runs the micro model at lambda more than max_parameter_step
///                (or the range's width) outside [parameter_min, parameter_max];
///   step size:   ds *= clamp(target / Newton steps, 1/2, 2) within [min_step, max_step];
///                a failed corrector halves ds and tries again from the same point.
///
/// Each point's stability is the leading eigenvalue of dPhi/dX there (coarse_spectrum.hpp).

#include <functional>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "coarse/equation_free/steady/coarse_map.hpp"
#include "coarse/equation_free/steady/coarse_spectrum.hpp"
#include "coarse/equation_free/steady/newton_krylov.hpp"

namespace efdem::coarse {

struct Branch;
/// Called with the branch so far after each new point (e.g. to record it as the run goes).
using BranchObserver = std::function<void(const Branch&)>;

struct ContinuationSettings {
    NewtonKrylovSettings corrector;
    double step = 0.1;  ///< initial arclength step ds in (X, lambda) (> 0)
    /// > 0: the first step's ds is chosen so that the predictor moves lambda by this much
    /// (ds = parameter_step / |t_lambda|, within [min_step, max_step]); `step` is then unused.
    double parameter_step = 0.0;
    double min_step = 1e-4;
    double max_step = 1.0;
    /// > 0: no predictor moves lambda by more than this (ds <= max_parameter_step / |t_lambda|).
    /// A noisy corrector stops at the noise level in one or two Newton steps, which the
    /// iteration-count rule would read as an easy branch and double ds every point.
    double max_parameter_step = 0.0;
    int max_points = 50;  ///< branch points, the first included
    /// The continuation stops after the first point outside [parameter_min, parameter_max]. A
    /// predictor heading out of the range is shortened to land on its end (the last point).
    double parameter_min = -1e300;
    double parameter_max = 1e300;
    /// Where the micro model can be run at all (e.g. a gas velocity >= 0): no corrector
    /// evaluates beyond, nor beyond one max_parameter_step (or the range's width) outside
    /// [parameter_min, parameter_max].
    double evaluation_min = -std::numeric_limits<double>::infinity();
    double evaluation_max = std::numeric_limits<double>::infinity();
    int target_iterations = 3;  ///< Newton steps per corrector the step size aims at
    /// A predicted point with |F| above this multiple of the stopping threshold is compared
    /// with the last point at the predicted parameter (FallbackGuess: one or two extra bursts).
    double fallback_ratio = 2.0;
    bool stability = true;                            ///< the leading eigenvalue at each point
    SpectrumSettings spectrum = SpectrumSettings{1};  // the leading eigenvalue only
    BranchObserver on_point;                          ///< may be empty
    /// lambda x display_scale is what the log and the end reason show (the scene's units when
    /// the caller continues in a scaled parameter).
    double display_scale = 1.0;
};

struct BranchPoint {
    double parameter = 0;
    Eigen::VectorXd x;
    double residual = 0;  ///< |F| at the point in the stepper's coordinates X (d_p for the ICDF)
    double noise = 0;     ///< the noise norm measured with it, in X
    int newton_iterations = 0;
    double step = 0;  ///< the arclength step that reached it (0 for the first point)
    /// Its corrector started from the last point at the predicted parameter, not the predictor.
    bool from_fallback = false;
    bool has_leading = false;
    CoarseEigenvalue leading;  ///< largest |mu| (if has_leading)
    double micro_time = 0;     ///< micro time this point cost, its spectrum included
};

/// A fold between branch points: lambda has an extremum at point `at`.
struct FoldEstimate {
    std::size_t at = 0;
    /// The vertex of the parabola lambda(s) through points at-1, at, at+1 (s the chord
    /// arclength): error O(ds^3) for a smooth branch.
    double parameter = 0;
};

struct Branch {
    std::vector<BranchPoint> points;
    std::string end_reason;
    /// The first point's Newton solve (in the solver's coordinates): its residual history is
    /// what a user needs when the first point did not converge.
    SteadySolveRecord first_solve;
    double micro_time = 0;
    long evaluations = 0;
    /// Where the parameter turns (consecutive differences change sign).
    std::vector<FoldEstimate> folds() const;
};

class PseudoArclengthContinuation {
  public:
    /// \pre map has a parameter hook and no base; step sizes 0 < min_step <= step <= max_step.
    PseudoArclengthContinuation(CoarseMap& map, const ContinuationSettings& settings);
    /// From the guess x0 at lambda0, with lambda first increasing (direction > 0) or decreasing.
    Branch run(const Eigen::VectorXd& x0, double lambda0, double direction);

  private:
    /// Stability and bookkeeping of a corrected point.
    BranchPoint make_point(const SteadySolveRecord& rec, Eigen::Index n, double step,
                           double micro_before);
    /// The unit tangent at (x, lambda) from F_X z = -F_lambda.
    Eigen::VectorXd first_tangent(const Eigen::VectorXd& x, double lambda, double direction);
    /// The predictor's arclength step from the planned ds: at most max_parameter_step in lambda,
    /// and shortened to land on the end of the range it heads for (then `true`).
    std::pair<double, bool> predictor_step(double ds, double lambda, double t_lambda) const;
    /// "<what> the parameter range [min, max] at lambda", in the display scale.
    std::string range_end(const char* what, double lambda) const;

    CoarseMap& map_;
    ContinuationSettings settings_;
    NewtonKrylov newton_;
};

}  // namespace efdem::coarse
