#include "mpi_driver/output/run_file_schema.hpp"

#include <algorithm>

#include "core/contracts.hpp"

namespace efdem::mpi_driver {

namespace {
using D = std::vector<std::string_view>;
const D scalar{}, sample{"sample"}, sample_node{"sample", "node"},
    sample_r{"sample", "realization"}, sample_r_node{"sample", "realization", "node"}, step{"step"},
    step_coarse{"step", "coarse_node"}, step_r{"step", "realization"}, failure{"failure"},
    iterate{"iterate"}, iterate_node{"iterate", "steady_node"}, steady_node{"steady_node"},
    newton_step{"newton_step"}, gmres{"gmres_entry"}, eigen{"eigenvalue"}, point{"point"},
    point_node{"point", "steady_node"}, fold{"fold"};
}  // namespace

const std::vector<DatasetDoc>& run_file_schema() {
    static const std::vector<DatasetDoc> table = {
        // Fixed datasets: the run's set-up and axes.
        {"/scene", "text", "the scene file as read", scalar},
        {"/parameters", "text",
         "every parameter the run used: 'key = value   [origin]' lines (origin: file:line, "
         "<command line> or default)",
         scalar},
        {"/p", "1", "the ICDF's probability nodes p_i = i/(m+1) (observe.quantiles = m)", {"node"}},
        {"/realization",
         "1",
         "global index of each realization (its seed stream and rank-independent order)",
         {"realization"}},
        // /samples: one row per ensemble sample (every observe.interval of DEM time).
        {"/samples/time", "sqrt(d_p/g)", "time of the sample", sample},
        {"/samples/mean", "d_p",
         "ensemble-mean ICDF of the observed species' heights (the realizations in the ensemble)",
         sample_node},
        {"/samples/variance", "d_p^2",
         "unbiased ensemble variance of the ICDF per node (0 when R = 1)", sample_node},
        {"/samples/icdf", "d_p",
         "each realization's ICDF of the observed species' heights (NaN rows: dropped after a "
         "failure)",
         sample_r_node},
        {"/samples/at_rest", "1",
         "1 where the realization is at rest (every particle slower than 1e-6 sqrt(g d_p) and "
         "accelerated by less than 1e-6 g at the end of 4 sample intervals in a row: a bed the gas "
         "no longer moves), 0 where it moves or was dropped",
         sample_r},
        {"/samples/com", "d_p",
         "each realization's mass-weighted centre-of-mass height (the travelling-wave phase "
         "signal)",
         sample_r},
        {"/samples/realizations_used", "1", "realizations in the means (R less those dropped)",
         sample},
        {"/samples/top_mean", "d_p",
         "ensemble-mean ICDF of the N/2 highest particles regardless of species", sample_node},
        {"/samples/compact",
         "d_p",
         "(A, B, C, D) of the compact fit of y(p) = Q_top - Q_L of the ensemble mean",
         {"sample", "compact_parameter"}},
        {"/samples/compact_status", "1", "status of the compact fit (0 ok)", sample},
        // /bed: observe.bed = true.
        {"/bed/z", "d_p", "centre height of each slab of the solid-fraction profile", {"slab"}},
        {"/bed/species", "text", "species names, in the order of the species axis", {"species"}},
        {"/bed/pressure_drop", "rho_s g d_p",
         "gas pressure drop across the bed, sum_j dz (-dp/dz)_j", sample_r},
        {"/bed/pressure_drop_ratio", "1",
         "pressure drop / (bed weight per area): 1 for a bed the gas fully supports", sample_r},
        {"/bed/pressure_drop_pa", "Pa",
         "/bed/pressure_drop in pascal (x the root attribute si_pressure_Pa; only where the scene "
         "gives the SI scales)",
         sample_r},
        {"/bed/height", "d_p", "bed height: 99 % of the particle volume lies below it", sample_r},
        {"/bed/expansion", "1", "bed height / bed height at the run's first sample", sample_r},
        {"/bed/mixing_index", "1",
         "Lacey mixing index of the observed species over horizontal layers "
         "(observe.mixing_layer): 1 random mixture, 0 segregated",
         sample_r},
        {"/bed/species_height",
         "d_p",
         "number-weighted mean centre height of each species",
         {"sample", "realization", "species"}},
        {"/bed/solid_fraction",
         "1",
         "solid volume fraction phi of each slab (exact partial sphere volumes)",
         {"sample", "realization", "slab"}},
        {"/bed/mean/pressure_drop", "rho_s g d_p", "ensemble mean of /bed/pressure_drop", sample},
        {"/bed/mean/pressure_drop_ratio", "1", "ensemble mean of /bed/pressure_drop_ratio", sample},
        {"/bed/mean/pressure_drop_pa", "Pa", "ensemble mean of /bed/pressure_drop_pa", sample},
        {"/bed/mean/height", "d_p", "ensemble mean of /bed/height", sample},
        {"/bed/mean/expansion", "1",
         "ensemble-mean bed height / its value at the run's first sample", sample},
        {"/bed/mean/mixing_index", "1", "ensemble mean of /bed/mixing_index", sample},
        {"/bed/mean/species_height",
         "d_p",
         "ensemble mean of /bed/species_height",
         {"sample", "species"}},
        {"/bed/mean/solid_fraction",
         "1",
         "ensemble mean of /bed/solid_fraction",
         {"sample", "slab"}},
        // /cpi: one row per attempted coarse step (a rejected step of adaptive CPI has a row too).
        {"/cpi/coarse_node",
         "1",
         "component index of the coarse vector (cpi.observable = icdf: the node of /p)",
         {"coarse_node"}},
        {"/cpi/t_start", "sqrt(d_p/g)", "time at which the step's burst began", step},
        {"/cpi/burst_length", "sqrt(d_p/g)", "DEM time of the step's burst (healing + window)",
         step},
        {"/cpi/healing", "sqrt(d_p/g)", "healing part of the burst (not used for the slope)", step},
        {"/cpi/window", "sqrt(d_p/g)", "window over which the slope was fitted", step},
        {"/cpi/dt_requested", "sqrt(d_p/g)",
         "projective step DT asked for (by cpi.dt, the period rule or the controller)", step},
        {"/cpi/dt", "sqrt(d_p/g)", "projective step DT taken (0: no jump)", step},
        {"/cpi/period", "sqrt(d_p/g)", "travelling-wave period estimated in the burst (NaN: none)",
         step},
        {"/cpi/periods", "1", "wave periods per step (cpi.projection = periods)", step},
        {"/cpi/t_end", "sqrt(d_p/g)", "time after the jump", step},
        {"/cpi/status", "text",
         "what the step did: projected, burst_only, stopped_unstable, too_few_periods, "
         "invalid_burst, infeasible_projection or rejected",
         step},
        {"/cpi/message", "text", "why, where the status needs a reason", step},
        {"/cpi/slope", "d_p/sqrt(d_p/g)", "slope of the coarse vector fitted over the window",
         step_coarse},
        {"/cpi/slope_standard_error", "d_p/sqrt(d_p/g)",
         "standard error of the slope (ensemble spread of the realizations' own slopes / sqrt(R))",
         step_coarse},
        {"/cpi/x_end", "d_p", "coarse vector at the end of the burst", step_coarse},
        {"/cpi/x_projected", "d_p", "coarse vector after the jump (before repair)", step_coarse},
        {"/cpi/repair_max_adjustment", "d_p",
         "largest change the monotone repair made to the projected ICDF", step},
        {"/cpi/repair_clipped", "1", "nodes clipped into the heights the particles occupy", step},
        {"/cpi/repair_non_monotone", "1", "1 if the projected ICDF was not monotone", step},
        {"/cpi/stability_assessed", "1", "1 if the stability monitor could assess the step", step},
        {"/cpi/stability_stable", "1",
         "1 if the projective step's amplification is below 1 for the estimated decay rate", step},
        {"/cpi/stability_rate", "1/sqrt(d_p/g)", "fastest decay rate the monitor estimated", step},
        {"/cpi/stability_amplification", "1",
         "amplification factor of the projective step at that rate", step},
        {"/cpi/controller/accepted", "1", "1 if the adaptive step was accepted", step},
        {"/cpi/controller/steps", "1", "accepted steps so far", step},
        {"/cpi/controller/tolerance", "d_p",
         "cpi.tolerance: error a step may add (RMS over the coarse vector)", step},
        {"/cpi/controller/error_statistical", "d_p",
         "statistical error the budget charged the step: the growth of the accumulated error's "
         "s.d. (DT x s.e. of the slope unless a pooled slope reused bursts; RMS)",
         step},
        {"/cpi/controller/error_statistical_jump", "d_p",
         "the step's own statistical error: DT x s.e. of the slope it used (RMS)", step},
        {"/cpi/controller/error_statistical_burst", "d_p",
         "what the last burst's slope alone would have given at the same DT (RMS)", step},
        {"/cpi/controller/error_statistical_pool", "d_p",
         "what the whole slope pool (cpi.pool bursts) would have given at the same DT (RMS)", step},
        {"/cpi/controller/slope", "text", "cpi.slope: burst or pooled", step},
        {"/cpi/controller/transient", "1",
         "cpi.healing_auto: post-lift transient statistic of the burst after the jump (~1: none)",
         step},
        {"/cpi/controller/transient_threshold", "1",
         "above it the transient counts as measured and the next bursts heal for cpi.healing",
         step},
        {"/cpi/controller/window_noise_ratio", "1",
         "cpi.window_auto: V(W/2)/V(W) of the members' slopes in the accepted burst (2: the "
         "ensemble's random walk, 8: fast noise about the slow path)",
         step},
        {"/cpi/controller/window_noise_correlation", "1",
         "cpi.window_auto: correlation of the members' slopes over the window's two halves", step},
        {"/cpi/controller/window_next", "sqrt(d_p/g)",
         "cpi.window_auto: the window of the bursts from this step on", step},
        {"/cpi/controller/member_step", "d_p",
         "cpi.lift = own: RMS over the realizations and nodes of DT (s_r - mean s), how far the "
         "jump moved the realizations apart (NaN: they moved alike)",
         step},
        {"/cpi/controller/budget", "d_p",
         "cpi.accuracy: the error the jumps may add to the trajectory, a x the ensemble's "
         "standard error (NaN without cpi.accuracy)",
         step},
        {"/cpi/controller/ensemble_standard_error", "d_p",
         "cpi.accuracy: the ensemble's standard error the budget is set from (RMS over the nodes "
         "of sqrt(var/R))",
         step},
        {"/cpi/controller/budget_spent", "d_p",
         "cpi.accuracy: the error the kept jumps have added so far, contracted where a decay is "
         "measured",
         step},
        {"/cpi/controller/contraction_rate", "1/sqrt(d_p/g)",
         "cpi.accuracy: the decay rate credited to the accumulated error (0: none measured)", step},
        {"/cpi/controller/pooled_bursts", "1",
         "bursts the step's slope used (1: the last burst's own)", step},
        {"/cpi/controller/error_truncation", "d_p", "estimated truncation error of the step (RMS)",
         step},
        {"/cpi/controller/predicted_truncation", "d_p",
         "truncation error the controller predicted for the DT it chose", step},
        {"/cpi/controller/dt_tolerance", "sqrt(d_p/g)", "largest DT within tolerance", step},
        {"/cpi/controller/dt_tolerance_2r", "sqrt(d_p/g)", "the same with 2 R realizations", step},
        {"/cpi/controller/dt_tolerance_4r", "sqrt(d_p/g)", "the same with 4 R realizations", step},
        {"/cpi/controller/limited_by", "text",
         "what limited DT: tolerance, dt_max, first burst, stability, end of run, fixed, ...",
         step},
        {"/cpi/controller/error_statistical_nodes", "d_p", "statistical error per coarse component",
         step_coarse},
        {"/cpi/controller/error_truncation_nodes", "d_p", "truncation error per coarse component",
         step_coarse},
        {"/cpi/controller_summary", "text",
         "what the controller did and what more realizations would buy", scalar},
        {"/cpi/lift_changed", "1", "labels lifting changed in each realization", step_r},
        {"/cpi/lift_max_deviation", "d_p",
         "largest |achieved - target| of the lifted ICDF per realization", step_r},
        {"/cpi/lift_at_rest", "1",
         "1 where the realization was at rest and left where it was (cpi.at_rest = hold)", step_r},
        {"/cpi/lift_message", "text", "realizations whose target was repaired or clipped, and why",
         step},
        // /steady: mode = steady | continuation. One row of /steady/iterate per iterate of
        // every solve, as it comes; the rest at the end of the run.
        {"/steady/coarse_node", "1",
         "component index of the coarse vector (cpi.observable = icdf: the node of /p)",
         steady_node},
        {"/steady/iterate/dem_time", "sqrt(d_p/g)",
         "DEM time spent after the warm-up when the iterate's residual was known (per realization)",
         iterate},
        {"/steady/iterate/solve", "1",
         "which solve: 0 the steady solve or the first branch point, k the k-th continuation "
         "corrector",
         iterate},
        {"/steady/iterate/iteration", "1",
         "Newton step or fixed-point iteration within its solve (0: its start)", iterate},
        {"/steady/iterate/residual", "d_p",
         "|F| = |Phi_tau(X) - X| at the iterate, in heights whatever steady.coordinates (a "
         "corrector: F of the point, without the arclength row)",
         iterate},
        {"/steady/iterate/noise", "d_p",
         "noise norm of F: |SE| of Phi_tau(X) from the realizations' spread, in heights", iterate},
        {"/steady/iterate/parameter", "scene unit",
         "continuation: the parameter at the iterate (0 in mode = steady)", iterate},
        {"/steady/iterate/x", "d_p", "the iterate's coarse vector", iterate_node},
        {"/steady/x0", "d_p", "the initial guess: the ensemble mean at the end of the warm-up",
         steady_node},
        {"/steady/x", "d_p",
         "mode = steady: the last iterate (the answer when the solve converged)", steady_node},
        {"/steady/best", "d_p",
         "mode = steady: the iterate with the smallest |F| (saved also when the solve did not "
         "converge); mode = continuation: the first point's, when it did not converge",
         steady_node},
        {"/steady/krylov_products", "1",
         "newton: GMRES products (J v, one burst each) per Newton step", newton_step},
        {"/steady/step_length", "1", "line-search factor (newton) or damping (anderson) per step",
         newton_step},
        {"/steady/gmres_residual", "d_p",
         "newton: GMRES residual |F + J d| before the first product and after each product", gmres},
        {"/steady/gmres_newton_step", "1", "the Newton step each /steady/gmres_residual belongs to",
         gmres},
        {"/steady/eigenvalue_real", "1",
         "real part of a leading eigenvalue mu of dPhi_tau/dX at the answer", eigen},
        {"/steady/eigenvalue_imag", "1", "imaginary part of mu", eigen},
        {"/steady/eigenvalue_rate", "1/sqrt(d_p/g)",
         "log|mu| / tau: the decay (< 0) or growth rate of the mode", eigen},
        {"/steady/eigenvalue_residual", "1",
         "Arnoldi residual estimate of the Ritz pair (noise-free part of the uncertainty of mu)",
         eigen},
        {"/steady/eigenvalue_noise", "1",
         "noise of the J v products over the Krylov basis (members' standard errors): with the "
         "residual, the uncertainty of mu",
         eigen},
        // /branch: mode = continuation, one row per branch point, as it comes.
        {"/branch/parameter", "scene unit",
         "the continuation parameter at the point (continuation.parameter)", point},
        {"/branch/x", "d_p", "the steady coarse vector at the point", point_node},
        {"/branch/residual", "d_p", "|F| at the point, in heights", point},
        {"/branch/noise", "d_p", "noise norm of F at the point, in heights", point},
        {"/branch/mean_height", "d_p",
         "segregation measure: the mean of the ICDF nodes, an estimate of the observed species' "
         "mean height",
         point},
        {"/branch/mean_height_error", "d_p",
         "upper bound on the standard error of /branch/mean_height: noise / sqrt(nodes)", point},
        {"/branch/newton_steps", "1", "Newton steps of the point's corrector", point},
        {"/branch/arclength_step", "1",
         "arclength step that reached the point in (X [d_p], parameter / continuation.scale); 0 "
         "for the first",
         point},
        {"/branch/from_last_point", "1",
         "1: the point's corrector started from the last point at the predicted parameter (the "
         "predictor was farther from steady, continuation.predictor_fallback), 0: from the "
         "predictor",
         point},
        {"/branch/leading_real", "1",
         "real part of the leading eigenvalue mu of dPhi_tau/dX at the point (NaN: not computed)",
         point},
        {"/branch/leading_imag", "1", "imaginary part of the leading mu", point},
        {"/branch/leading_rate", "1/sqrt(d_p/g)",
         "log|mu| / tau of the leading eigenvalue: > 0 an unstable steady state", point},
        {"/branch/leading_residual", "1", "Arnoldi residual estimate of the leading eigenvalue",
         point},
        {"/branch/leading_noise", "1",
         "noise of the J v products over the Krylov basis: with the residual, the uncertainty of "
         "the leading mu",
         point},
        {"/branch/dem_time", "sqrt(d_p/g)",
         "DEM time the point cost (its corrector and eigenvalue, per realization)", point},
        {"/branch/fold_parameter", "scene unit",
         "where the parameter turns along the branch (vertex of a parabola through three points)",
         fold},
        // /failures: one row per realization failure the run survived.
        {"/failures/time", "sqrt(d_p/g)", "when the realization failed", failure},
        {"/failures/realization", "1", "the failed realization", failure},
        {"/failures/action", "text", "dropped, replaced or fatal", failure},
        {"/failures/reason", "text", "the failure's message", failure},
        {"/failures/donor", "1",
         "replaced: the realization whose state it was rebuilt from (-1: none)", failure},
        {"/failures/resumed_at", "sqrt(d_p/g)",
         "cpi: where the interrupted coarse step was redone from", failure},
        {"/failures/realizations_left", "1", "realizations in the ensemble after it", failure},
    };
    return table;
}

const DatasetDoc& dataset_doc(std::string_view path) {
    const auto& t = run_file_schema();
    const auto it =
        std::find_if(t.begin(), t.end(), [&](const DatasetDoc& d) { return d.path == path; });
    EFDEM_EXPECTS(it != t.end());
    return *it;
}

std::string_view dimension_scale(std::string_view dim) {
    if (dim == "sample") return "/samples/time";
    if (dim == "realization") return "/realization";
    if (dim == "node") return "/p";
    if (dim == "step") return "/cpi/t_start";
    if (dim == "coarse_node") return "/cpi/coarse_node";
    if (dim == "species") return "/bed/species";
    if (dim == "slab") return "/bed/z";
    if (dim == "failure") return "/failures/time";
    if (dim == "steady_node") return "/steady/coarse_node";
    if (dim == "iterate") return "/steady/iterate/dem_time";
    if (dim == "point") return "/branch/parameter";
    return "";
}

}  // namespace efdem::mpi_driver
