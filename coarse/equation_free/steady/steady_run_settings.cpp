#include "coarse/equation_free/steady/steady_run_settings.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "core/whole_multiple.hpp"

namespace efdem::coarse {

namespace {
/// Keys of one solver given to the other: refused, naming the key (they would be ignored).
void refuse(const Params& scope, const std::vector<const char*>& keys, const std::string& why,
            const std::string& allowed) {
    for (const char* key : keys)
        if (scope.contains(key)) scope.fail(key, why, allowed);
}
}  // namespace

SteadyRunSettings SteadyRunSettings::from_params(
    const Params& root, double sample_interval, long dimension, Use use,
    const std::vector<ContinuationParameter>& allowed_parameters,
    const std::function<double(const std::string&)>& current_value) {
    SteadyRunSettings s;
    const bool continuation = use == Use::continuation;
    const bool hand_off = use == Use::hand_off;
    s.continuation = continuation;
    const Params steady = root.scope("steady");
    const Params cont = root.scope("continuation");
    const char* interval = "observe.interval";
    const std::string solver =
        continuation ? std::string("newton")
                     : steady.get_or_choice("solver", hand_off ? "anderson" : "newton",
                                            {"newton", "anderson"});
    if (continuation && steady.contains("solver") &&
        steady.get_or_choice("solver", "newton", {"newton", "anderson"}) != "newton")
        steady.fail(
            "solver",
            "mode = continuation corrects every branch point with Newton-GMRES (fixed-point "
            "iteration cannot converge on an unstable branch or at a fold)",
            "newton (or remove it) with mode = continuation");
    s.solver = solver == "anderson" ? Solver::anderson : Solver::newton;
    const bool newton = s.solver == Solver::newton;

    // A hand-off starts from the CPI run's last state: one sample gives the solver its initial
    // guess and the members' noise.
    s.warmup = steady.get_or<double>("warmup", hand_off ? sample_interval : 20.0,
                                     Bounds::open_closed(0.0, 1e7));
    whole_multiple(steady, "warmup", s.warmup, sample_interval, interval);
    s.map.tau = steady.get_or<double>("tau", 20.0, Bounds::open_closed(0.0, 1e7));
    whole_multiple(steady, "tau", s.map.tau, sample_interval, interval);
    s.gap_coordinates =
        steady.get_or_choice("coordinates", "heights", {"heights", "gaps"}) == "gaps";
    // Absent: derived from the noise at the end of the warm-up (SteadyRun::run); what it falls
    // back to without members to measure it (in log gaps 0.2 changes the gaps by about 20 % at
    // most; in heights 0.5 d_p over the nodes).
    s.difference_step_from_noise = newton && !steady.contains("difference_step");
    s.map.difference_step = steady.get_or<double>("difference_step", s.gap_coordinates ? 0.2 : 0.5,
                                                  Bounds::open_closed(0.0, 1e3));
    s.map.common_random_numbers = newton;  // Anderson needs no kept state

    SteadyStopRule stop;
    stop.tolerance = steady.get_or<double>("tolerance", 1e-10, Bounds::closed(0.0, 1e6));
    stop.noise_factor = steady.get_or<double>("noise_factor", 2.0, Bounds::closed(0.0, 1e3));
    s.newton.stop = s.fixed_point.stop = stop;
    const int max_iterations =
        steady.get_or<int>("max_iterations", newton ? 8 : 40, Bounds::closed(0, 10000));
    const int dim = static_cast<int>(std::max(1L, dimension));
    if (newton) {
        s.newton.max_iterations = max_iterations;
        s.newton.max_krylov = steady.get_or<int>("max_krylov", dim, Bounds::closed(1, 100000));
        s.newton.forcing = steady.get_or<double>("forcing", 0.1, Bounds::open(0.0, 1.0));
        s.newton.max_backtracks = steady.get_or<int>("max_backtracks", 3, Bounds::closed(0, 30));
        refuse(steady, {"depth", "damping"}, "is read only with steady.solver = anderson",
               "remove it, or set steady.solver = anderson");
    } else {
        s.fixed_point.max_iterations = max_iterations;
        s.fixed_point.depth = steady.get_or<int>("depth", 3, Bounds::closed(0, 100));
        s.fixed_point.damping =
            steady.get_or<double>("damping", 1.0, Bounds::open_closed(0.0, 1.0));
        refuse(steady, {"max_krylov", "forcing", "max_backtracks"},
               "is read only with steady.solver = newton",
               "remove it, or set steady.solver = newton");
    }
    s.eigenvalues = steady.get_or<int>("eigenvalues", newton ? 3 : 0, Bounds::closed(0, 1000));
    if (s.eigenvalues > dim)
        steady.fail(
            "eigenvalues",
            fmt::format("asks for more eigenvalues than the coarse vector has components ({})",
                        dim),
            fmt::format("0 to {}", dim));
    if (s.eigenvalues > 0 && !newton)
        steady.fail(
            "eigenvalues",
            "needs the CRN derivatives of steady.solver = newton (anderson keeps no micro state)",
            "0 with steady.solver = anderson, or steady.solver = newton");
    s.spectrum.eigenvalues = std::max(1, s.eigenvalues);
    s.spectrum.max_products =
        steady.get_or<int>("eigenvalue_products", dim, Bounds::closed(1, 100000));
    // Arnoldi stops early only when the wanted Ritz values are this accurate; with noisy
    // products it usually runs to eigenvalue_products (the explicit Jacobian at k = dim).
    s.spectrum.tolerance = 1e-3;

    if (!continuation) {
        for (const char* key :
             {"parameter", "end", "step", "max_step", "scale", "max_points", "predictor_fallback"})
            if (cont.contains(key))
                cont.fail(key, "is read only with mode = continuation",
                          "remove it, or set mode = continuation");
        return s;
    }
    std::vector<std::string> names;
    for (const ContinuationParameter& p : allowed_parameters) names.push_back(p.key);
    s.parameter = cont.get_choice("parameter", names);
    const Bounds parameter_bounds =
        std::find_if(allowed_parameters.begin(), allowed_parameters.end(),
                     [&](const ContinuationParameter& p) { return p.key == s.parameter; })
            ->bounds;
    s.parameter_start = current_value(s.parameter);
    s.parameter_end = cont.get<double>("end", parameter_bounds);
    const double range = std::abs(s.parameter_end - s.parameter_start);
    if (range <= 1e-12 * std::max(1.0, std::abs(s.parameter_start)))
        cont.fail("end",
                  fmt::format("equals the start of the range ({} = {:g})", s.parameter,
                              s.parameter_start),
                  fmt::format("a value other than {:g}", s.parameter_start));
    s.parameter_scale = cont.get_or<double>("scale", 0.01, Bounds::open_closed(0.0, 1e3));
    const double step = cont.get_or<double>("step", range / 4.0, Bounds::open_closed(0.0, 1e3));
    if (step > range)
        cont.fail("step",
                  fmt::format("is larger than the range |continuation.end - start| = {:g}", range),
                  fmt::format("(0, {:g}]", range));
    // Noisy correctors stop at the noise level within a step or two, which the iteration-count
    // rule reads as an easy branch: by default the parameter moves by at most `step` a point.
    const double max_step = cont.get_or<double>("max_step", step, Bounds::open_closed(0.0, 1e3));
    s.branch.max_points = cont.get_or<int>("max_points", 12, Bounds::closed(1, 10000));
    s.branch.fallback_ratio =
        cont.get_or<double>("predictor_fallback", 2.0, Bounds::closed(0.0, 1e6));
    // In the scaled parameter lambda = value / scale (the arclength's units: d_p-equivalents).
    ContinuationSettings& b = s.branch;
    b.corrector = s.newton;
    b.parameter_step = step / s.parameter_scale;
    b.step = b.parameter_step;
    b.max_step = 4.0 * b.parameter_step * std::sqrt(static_cast<double>(dim) + 1.0);
    b.min_step = b.parameter_step / 16.0;
    b.max_parameter_step = max_step / s.parameter_scale;
    b.step = std::clamp(b.step, b.min_step, b.max_step);
    b.parameter_min = std::min(s.parameter_start, s.parameter_end) / s.parameter_scale;
    b.parameter_max = std::max(s.parameter_start, s.parameter_end) / s.parameter_scale;
    b.display_scale = s.parameter_scale;
    // The bounds the micro model reads the parameter with (continuation.end too): no corrector
    // runs the micro model outside.
    b.evaluation_min = parameter_bounds.lo / s.parameter_scale;
    b.evaluation_max = parameter_bounds.hi / s.parameter_scale;
    b.stability = s.eigenvalues > 0;
    b.spectrum = s.spectrum;
    b.spectrum.eigenvalues = 1;
    return s;
}

}  // namespace efdem::coarse
