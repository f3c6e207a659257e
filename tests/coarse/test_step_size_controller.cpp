// StepSizeController on its own (docs/error_control.md §4): plan() with each cap, judge() with
// accept, reject, the redo rule and the rejection cap, and the recorded texts of DtLimit. No
// stepper: the error models are built by hand so that the DT each rule gives is known in closed
// form.
//
// Closed forms used below, for one slope node (forward Euler, W = DT) at tau = t0 with the same
// standard error se in every component and curvature D:
//   statistical part  E_stat(DT) = se DT,
//   truncation part   E_trunc(DT) = D integral_0^DT u du = D DT^2 / 2,
// so the largest DT within a target is target/se (no curvature) or sqrt(2 target / D) (no
// noise). largest_dt_within() bisects to 1e-6 relative and returns the lower end, so a DT from
// the tolerance is compared with a relative margin of 2e-6 (twice the bisection's width); a DT
// set by a cap (dt_max, growth, cpi.dt, one burst, DT/2, the end of the run) is exact.
#include <catch2/catch.hpp>

#include <cmath>
#include <limits>
#include <set>
#include <string>

#include <Eigen/Core>

#include "coarse/equation_free/projective/projective_stability.hpp"
#include "coarse/equation_free/projective/stability_monitor.hpp"
#include "coarse/equation_free/projective/step_size_controller.hpp"

using namespace efdem::coarse;

namespace {

constexpr double kBisection = 2e-6;  // relative: twice largest_dt_within's bracket
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

/// One node at tau = t0 = 100 with standard error `se` in 5 components, curvature `d`.
JumpErrorModel model(double se, double d = 0.0) {
    SlopeNode n{100.0, Eigen::VectorXd::Constant(5, 0.3), Eigen::VectorXd::Constant(5, se)};
    return {{n}, 100.0, d, 1.0, {}, {}};
}

/// tolerance 0.05, safety 0.8 (target 0.04), dt_min 5, dt_max 160, growth 2, burst 20 = 10 + 10.
StepSizeSetup setup() {
    StepSizeSetup s;
    s.control = {.tolerance = 0.05,
                 .dt_min = 5.0,
                 .dt_max = 160.0,
                 .safety = 0.8,
                 .growth = 2.0,
                 .max_rejections = 2};
    s.burst = 20.0;
    s.window = 10.0;
    return s;
}

PlanInput input(const JumpErrorModel& m, double end_time = 1e6) {
    PlanInput in;
    in.model = m;
    in.end_time = end_time;
    return in;
}

/// A jump of `dt` whose error is `e` (all statistical), judged with no curvature after it.
JumpVerdict judge_error(StepSizeController& c, double dt, double e, double d_after = 0.0) {
    return c.judge(dt, {e, 0.0}, model(0.0, d_after));
}

}  // namespace

TEST_CASE("plan: DT from the tolerance, capped by dt_max; what more realizations buy",
          "[unit][coarse][controller]") {
    StepSizeController c(setup());
    // se = 1e-3: target 0.04 / se = 40.
    const DtPlan p = c.plan(input(model(1e-3)));
    CHECK(p.limited_by == DtLimit::tolerance);
    CHECK(p.dt == Approx(40.0).epsilon(kBisection));
    CHECK(p.dt <= 40.0);  // never above the target: the bisection keeps the lower end
    CHECK(p.dt_tolerance == p.dt);
    // Twice and four times the realizations: se / sqrt(2), se / 2.
    CHECK(p.dt_tolerance_2r == Approx(40.0 * std::sqrt(2.0)).epsilon(kBisection));
    CHECK(p.dt_tolerance_4r == Approx(80.0).epsilon(kBisection));
    CHECK(p.message.empty());

    StepSizeSetup s = setup();
    s.control.dt_max = 30.0;
    const DtPlan q = StepSizeController(s).plan(input(model(1e-3)));
    CHECK(q.limited_by == DtLimit::dt_max);
    CHECK(q.dt == 30.0);  // the cap itself, exactly

    // With curvature and no noise: sqrt(2 x 0.04 / 1e-4) = sqrt(800).
    const DtPlan r = c.plan(input(model(0.0, 1e-4)));
    CHECK(r.dt == Approx(std::sqrt(800.0)).epsilon(kBisection));
}

TEST_CASE("plan: the tolerance the last lift spent is reserved, at most half of it",
          "[unit][coarse][controller]") {
    StepSizeController c(setup());
    PlanInput in = input(model(1e-3));  // se 1e-3: DT = target / se
    in.lift_reserve = 0.01;             // target 0.04 - 0.01 = 0.03
    CHECK(c.plan(in).dt == Approx(30.0).epsilon(kBisection));
    in.lift_reserve = 0.5;  // more than the tolerance: only half the target is reserved
    CHECK(c.plan(in).dt == Approx(20.0).epsilon(kBisection));
    // The redo after a rejection plans for the rejected jump's own lift error: the curvature
    // 8e-4 after it allows sqrt(2 x (0.04 - 0.02) / 8e-4) = sqrt(50) with a lift error of 0.02.
    REQUIRE_FALSE(c.judge(40.0, {0.04, 0.0, 0.02}, model(0.0, 8e-4)).accepted);
    CHECK(c.state().dt_cap == Approx(std::sqrt(50.0)).epsilon(kBisection));
}

TEST_CASE("plan: the first jump is capped by cpi.dt, or by one burst without a curvature",
          "[unit][coarse][controller]") {
    // No curvature measured yet (NaN): at most max(dt_min, burst) = 20.
    StepSizeController c(setup());
    const DtPlan p = c.plan(input(model(1e-3, kNaN)));
    CHECK(p.limited_by == DtLimit::first_jump_no_curvature);
    CHECK(p.dt == 20.0);
    CHECK(to_string(p.limited_by) == "first jump (no curvature measured yet)");

    // cpi.dt given: it caps the first jump (curvature known or not), and only the first.
    StepSizeSetup s = setup();
    s.first_dt = 15.0;
    StepSizeController f(s);
    const DtPlan q = f.plan(input(model(1e-3)));
    CHECK(q.limited_by == DtLimit::first_jump_dt);
    CHECK(q.dt == 15.0);
    REQUIRE(judge_error(f, q.dt, 0.01).accepted);
    const DtPlan after = f.plan(input(model(1e-3)));
    CHECK(after.limited_by == DtLimit::growth);  // 2 x 15 = 30 < 40: growth, not cpi.dt
    CHECK(after.dt == 30.0);
}

TEST_CASE("plan: growth over the last kept DT, rounding to the sampling grid",
          "[unit][coarse][controller]") {
    StepSizeSetup s = setup();
    s.dt_quantum = 3.0;
    StepSizeController c(s);
    REQUIRE(judge_error(c, 12.0, 0.01).accepted);
    CHECK(c.state().dt_last == 12.0);
    const DtPlan p = c.plan(input(model(1e-3)));  // tolerance ~40, growth 24
    CHECK(p.limited_by == DtLimit::growth);
    CHECK(p.dt == 24.0);  // 24 is a multiple of 3: kept exactly
    REQUIRE(judge_error(c, 24.0, 0.01).accepted);
    const DtPlan q = c.plan(input(model(1e-3)));  // tolerance 39.99996... -> floor to 39
    CHECK(q.limited_by == DtLimit::tolerance);
    CHECK(q.dt == 39.0);
}

TEST_CASE("plan: below dt_min, at the end of the run, held bursts: no jump or a shorter one",
          "[unit][coarse][controller]") {
    StepSizeController c(setup());
    SECTION("the tolerance allows less than dt_min") {
        const DtPlan p = c.plan(input(model(0.01)));  // 0.04 / 0.01 = 4 < 5
        CHECK(p.dt == 0.0);
        CHECK(p.limited_by == DtLimit::below_dt_min);
        CHECK(to_string(p.limited_by) == "tolerance below dt_min");
        CHECK_THAT(p.message, Catch::Contains("the tolerance 0.05 allows DT = 4") &&
                                  Catch::Contains("one burst of direct simulation instead"));
    }
    SECTION("the burst after this jump ends the run exactly") {
        // t0 = 100, burst 20, end 150: a jump may take the 30 left after its burst (< 40).
        const DtPlan p = c.plan(input(model(1e-3), 150.0));
        CHECK(p.limited_by == DtLimit::end_of_run);
        CHECK(p.dt == 30.0);
    }
    SECTION("a jump never leaves less than a whole burst before the end") {
        // End 165: 45 left after the burst; 40 would leave 5 < one burst, so the jump leaves
        // exactly one burst more: 45 - 20 = 25 (end_of_run_jump_limit).
        const DtPlan p = c.plan(input(model(1e-3), 165.0));
        CHECK(p.limited_by == DtLimit::end_of_run);
        CHECK(p.dt == 25.0);
    }
    SECTION("this step's burst is the run's last") {
        const DtPlan p = c.plan(input(model(1e-3), 120.0));
        CHECK(p.dt == 0.0);
        CHECK(p.limited_by == DtLimit::end_of_run);
    }
    SECTION("a burst still in a fast transient holds the jump back") {
        PlanInput in = input(model(1e-3));
        in.hold = DtLimit::fast_transient;
        in.hold_message = "still in a fast transient (drift 3 x noise)";
        const DtPlan p = c.plan(in);
        CHECK(p.dt == 0.0);
        CHECK(p.limited_by == DtLimit::fast_transient);
        CHECK(p.message ==
              "still in a fast transient (drift 3 x noise): one burst of direct "
              "simulation");
        CHECK(std::isnan(p.dt_tolerance));  // not planned from the tolerance
    }
}

TEST_CASE("plan: DT is halved until the measured transient is not amplified",
          "[unit][coarse][controller]") {
    // Forward Euler, burst 20 = 10 + 10: lambda = -0.1 is amplified at DT = 80 and not at 40
    // (docs/error_control.md §5; checked here with the monitor itself).
    DecayRateEstimate decay;
    decay.ok = true;
    decay.rate = -0.1;
    const CpiCycle at80{SlopeEstimator::least_squares, 20.0, 10.0, 80.0, 1};
    CpiCycle at40 = at80;
    at40.dt = 40.0;
    REQUIRE(!assess_stability(decay, at80).stable);
    REQUIRE(assess_stability(decay, at40).stable);
    StepSizeSetup s = setup();
    s.control.dt_max = 80.0;
    PlanInput in = input(model(1e-4));  // the tolerance allows 400: dt_max 80
    in.decay = decay;
    const DtPlan p = StepSizeController(s).plan(in);
    CHECK(p.limited_by == DtLimit::stability);
    CHECK(p.dt == 40.0);
    REQUIRE(p.stability.has_value());
    CHECK(p.stability->stable);  // the assessment of the DT taken

    // No stable DT >= dt_min: no jump, and the message says why.
    s.control.dt_min = 50.0;
    const DtPlan q = StepSizeController(s).plan(in);
    CHECK(q.dt == 0.0);
    CHECK(q.limited_by == DtLimit::stability);
    CHECK_THAT(q.message, Catch::StartsWith("no DT >= cpi.dt_min is stable"));
}

TEST_CASE("plan: the stability check models the slope the run fits (cpi.slope_fit)",
          "[unit][coarse][controller]") {
    // Burst 2 + 18, DT = 80, lambda = -0.5: the least-squares slope damps the mode (G = 0.85),
    // the increment's end points see it undamped (G = 1.63): halved for the increment only.
    DecayRateEstimate decay;
    decay.ok = true;
    decay.rate = -0.5;
    StepSizeSetup s = setup();
    s.burst = 20.0;
    s.window = 18.0;
    s.control.dt_max = 80.0;
    PlanInput in = input(model(1e-4));  // the tolerance allows 400: dt_max 80
    in.decay = decay;
    const DtPlan ls = StepSizeController(s).plan(in);
    CHECK(ls.dt == 80.0);
    CHECK(ls.limited_by != DtLimit::stability);
    s.estimator = SlopeEstimator::increment;
    const DtPlan inc = StepSizeController(s).plan(in);
    CHECK(inc.dt < 80.0);
    CHECK(inc.limited_by == DtLimit::stability);
    REQUIRE(inc.stability.has_value());
    CHECK(inc.stability->stable);
}

TEST_CASE("judge: accept within the tolerance, reject above it, and the redo rule",
          "[unit][coarse][controller]") {
    StepSizeController c(setup());
    SECTION("within the tolerance: kept, the caps lifted") {
        c.jump_failed(60.0);                               // a cap of 30 from an earlier failure
        const JumpVerdict v = judge_error(c, 20.0, 0.05);  // error == tolerance: kept
        CHECK(v.accepted);
        CHECK(v.message.empty());
        CHECK(c.state().dt_last == 20.0);
        CHECK(std::isinf(c.state().dt_cap));
        CHECK(c.state().consecutive_rejections == 0);
    }
    SECTION("rejected: the next DT is what the curvature after the jump allows") {
        // Curvature 8e-4 after the jump: sqrt(2 x 0.04 / 8e-4) = 10 < DT/2 = 20.
        const JumpVerdict v = judge_error(c, 40.0, 0.08, 8e-4);
        CHECK(!v.accepted);
        CHECK_THAT(v.message, Catch::StartsWith("step rejected: error 0.08 = 1.60 x tolerance"));
        CHECK(c.state().dt_cap == Approx(10.0).epsilon(kBisection));
        CHECK(c.state().consecutive_rejections == 1);
        CHECK(std::isnan(c.state().dt_last));  // nothing kept yet
        const DtPlan p = c.plan(input(model(1e-3)));
        CHECK(p.limited_by == DtLimit::rejection);
        CHECK(p.dt == c.state().dt_cap);
    }
    SECTION("rejected with a mild curvature: at most half the DT") {
        // Curvature 5e-5 allows 40 > 20: the cap is DT/2 exactly.
        REQUIRE(!judge_error(c, 40.0, 0.06, 5e-5).accepted);
        CHECK(c.state().dt_cap == 20.0);
    }
    SECTION("rejected with a curvature that allows nothing >= dt_min: one burst directly") {
        // sqrt(2 x 0.04 / 0.01) = 2.8 < dt_min = 5: cap 0, the next plan makes no jump.
        REQUIRE(!judge_error(c, 40.0, 0.2, 0.01).accepted);
        CHECK(c.state().dt_cap == 0.0);
        const DtPlan p = c.plan(input(model(1e-3)));
        CHECK(p.dt == 0.0);
        CHECK(p.limited_by == DtLimit::below_dt_min);
        CHECK_THAT(p.message, Catch::Contains("the curvature the rejected jump showed allows no "
                                              "DT >= cpi.dt_min = 5"));
        c.direct_burst_done();
        CHECK(std::isinf(c.state().dt_cap));
    }
    SECTION("the lift's own error counts: within the tolerance alone, above it with the lift") {
        // 0.03 statistical is within 0.05; with a lift that left X 0.03 away it is 0.06.
        CHECK(c.judge(20.0, {0.03, 0.0, 0.0}, model(0.0)).accepted);
        const JumpVerdict v = c.judge(20.0, {0.03, 0.0, 0.03}, model(0.0));
        CHECK(!v.accepted);
        CHECK_THAT(v.message, Catch::Contains("error 0.06 = 1.20 x tolerance (statistical 0.03, "
                                              "truncation 0, lift 0.03)"));
    }
    SECTION("a forced rejection halves DT") {
        const JumpVerdict v = c.judge(40.0, {0.01, 0.0}, model(0.0), true);
        CHECK(!v.accepted);
        CHECK_THAT(v.message, Catch::StartsWith("step rejected (forced)"));
        CHECK(c.state().dt_cap == 20.0);
    }
    SECTION("a jump that could not be made: the next one at most half as far") {
        c.jump_failed(30.0);
        CHECK(c.state().dt_cap == 15.0);
    }
}

TEST_CASE("judge: the rejection cap and dt_min keep a jump above the tolerance",
          "[unit][coarse][controller]") {
    StepSizeController c(setup());  // max_rejections = 2
    REQUIRE(!judge_error(c, 40.0, 0.08, 8e-4).accepted);
    REQUIRE(!judge_error(c, 10.0, 0.08, 8e-4).accepted);
    CHECK(c.state().consecutive_rejections == 2);
    const JumpVerdict v = judge_error(c, 10.0, 0.08, 8e-4);
    CHECK(v.accepted);
    CHECK(v.message == "error 0.08 = 1.60 x tolerance kept: too many rejections in a row");
    CHECK(c.state().consecutive_rejections == 0);

    StepSizeController d(setup());
    const JumpVerdict at_floor = judge_error(d, 5.0, 0.08);
    CHECK(at_floor.accepted);
    CHECK(at_floor.message == "error 0.08 = 1.60 x tolerance kept: DT is at cpi.dt_min");
}

TEST_CASE("fixed DT: the controller only shortens at the end and keeps every jump",
          "[unit][coarse][controller]") {
    StepSizeSetup s = setup();
    s.adaptive = false;
    s.fixed_dt = 80.0;
    StepSizeController c(s);
    const DtPlan p = c.plan(input(model(1.0, kNaN)));
    CHECK(p.dt == 80.0);
    CHECK(p.limited_by == DtLimit::fixed);
    CHECK(to_string(p.limited_by) == "fixed");
    CHECK(c.plan(input(model(1.0), 150.0)).dt == 30.0);  // as the adaptive end-of-run rule
    const JumpVerdict v = judge_error(c, 80.0, 100.0);
    CHECK(v.accepted);
    CHECK(v.message.empty());
}

TEST_CASE("cpi.jump_until: the last jump ends there, and none after it",
          "[unit][coarse][controller]") {
    // The burst ends at t0 = 100. Without curvature the tolerance allows DT = 0.04 / se.
    StepSizeController c(setup());
    PlanInput in = input(model(1e-3));  // DT 40 from the tolerance
    in.jump_end = 130.0;
    const DtPlan p = c.plan(in);
    CHECK(p.dt == 30.0);  // shortened to end at the jump end exactly
    CHECK(p.limited_by == DtLimit::jump_until);
    in.jump_end = 103.0;  // 3 left < cpi.dt_min = 5: a burst instead
    const DtPlan q = c.plan(in);
    CHECK(q.dt == 0.0);
    CHECK(q.limited_by == DtLimit::jump_until);
    CHECK(q.message.find("less than cpi.dt_min") != std::string::npos);
    in.jump_end = 100.0;  // the burst ended there: bursts only from here
    const DtPlan r = c.plan(in);
    CHECK(r.dt == 0.0);
    CHECK(r.message.find("no jump after t = 100") != std::string::npos);
    in.jump_end = 1000.0;  // far: the tolerance's DT, as without the key
    CHECK(c.plan(in).dt == Approx(40.0).epsilon(kBisection));
    // Fixed DT: capped in the same way, and no jump once it is passed.
    StepSizeSetup s = setup();
    s.adaptive = false;
    s.fixed_dt = 80.0;
    StepSizeController f(s);
    in.jump_end = 150.0;
    CHECK(f.plan(in).dt == 50.0);
    in.jump_end = 90.0;
    CHECK(f.plan(in).dt == 0.0);
    CHECK(f.plan(in).limited_by == DtLimit::jump_until);
}

TEST_CASE("DtLimit's texts are the recorded ones and read back", "[unit][coarse][controller]") {
    // The run file's /cpi/controller/limited_by and the CSVs hold these texts: they must not
    // change (run files are compared byte for byte with earlier versions).
    const std::pair<DtLimit, const char*> recorded[] = {
        {DtLimit::none, ""},
        {DtLimit::fixed, "fixed"},
        {DtLimit::first_burst, "first burst"},
        {DtLimit::tolerance, "tolerance"},
        {DtLimit::dt_max, "dt_max"},
        {DtLimit::first_jump_dt, "first jump (cpi.dt)"},
        {DtLimit::first_jump_no_curvature, "first jump (no curvature measured yet)"},
        {DtLimit::growth, "growth"},
        {DtLimit::rejection, "rejection"},
        {DtLimit::end_of_run, "end of run"},
        {DtLimit::below_dt_min, "tolerance below dt_min"},
        {DtLimit::stability, "stability"},
        {DtLimit::fast_transient, "fast transient"},
        {DtLimit::in_phase_wave, "in-phase wave"},
        {DtLimit::jump_until, "cpi.jump_until"},
    };
    std::set<std::string> texts;
    for (const auto& [limit, text] : recorded) {
        CHECK(to_string(limit) == text);
        CHECK(dt_limit_from_string(text) == limit);
        texts.insert(text);
    }
    CHECK(texts.size() == std::size(recorded));
    CHECK(!dt_limit_from_string("growth ").has_value());
}
