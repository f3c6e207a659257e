#pragma once
/// \file
/// SteadyRunSettings: the scene's `steady.*` and `continuation.*` keys (mode = steady and
/// mode = continuation; docs/steady_states.md), filled straight into the solvers' own settings.
/// Times in sqrt(d_p/g), coarse-vector norms in the unit of the coarse vector (d_p for the
/// ICDF).
///
// clang-format off
/// | key                       | meaning                                                     | default  |
/// |---------------------------|-------------------------------------------------------------|----------|
/// | steady.solver             | `newton` (Newton-GMRES, CRN derivatives) or `anderson`      | newton;  |
/// |                           |                                                             | anderson |
/// |                           |                                                             | hand-off |
/// | steady.warmup             | direct simulation before the first evaluation; its last     | 20; one  |
/// |                           | sample is the initial guess                                 | sample   |
/// |                           |                                                             | hand-off |
/// | steady.tau                | micro time of one evaluation of Phi_tau                     | 20       |
/// | steady.coordinates        | `heights` (the ICDF nodes) or `gaps` (first node, log gaps) | heights  |
/// | steady.difference_step    | h of the CRN differences J v (norm of the perturbation)     | 6 x noise|
/// | steady.tolerance          | absolute floor of the stopping rule on \|F\|                | 1e-10    |
/// | steady.noise_factor       | stop at \|F\| <= this x the noise of F                      | 2        |
/// | steady.max_iterations     | Newton steps (newton) / iterations (anderson)               | 8 / 40   |
/// | steady.max_krylov         | newton: GMRES products per Newton step                      | dim      |
/// | steady.forcing            | newton: relative GMRES tolerance                            | 0.1      |
/// | steady.max_backtracks     | newton: line-search halvings                                | 3        |
/// | steady.depth              | anderson: depth m (0: damped iteration)                     | 3        |
/// | steady.damping            | anderson: beta in (0, 1]                                    | 1        |
/// | steady.eigenvalues        | leading coarse eigenvalues at the solution (0: none)        | 3 newton,|
/// |                           |                                                             | 0 anders.|
/// | steady.eigenvalue_products| most J v products the Arnoldi process spends                | dim      |
/// | continuation.parameter    | the scene key continued in                                  | required |
/// | continuation.end          | the other end of the parameter range (start: the scene's)  | required |
/// | continuation.step         | parameter change of the first predictor                     | range/4  |
/// | continuation.max_step     | most parameter change of any predictor                      | step     |
/// | continuation.scale        | parameter change that weighs as 1 unit of the coarse vector | 0.01     |
/// |                           | in the arclength                                            |          |
/// | continuation.max_points   | branch points, the first included                           | 12       |
/// | continuation.predictor_fallback | |G| at the predictor above this x the stopping        | 2        |
/// |                           | threshold: try the last point, the parameter held there     |          |
// clang-format on
///
/// Newton-only keys are refused with steady.solver = anderson and the other way round;
/// continuation.* keys are refused outside mode = continuation, which always uses Newton.
/// A hand-off (cpi.hand_off = steady: the solve starts from where a CPI run ended) reads the
/// same steady.* keys; its defaults differ where the CPI run already did the work: the state a
/// forward integration reached is a stable one, so Anderson (no derivatives), and the warm-up is
/// one sample of the CPI's last state.

#include <functional>
#include <string>
#include <vector>

#include "coarse/equation_free/steady/coarse_map.hpp"
#include "coarse/equation_free/steady/coarse_spectrum.hpp"
#include "coarse/equation_free/steady/continuation.hpp"
#include "coarse/equation_free/steady/fixed_point_iteration.hpp"
#include "coarse/equation_free/steady/newton_krylov.hpp"
#include "core/param_table.hpp"

namespace efdem::coarse {

/// A scene key continuation.parameter may name, with the bounds the micro model reads it with:
/// continuation.end is read with them, and no corrector runs the micro model outside them.
struct ContinuationParameter {
    std::string key;  ///< "gas_drag.superficial_velocity"
    Bounds bounds;
};

struct SteadyRunSettings {
    enum class Solver { newton, anderson } solver = Solver::newton;
    /// What the keys are read for: mode = steady, mode = continuation, or the hand-off of a CPI
    /// run to the steady solver (cpi.hand_off = steady).
    enum class Use { steady, continuation, hand_off };
    bool continuation = false;  ///< mode = continuation (else a steady solve)
    /// steady.coordinates: solve in the node heights or in the ICDF's gap coordinates
    /// (coarse/demixing/icdf_gap_coordinates.hpp; the caller supplies them).
    bool gap_coordinates = false;
    double warmup = 20.0;
    CoarseMapSettings map;
    /// steady.difference_step absent (newton): h = difference_noise_multiple x the noise norm of
    /// the warm-up's last sample, measured from the members in the solver's coordinates
    /// (SteadyRun::difference_step); map.difference_step is the fallback without members.
    bool difference_step_from_noise = false;
    /// The CRN difference leaves up to sqrt(2) |SE| of noise in Phi(X + h v) - Phi(X) after a
    /// chaotic burst (measured on the demo bed), so J v carries ~sqrt(2)/6 = 0.24 per unit |v|:
    /// a quarter to a half of |J_F v| >= 1 - |mu| for the slow modes (0.6 on the demo bed), while h
    /// stays a few noise widths, where the ICDF's response is still nearly linear (DEM: h = 2 d_p
    /// converged, 0.5 gave J v as noisy as itself; docs/steady_states.md).
    double difference_noise_multiple = 6.0;
    NewtonKrylovSettings newton;
    FixedPointSettings fixed_point;
    /// eigenvalues == 0 in `spectrum_wanted`: no spectrum.
    int eigenvalues = 3;
    SpectrumSettings spectrum;
    /// mode = continuation: the parameter's scene key, its range and scaling. The coarse layer
    /// continues in lambda = value / scale (ContinuationSettings are in those units).
    std::string parameter;
    double parameter_start = 0, parameter_end = 0, parameter_scale = 0.01;
    ContinuationSettings branch;

    /// Reads the keys above. `sample_interval`: the stepper's (observe.interval), which tau and
    /// warmup must be whole multiples of; `dimension`: of the coarse vector; `use`: which run
    /// reads them (the defaults above); `allowed_parameters`: the keys continuation.parameter may
    /// name, and `current_value` the scene's value of one of them (the start of the branch).
    static SteadyRunSettings from_params(
        const Params& root, double sample_interval, long dimension, Use use,
        const std::vector<ContinuationParameter>& allowed_parameters,
        const std::function<double(const std::string&)>& current_value);
};

}  // namespace efdem::coarse
