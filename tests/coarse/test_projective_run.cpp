// The coarse run loop (coarse/equation_free/projective/projective_run.hpp) on toy steppers, without
// MPI or DEM: the end-of-run rule, the observable fallback, the no-progress and instability stops,
// the observers' calls, and a resumed run that continues the uninterrupted one bit for bit.
#include <catch2/catch.hpp>

#include <cmath>
#include <limits>
#include <optional>
#include <string>
#include <tuple>

#include <Eigen/Core>

#include "coarse/equation_free/projective/cpi_settings.hpp"
#include "coarse/equation_free/projective/projective_run.hpp"
#include "core/param_table.hpp"
#include "tests/coarse/toy_steppers.hpp"
#include "tests/support/input_error.hpp"

using namespace efdem;
using namespace efdem::coarse;

namespace {
constexpr double kH = 0.1;  // sampling interval of the toys

/// Two slow decaying modes (P = I + h A + (h A)^2/2): DT = 8 is well inside the stable range.
test::LinearToyStepper slow_toy() {
    Eigen::MatrixXd a(2, 2);
    a << -0.05, 0.01, 0.0, -0.02;
    const Eigen::MatrixXd p = (Eigen::MatrixXd::Identity(2, 2) + kH * a + 0.5 * kH * kH * a * a);
    return test::LinearToyStepper(p, kH, Eigen::Vector2d(3.0, 1.0));
}

/// The input error CpiSettings raises for the scene `text` (on a 0.5 sampling grid).
std::string cpi_refusal(const std::string& text) {
    ParamTable t = ParamTable::from_text(text, "scene.cfg", "/scenes");
    return test::input_error([&] { CpiSettings::from_params(t.root().scope("cpi"), 0.5); }).what();
}

/// Bursts of 1 + 1, DT = 8: a cycle of 10 time units.
CpiSettings fixed_settings(double warmup = 0.0) {
    CpiSettings s;
    s.warmup = warmup;
    s.fixed.burst.healing = 1.0;
    s.fixed.burst.window = 1.0;
    s.fixed.dt = 8.0;
    return s;
}

CoarseVariable variable(std::string name, int* repairs = nullptr) {
    CoarseVariable v;
    v.name = name;
    v.description = name + " variable";
    if (repairs)
        v.repair = [repairs](Eigen::VectorXd&) {
            ++*repairs;
            return RepairReport{};
        };
    return v;
}

/// Counts the callbacks and keeps a copy of the stepper and loop state before step `at`.
template <class Stepper>
struct Recorder final : ProjectiveRunObserver {
    const Stepper* stepper = nullptr;
    long at = -1;
    long first = 0;  ///< coarse steps done before this run (a resumed run)
    int warmups = 0, betweens = 0, steps = 0;
    std::optional<Stepper> snapshot;
    std::optional<ProjectiveRunState> snapshot_state;
    void warmup_done(const ProjectiveRun&) override { ++warmups; }
    void between_steps(const ProjectiveRun& run) override {
        ++betweens;
        if (run.state().coarse_steps == at && !snapshot) {  // the first between at `at`
            snapshot.emplace(*stepper);
            snapshot_state = run.state();
        }
    }
    void step_done(const ProjectiveRun& run, const ProjectiveStepRecord&) override {
        ++steps;
        CHECK(run.state().coarse_steps == first + steps);
    }
};

/// A linear toy whose primary restriction fails (NaN samples) from t_fail on; selecting the
/// fallback variable switches to the exact samples. Copyable, like LinearToyStepper.
class FailingPrimaryStepper final : public CoarseStepper {
  public:
    FailingPrimaryStepper(test::LinearToyStepper toy, double t_fail)
        : toy_(std::move(toy)), t_fail_(t_fail) {}
    double time() const override { return toy_.time(); }
    void run(double duration, BurstSamples& out) override {
        const std::size_t first = out.size();
        toy_.run(duration, out);
        if (!use_primary) return;
        for (std::size_t k = first; k < out.size(); ++k)
            if (out.t[k] >= t_fail_) out.x[k].setConstant(std::numeric_limits<double>::quiet_NaN());
    }
    void lift(const Eigen::VectorXd& target, double new_time) override {
        toy_.lift(target, new_time);
    }
    const Eigen::VectorXd& state() const { return toy_.state(); }
    bool use_primary = true;
    int selects = 0;

  private:
    test::LinearToyStepper toy_;
    double t_fail_;
};

/// A linear toy that reaches an end state at t_rest: from then on it does not move (its state
/// stays what it was at t_rest, lifts included) and end_state_since() says since when.
class RestingStepper final : public CoarseStepper {
  public:
    RestingStepper(test::LinearToyStepper toy, double t_rest)
        : toy_(std::move(toy)), t_rest_(t_rest) {}
    double time() const override { return toy_.time(); }
    void run(double duration, BurstSamples& out) override {
        const std::size_t first = out.size();
        toy_.run(duration, out);
        for (std::size_t k = first; k < out.size(); ++k)
            if (out.t[k] >= t_rest_ - 1e-9) {
                if (std::isnan(since_)) {
                    since_ = out.t[k];
                    rest_ = out.x[k];
                }
                out.x[k] = rest_;
            }
    }
    void lift(const Eigen::VectorXd& target, double new_time) override {
        toy_.lift(std::isnan(since_) ? target : rest_, new_time);
    }
    double end_state_since() const override { return since_; }

  private:
    test::LinearToyStepper toy_;
    double t_rest_;
    double since_ = std::numeric_limits<double>::quiet_NaN();
    Eigen::VectorXd rest_;
};
}  // namespace

TEST_CASE("the coarse run loop ends at t_origin + duration exactly, with the warm-up first",
          "[unit][coarse][run]") {
    auto toy = slow_toy();
    ProjectiveRun run(fixed_settings(2.0), toy, variable("x"));
    Recorder<test::LinearToyStepper> seen;
    seen.stepper = &toy;
    run.add_observer(seen);
    // Warm-up to 2, nine cycles of 10 to 92, a burst to 94 and the jump shortened to 6: the
    // run ends at 100 after 10 coarse steps. Sums of multiples of 0.1: exact to 1e-9.
    const double planned = planned_micro_time(2.0, 100.0, 2.0, 8.0);
    CHECK(planned == Approx(20.0).margin(1e-9));
    const ProjectiveRunOutcome out = run.run(100.0);
    CHECK(out.end_status == "completed");
    CHECK(out.coarse_steps == 10);
    CHECK(toy.time() == Approx(100.0).margin(1e-9));
    CHECK(out.simulated_time == Approx(100.0).margin(1e-9));
    CHECK_FALSE(out.fell_back);
    CHECK(toy.lifts == 10);
    CHECK(seen.warmups == 1);
    CHECK(seen.betweens == 11);  // before the warm-up (where a run can stop) and before each step
    CHECK(seen.steps == 10);
    CHECK(run.end_time() == 100.0);
}

TEST_CASE("a run shorter than warm-up plus one burst stops with no coarse step, and says so",
          "[unit][coarse][run]") {
    auto toy = slow_toy();
    ProjectiveRun run(fixed_settings(10.0), toy, variable("x"));
    const ProjectiveRunOutcome out = run.run(11.0);  // 1 time unit left after warm-up < burst 2
    CHECK(out.coarse_steps == 0);
    CHECK(out.jumps == 0);
    CHECK(toy.time() == Approx(10.0).margin(1e-9));
    CHECK(out.end_status ==
          "completed (no projective jump: the 1 time units after the warm-up were less than one "
          "burst (2); all 10 "
          "time units were direct simulation)");
}

TEST_CASE("a run of exactly warm-up plus one burst makes one burst and no jump, and says so",
          "[unit][coarse][run]") {
    auto toy = slow_toy();
    ProjectiveRun run(fixed_settings(10.0), toy, variable("x"));
    const ProjectiveRunOutcome out = run.run(12.0);  // warm-up 10, burst 2, nothing left to jump
    CHECK(out.coarse_steps == 1);
    CHECK(out.jumps == 0);
    CHECK(toy.lifts == 0);
    CHECK(out.end_status.rfind(
              "completed (no projective jump: 1 coarse step(s), each a burst only;", 0) == 0);
}

TEST_CASE(
    "a run that jumps ends plain 'completed'; a resumed run does not judge the jumps it did not "
    "see",
    "[unit][coarse][run]") {
    // Warm-up to 2, two cycles of burst 2 + jump 8 to 22, a last burst to 24 with nothing left to
    // jump.
    auto toy = slow_toy();
    ProjectiveRun run(fixed_settings(2.0), toy, variable("x"));
    Recorder<test::LinearToyStepper> seen;
    seen.stepper = &toy;
    seen.at = 2;  // the state before the third step: 2 jumps done, 2 time units left (one burst)
    run.add_observer(seen);
    ProjectiveRunOutcome out = run.run(24.0);
    CHECK(out.jumps == 2);
    CHECK(out.end_status == "completed");
    // Resumed before the last step (a burst only, no jump left): no jump in this call, but two
    // before it, which the loop state does not count, so no claim about jumps.
    REQUIRE(seen.snapshot);
    auto again = *seen.snapshot;
    ProjectiveRun resumed(fixed_settings(2.0), again, variable("x"));
    out = resumed.run(24.0, seen.snapshot_state);
    CHECK(out.jumps == 0);
    CHECK(out.end_status == "completed");
}

TEST_CASE("the planned micro time of a run follows the shortened last jumps",
          "[unit][coarse][run]") {
    // Bursts of 20, DT 80: from 10 to 200 two bursts (jumps 80, 70); to 225 three (80, 75,
    // burst only); to 210 two (80, 80). DT = 0 is a direct run in bursts: all of the time left.
    // Less than a burst left: nothing. Sums of a few multiples of 20: exact to 1e-9.
    CHECK(planned_micro_time(10, 200, 20, 80) == Approx(40).margin(1e-9));
    CHECK(planned_micro_time(10, 225, 20, 80) == Approx(60).margin(1e-9));
    CHECK(planned_micro_time(10, 210, 20, 80) == Approx(40).margin(1e-9));
    CHECK(planned_micro_time(0, 100, 20, 0) == Approx(100).margin(1e-9));
    CHECK(planned_micro_time(190, 200, 20, 80) == 0.0);
}

TEST_CASE("a failing coarse variable falls back once and the run completes on the fallback",
          "[unit][coarse][run]") {
    FailingPrimaryStepper stepper(slow_toy(), 25.0);
    int primary_repairs = 0, fallback_repairs = 0;
    CoarseVariable fallback = variable("b", &fallback_repairs);
    fallback.select = [&stepper] {
        stepper.use_primary = false;
        ++stepper.selects;
    };
    CoarseVariable primary = variable("a", &primary_repairs);
    primary.failure = [] { return std::string("the toy restriction failed"); };
    ProjectiveRun run(fixed_settings(), stepper, primary, fallback);
    Recorder<FailingPrimaryStepper> seen;
    seen.stepper = &stepper;
    seen.at = 5;
    run.add_observer(seen);
    const ProjectiveRunOutcome out = run.run(100.0);
    // Cycles start at 0, 10, 20: the third burst (20..22) is clean, its jump lands at 30, so
    // the fourth burst (30..32) is the first with NaN samples: rejected, no jump; the fallback
    // takes over at t = 32 and the run still ends at 100.
    CHECK(out.end_status == "completed (a observable fell back to b)");
    CHECK(out.fell_back);
    CHECK(stepper.selects == 1);
    CHECK(primary_repairs == 3);
    CHECK(fallback_repairs == out.coarse_steps - 4);
    CHECK(stepper.time() == Approx(100.0).margin(1e-9));

    SECTION("a resumed run continues on the fallback and ends in the same state, bit for bit") {
        REQUIRE(seen.snapshot);
        REQUIRE(seen.snapshot_state->fell_back);
        FailingPrimaryStepper resumed_stepper = *seen.snapshot;
        resumed_stepper.use_primary = true;  // a restarted process starts on the primary
        CoarseVariable fb = fallback;
        fb.select = [&resumed_stepper] {
            resumed_stepper.use_primary = false;
            ++resumed_stepper.selects;
        };
        ProjectiveRun again(fixed_settings(), resumed_stepper, primary, fb);
        const ProjectiveRunOutcome out2 = again.run(100.0, seen.snapshot_state);
        CHECK(out2.end_status == out.end_status);
        CHECK(out2.coarse_steps == out.coarse_steps);
        CHECK(resumed_stepper.time() == stepper.time());
        CHECK(resumed_stepper.state() == stepper.state());
    }
}

TEST_CASE("without a fallback, three steps without a jump stop the run", "[unit][coarse][run]") {
    FailingPrimaryStepper stepper(slow_toy(), 25.0);
    ProjectiveRun run(fixed_settings(), stepper, variable("a"));
    const ProjectiveRunOutcome out = run.run(100.0);
    // Three clean steps (to t = 30), then three rejected bursts (30..32, 32..34, 34..36).
    CHECK(out.coarse_steps == 3 + kMaxStepsWithoutProgress);
    CHECK_THAT(out.end_status, Catch::StartsWith("stopped at t = 36: invalid_burst"));
    CHECK(stepper.time() == Approx(36.0).margin(1e-9));
}

TEST_CASE("StabilityPolicy::stop ends the run at the first flagged step", "[unit][coarse][run]") {
    // A fast mode lambda = -2 seen in the window: |G| of forward Euler with DT = 8 is about
    // |1 - 16| >> 1, so the monitor flags the first step and the stop policy takes no jump.
    test::LinearToyStepper toy(Eigen::MatrixXd::Constant(1, 1, std::exp(-2.0 * kH)), kH,
                               Eigen::VectorXd::Constant(1, 5.0));
    CpiSettings s = fixed_settings();
    s.fixed.burst.healing = 0.0;
    s.fixed.burst.window = 2.0;
    s.fixed.burst.stability = StabilityPolicy::stop;
    ProjectiveRun run(s, toy, variable("x"));
    const ProjectiveRunOutcome out = run.run(100.0);
    CHECK(out.coarse_steps == 1);
    CHECK_THAT(out.end_status, Catch::StartsWith("stopped at t = 2: stopped_unstable"));
    CHECK(toy.lifts == 0);
}

namespace {
/// A whole run of the slow toy (warm-up 2, 100 time units), and a second run resumed from the
/// copy of the stepper and loop state kept at the first between_steps with `at` coarse steps
/// done. Returns {whole, resumed} outcomes; the checks compare the two ends.
struct ResumedPair {
    ProjectiveRunOutcome whole, rest;
    std::optional<ProjectiveRunState> kept;
    test::LinearToyStepper end_whole, end_rest;
    int warmups_resumed = 0;
    bool warmed_up_at_end = false;
};
ResumedPair run_and_resume(long at) {
    auto toy = slow_toy();
    ProjectiveRun run(fixed_settings(2.0), toy, variable("x"));
    Recorder<test::LinearToyStepper> seen;
    seen.stepper = &toy;
    seen.at = at;
    run.add_observer(seen);
    ResumedPair out{run.run(100.0), {}, {}, toy, toy, 0, false};
    REQUIRE(seen.snapshot);
    out.kept = seen.snapshot_state;
    out.warmed_up_at_end = run.state().warmed_up;
    test::LinearToyStepper copy = *seen.snapshot;
    ProjectiveRun resumed(fixed_settings(2.0), copy, variable("x"));
    Recorder<test::LinearToyStepper> seen2;
    seen2.stepper = &copy;
    seen2.first = at;
    resumed.add_observer(seen2);
    out.rest = resumed.run(100.0, seen.snapshot_state);
    out.end_whole = toy;
    out.end_rest = copy;
    out.warmups_resumed = seen2.warmups;
    return out;
}
}  // namespace

TEST_CASE("a warm-up by time has safe points; a run resumed inside it equals the whole run",
          "[unit][coarse][run]") {
    // Warm-up 7 in pieces of one burst (2): 2, 4, 6, 7, with a safe point after 2, 4 and 6.
    auto toy = slow_toy();
    ProjectiveRun run(fixed_settings(7.0), toy, variable("x"));
    struct Inside final : ProjectiveRunObserver {
        const test::LinearToyStepper* stepper = nullptr;
        std::vector<double> done;  ///< warmup_done at each safe point inside the warm-up
        std::optional<test::LinearToyStepper> copy;
        std::optional<ProjectiveRunState> state;
        void between_steps(const ProjectiveRun& r) override {
            if (r.state().warmed_up || r.state().warmup_done == 0) return;
            done.push_back(r.state().warmup_done);
            if (r.state().warmup_done == 4.0) {
                copy.emplace(*stepper);
                state = r.state();
            }
        }
    } seen;
    seen.stepper = &toy;
    run.add_observer(seen);
    const ProjectiveRunOutcome whole = run.run(100.0);
    CHECK(seen.done == std::vector<double>{2.0, 4.0, 6.0});
    REQUIRE(seen.copy);
    CHECK(seen.copy->time() == 4.0);
    ProjectiveRun resumed(fixed_settings(7.0), *seen.copy, variable("x"));
    Recorder<test::LinearToyStepper> again;
    again.stepper = &*seen.copy;
    resumed.add_observer(again);
    const ProjectiveRunOutcome rest = resumed.run(100.0, seen.state);
    CHECK(again.warmups == 1);  // the rest of the warm-up, then the steps
    CHECK(rest.coarse_steps == whole.coarse_steps);
    CHECK(seen.copy->time() == toy.time());
    CHECK(seen.copy->state() == toy.state());  // bit for bit
}

TEST_CASE("a resumed run equals the uninterrupted one bit for bit", "[unit][coarse][run]") {
    const ResumedPair r = run_and_resume(4);
    CHECK(r.kept->coarse_steps == 4);
    CHECK(r.kept->t_origin == 0.0);
    CHECK(r.warmups_resumed == 0);  // no second warm-up
    CHECK(r.rest.coarse_steps == r.whole.coarse_steps);
    CHECK(r.rest.end_status == r.whole.end_status);
    CHECK(r.end_rest.time() == r.end_whole.time());
    CHECK(r.end_rest.state() == r.end_whole.state());
}

TEST_CASE("a run resumed from before its warm-up does the warm-up and equals the uninterrupted one",
          "[unit][coarse][run]") {
    // The state kept before the warm-up is where a run stopped during its warm-up goes back to.
    const ResumedPair r = run_and_resume(0);
    CHECK_FALSE(r.kept->warmed_up);
    CHECK(r.warmed_up_at_end);
    CHECK(r.warmups_resumed == 1);
    CHECK(r.rest.coarse_steps == r.whole.coarse_steps);
    CHECK(r.end_rest.time() == r.end_whole.time());
    CHECK(r.end_rest.state() == r.end_whole.state());
}

TEST_CASE("CpiSettings reads the cpi keys into the integrators' settings", "[unit][coarse][run]") {
    ParamTable table = ParamTable::from_text(
        "cpi.projection = periods\ncpi.healing = 4\ncpi.window = 6\ncpi.periods = 3\ncpi.stability "
        "= halve\n",
        "scene.cfg", "/scenes");
    const CpiSettings s = CpiSettings::from_params(table.root().scope("cpi"), 0.5);
    CHECK(s.projection == CpiSettings::Projection::periods);
    CHECK(s.periods.burst.healing == 4.0);
    CHECK(s.periods.burst.window == 6.0);
    CHECK(s.periods.periods_per_step == 3);
    CHECK(s.periods.extension_step == 5.0);  // 5 time units on the 0.5 sample grid
    CHECK(s.fixed.dt == 80.0);               // read for both projections
    CHECK(s.fixed.burst.stability == StabilityPolicy::halve_step);
    CHECK(s.burst() == 10.0);
    CHECK(s.make_integrator({})->name() == "period_projective_euler");

    ParamTable bad = ParamTable::from_text("cpi.window = 1\n", "scene.cfg", "/scenes");
    const std::string e =
        test::input_error([&] { CpiSettings::from_params(bad.root().scope("cpi"), 0.5); }).what();
    CHECK_THAT(e, Catch::Contains("scene.cfg:1") && Catch::Contains("cpi.window") &&
                      Catch::Contains("holds 2 samples; a slope needs at least 3"));
}

TEST_CASE("CpiSettings reads the adaptive keys and refuses what adaptive would ignore",
          "[unit][coarse][run]") {
    ParamTable table = ParamTable::from_text(
        "cpi.projection = adaptive\ncpi.integrator = adams_bashforth2\ncpi.healing = 4\ncpi.window "
        "= 6\n"
        "cpi.tolerance = 0.05\ncpi.dt_max = 60\n",
        "scene.cfg", "/scenes");
    const CpiSettings s = CpiSettings::from_params(table.root().scope("cpi"), 0.5);
    CHECK(s.projection == CpiSettings::Projection::adaptive);
    CHECK(s.multistep.adaptive);
    CHECK(s.multistep.steps == 2);
    CHECK(s.multistep.control.tolerance == 0.05);
    CHECK(s.multistep.control.dt_min == 5.0);  // default: half a burst
    CHECK(s.multistep.control.dt_max == 60.0);
    CHECK(s.multistep.dt_quantum == 0.5);
    CHECK(std::isnan(s.multistep.first_dt));
    CHECK(s.make_integrator({})->name() == "adaptive_adams_bashforth2");

    // Fixed DT with Adams-Bashforth 2: the multistep integrator without the controller.
    ParamTable ab2 = ParamTable::from_text("cpi.integrator = adams_bashforth2\ncpi.dt = 40\n",
                                           "scene.cfg", "/scenes");
    const CpiSettings f = CpiSettings::from_params(ab2.root().scope("cpi"), 0.5);
    CHECK(!f.multistep.adaptive);
    CHECK(f.multistep.dt == 40.0);
    CHECK(f.make_integrator({})->name() == "projective_adams_bashforth2");

    // Each message names the key, the file and line, and what is allowed.
    CHECK_THAT(cpi_refusal("cpi.projection = adaptive\ncpi.tolerance = 0\n"),
               Catch::Contains("scene.cfg:2") && Catch::Contains("cpi.tolerance"));
    CHECK_THAT(cpi_refusal("cpi.projection = adaptive\ncpi.tolerance = -1\n"),
               Catch::Contains("cpi.tolerance"));
    CHECK_THAT(cpi_refusal("cpi.projection = adaptive\n"),
               Catch::Contains("cpi.tolerance"));  // required
    CHECK_THAT(
        cpi_refusal(
            "cpi.projection = adaptive\ncpi.tolerance = 0.1\ncpi.dt_min = 50\ncpi.dt_max = 20\n"),
        Catch::Contains("scene.cfg:3") && Catch::Contains("cpi.dt_min") &&
            Catch::Contains("cpi.dt_max = 20"));
    CHECK_THAT(cpi_refusal("cpi.projection = adaptive\ncpi.tolerance = 0.1\ncpi.periods = 2\n"),
               Catch::Contains("scene.cfg:3") && Catch::Contains("cpi.periods") &&
                   Catch::Contains("not read with cpi.projection = adaptive"));
    CHECK_THAT(cpi_refusal("cpi.projection = adaptive\ncpi.tolerance = 0.1\ncpi.dt = 500\n"),
               Catch::Contains("cpi.dt") && Catch::Contains("caps the first jump"));
    CHECK_THAT(
        cpi_refusal("cpi.projection = fixed\ncpi.tolerance = 0.1\n"),
        Catch::Contains("cpi.tolerance") && Catch::Contains("only with cpi.projection = adaptive"));
    CHECK_THAT(cpi_refusal("cpi.projection = periods\ncpi.integrator = adams_bashforth2\n"),
               Catch::Contains("cpi.integrator") && Catch::Contains("periods"));
    CHECK_THAT(cpi_refusal("cpi.projection = adaptive\ncpi.tolerance = 0.1\ncpi.dt_min = 0.3\n"),
               Catch::Contains("cpi.dt_min"));  // not a whole multiple of the sampling interval
    // cpi.window_auto: adaptive only; its bounds: 4 samples to cpi.window_max (default 4 bursts).
    CHECK_THAT(cpi_refusal("cpi.projection = fixed\ncpi.window_auto = true\n"),
               Catch::Contains("cpi.window_auto") &&
                   Catch::Contains("only with cpi.projection = adaptive"));
    CHECK_THAT(cpi_refusal("cpi.projection = adaptive\ncpi.tolerance = 0.1\ncpi.window_auto = "
                           "true\ncpi.window_max = 5\n"),
               Catch::Contains("cpi.window") && Catch::Contains("cpi.window_max = 5"));
    CHECK_THAT(cpi_refusal("cpi.projection = adaptive\ncpi.tolerance = 0.1\ncpi.window_max = 1\n"),
               Catch::Contains("scene.cfg:3") && Catch::Contains("cpi.window_max"));  // < 4 samples
    ParamTable w = ParamTable::from_text(
        "cpi.projection = adaptive\ncpi.tolerance = 0.1\ncpi.window_auto = true\n", "scene.cfg",
        "/scenes");
    const CpiSettings a = CpiSettings::from_params(w.root().scope("cpi"), 0.5);
    CHECK(a.multistep.window_auto);
    CHECK(a.multistep.window_min == 2.0);   // 4 samples of 0.5
    CHECK(a.multistep.window_max == 80.0);  // 4 bursts of 10 + 10
    // cpi.accuracy instead of cpi.tolerance: not both, positive, adaptive only; the warm-up then
    // runs by time unless asked otherwise, and no drift is judged before the noise is measured.
    CHECK_THAT(cpi_refusal("cpi.projection = adaptive\ncpi.tolerance = 0.1\ncpi.accuracy = 1\n"),
               Catch::Contains("scene.cfg:3") && Catch::Contains("cpi.accuracy") &&
                   Catch::Contains("cpi.tolerance") && Catch::Contains("one of them"));
    CHECK_THAT(cpi_refusal("cpi.projection = adaptive\ncpi.accuracy = 0\n"),
               Catch::Contains("scene.cfg:2") && Catch::Contains("cpi.accuracy"));
    CHECK_THAT(
        cpi_refusal("cpi.projection = fixed\ncpi.accuracy = 1\n"),
        Catch::Contains("cpi.accuracy") && Catch::Contains("only with cpi.projection = adaptive"));
    ParamTable acc = ParamTable::from_text("cpi.projection = adaptive\ncpi.accuracy = 1.5\n",
                                           "scene.cfg", "/scenes");
    const CpiSettings b = CpiSettings::from_params(acc.root().scope("cpi"), 0.5);
    CHECK(b.multistep.accuracy == 1.5);
    CHECK(!b.warmup_until_steady);
    CHECK(std::isinf(b.multistep.drift_rate));
    CHECK(b.make_integrator({})->name() == "adaptive_forward_euler");
    // On the command line, either replaces the scene's other.
    ParamTable over = ParamTable::from_text("cpi.projection = adaptive\ncpi.tolerance = 0.1\n",
                                            "scene.cfg", "/scenes");
    over.add_override("cpi.accuracy=2");
    CHECK(CpiSettings::from_params(over.root().scope("cpi"), 0.5).multistep.accuracy == 2.0);
    ParamTable back = ParamTable::from_text("cpi.projection = adaptive\ncpi.accuracy = 2\n",
                                            "scene.cfg", "/scenes");
    back.add_override("cpi.tolerance=0.2");
    const CpiSettings t = CpiSettings::from_params(back.root().scope("cpi"), 0.5);
    CHECK(std::isnan(t.multistep.accuracy));
    CHECK(t.multistep.control.tolerance == 0.2);
}

TEST_CASE("the warm-up of an adaptive run ends when the phase signal stops drifting",
          "[unit][coarse][run]") {
    // Component 0 (the phase signal) relaxes fast, X0 = 3 e^(-0.5 t); the others slowly. The
    // allowed drift is tolerance / burst = 0.05 / 6: the exact drift 1.5 e^(-0.5 t) falls below it
    // at t = 10.4 (2 s.e. of 8 members' slopes with sigma = 0.005 is ~1e-3, smaller). The
    // warm-up goes on in windows of 4 after cpi.warmup = 1, so it ends in [10.4, 14.4 + one
    // window of noise]; a warm-up by time ends at 1.
    Eigen::VectorXd k = Eigen::VectorXd::Constant(5, 0.005);
    k[0] = 0.5;
    struct WarmupTime final : ProjectiveRunObserver {
        const CoarseStepper* stepper = nullptr;
        double t = -1;
        void warmup_done(const ProjectiveRun&) override { t = stepper->time(); }
    };
    for (const std::string until : {"steady", "time"}) {
        ParamTable table = ParamTable::from_text(
            "cpi.projection = adaptive\ncpi.tolerance = 0.05\ncpi.healing = 2\n"
            "cpi.window = 4\ncpi.warmup = 1\ncpi.warmup_until = " +
                until + "\n",
            "scene.cfg", "/scenes");
        const CpiSettings s = CpiSettings::from_params(table.root().scope("cpi"), 0.1);
        test::OuEnsembleStepper toy(k, 0.005, 8, 0.1, Eigen::VectorXd::Constant(5, 3.0), 2);
        ProjectiveRun run(s, toy, variable("ou"));
        WarmupTime w;
        w.stepper = &toy;
        run.add_observer(w);
        run.run(60.0);
        if (until == "steady") {
            CHECK(w.t >= 10.4);
            CHECK(w.t <= 18.4);
        } else {
            CHECK(w.t == Approx(1.0));
        }
    }
}

TEST_CASE("a warm-up until steady has safe points; a run resumed inside it equals the whole run",
          "[unit][coarse][run]") {
    // The toy of the test above with cpi.warmup = 7 and bursts of 6: pieces 0-6 and 6-7 (a safe
    // point at 6), then the drift test at 7 finds the transient (exact drift 1.5 e^-3.5 = 0.045
    // per time unit against 0.05 / 6 allowed): a safe point at 7 before the next window. A run
    // resumed there must judge the drift from the same samples (the tail of the last burst
    // length, kept in the state) and so end its warm-up, and the whole run, as the uninterrupted
    // one, bit for bit.
    Eigen::VectorXd k = Eigen::VectorXd::Constant(5, 0.005);
    k[0] = 0.5;
    ParamTable table = ParamTable::from_text(
        "cpi.projection = adaptive\ncpi.tolerance = 0.05\ncpi.healing = 2\n"
        "cpi.window = 4\ncpi.warmup = 7\ncpi.warmup_until = steady\n",
        "scene.cfg", "/scenes");
    const CpiSettings s = CpiSettings::from_params(table.root().scope("cpi"), 0.1);
    struct Inside final : ProjectiveRunObserver {
        const test::OuEnsembleStepper* stepper = nullptr;
        std::vector<double> done;  ///< warmup_done at each safe point inside the warm-up
        std::optional<test::OuEnsembleStepper> copy;
        std::optional<ProjectiveRunState> state;
        double warmed_at = -1;
        void between_steps(const ProjectiveRun& r) override {
            if (r.state().warmed_up || r.state().warmup_done == 0) return;
            done.push_back(r.state().warmup_done);
            if (std::abs(r.state().warmup_done - 7.0) < 1e-9) {
                copy.emplace(*stepper);
                state = r.state();
            }
        }
        void warmup_done(const ProjectiveRun&) override { warmed_at = stepper->time(); }
    };
    test::OuEnsembleStepper toy(k, 0.005, 8, 0.1, Eigen::VectorXd::Constant(5, 3.0), 2);
    ProjectiveRun run(s, toy, variable("ou"));
    Inside seen;
    seen.stepper = &toy;
    run.add_observer(seen);
    const ProjectiveRunOutcome whole = run.run(60.0);
    REQUIRE(seen.done.size() >= 2);
    CHECK(seen.done[0] == Approx(6.0));
    CHECK(seen.done[1] == Approx(7.0));
    REQUIRE(seen.state);
    // The samples of the last burst length (6 time units at 0.1: 1.0 < t <= 7.0, and t = 1.0
    // itself within the time tolerance), with one phase signal per member.
    CHECK(seen.state->warmup_tail.t.size() == 61);
    CHECK(seen.state->warmup_tail.member_phase.size() == 61);
    CHECK(seen.warmed_at > 7.0);  // the warm-up went on after the safe point

    const auto resume = [&](ProjectiveRunState state) {
        test::OuEnsembleStepper copy = *seen.copy;
        ProjectiveRun resumed(s, copy, variable("ou"));
        Inside again;
        again.stepper = &copy;
        resumed.add_observer(again);
        const ProjectiveRunOutcome rest = resumed.run(60.0, state);
        return std::tuple{rest, again.warmed_at, copy};
    };
    const auto [rest, warmed_at, end] = resume(*seen.state);
    CHECK(warmed_at == seen.warmed_at);
    CHECK(rest.coarse_steps == whole.coarse_steps);
    CHECK(end.time() == toy.time());
    CHECK(end.mean() == toy.mean());  // bit for bit
    // Without the kept samples the drift test at 7 has none to read: the warm-up would end
    // there, and the run would differ.
    ProjectiveRunState bare = *seen.state;
    bare.warmup_tail = {};
    CHECK(std::get<1>(resume(bare)) != seen.warmed_at);
}

TEST_CASE("a burst that ends the run up to round-off leaves no jump", "[unit][coarse][run]") {
    // Seen before: the last burst of 16 time units ended at 16 - 3.5e-12 and the jump
    // "DT = 3.5e-12" was projected and lifted. Within the time tolerance nothing is left.
    CHECK(end_of_run_jump_limit(16.0 - 3.5e-12, 16.0, 1.5, 1.5) == 0.0);
    CHECK(end_of_run_jump_limit(14.0, 16.0, 1.5, 1.5) ==
          Approx(0.5));  // shortened to leave a burst
    CHECK(end_of_run_jump_limit(13.0, 16.0, 3.0, 1.5) == Approx(3.0));  // the jump ends the run
    CHECK(end_of_run_jump_limit(12.0, 16.0, 3.0, 1.5) ==
          Approx(2.5));  // leaves room for a last burst
}

TEST_CASE("a direct run reads the cpi block without checking it against the sampling grid",
          "[unit][coarse][run]") {
    // LAMMPS' dt = 1.8e-4 makes observe.interval = 0.09: the defaults (healing 10, window 10)
    // are not multiples of it. A cpi run refuses that, naming the key; a direct run does not use
    // them and must not.
    ParamTable table = ParamTable::from_text("cpi.projection = adaptive\n", "scene.cfg", "/scenes");
    CHECK_NOTHROW(CpiSettings::from_params(table.root().scope("cpi"), 0.09, false));
    ParamTable strict = ParamTable::from_text("cpi.tolerance = 0.1\n", "scene.cfg", "/scenes");
    try {
        (void)CpiSettings::from_params(strict.root().scope("cpi"), 0.09, true);
        FAIL("expected an InputError");
    } catch (const InputError& e) {
        CHECK(e.key() == "cpi.healing");
    }
}

TEST_CASE("cpi.finish = steady ends a moving ensemble's run once its pooled slope is noise",
          "[unit][coarse][run]") {
    // Eight OU members relax from 10 to 0 at rate 0.1 with stationary s.d. 0.67: the mean drifts
    // by e^(-0.1 t) per unit time. A burst's slope (window 1, healing 1) has a standard error of
    // ~0.4 per node, so the pool of 4 is steady once the drift is below about 2 x 0.2: after
    // t ~ 10, long before the 400 units of the run. The end state is the fixed point 0 within a
    // few stationary standard errors (0.67 / sqrt(8) = 0.24); without the key the run goes on.
    for (const bool finish : {true, false}) {
        test::OuEnsembleStepper toy(Eigen::VectorXd::Constant(3, 0.1), 0.3, 8, 0.05,
                                    Eigen::VectorXd::Constant(3, 10.0), 7);
        CpiSettings settings = fixed_settings();
        settings.fixed.dt = 4.0;
        settings.finish_at_end_state = finish;
        settings.finish_on_drift = finish;
        ProjectiveRun run(settings, toy, variable("ou"));
        const ProjectiveRunOutcome out = run.run(400.0);
        INFO(out.end_status);
        if (!finish) {
            CHECK(toy.time() == Approx(400.0).margin(1e-9));
            CHECK(std::isnan(out.end_state_time));
            continue;
        }
        CHECK(out.end_status.find("statistically steady") != std::string::npos);
        CHECK(out.end_state_time > 5.0);  // the drift (>= 0.6 per unit before t = 5) is seen
        CHECK(toy.time() < 150.0);
        CHECK(toy.mean().cwiseAbs().maxCoeff() < 1.0);
    }
}

TEST_CASE("a run resumed with the drift test's pool ends where the uninterrupted one does",
          "[unit][coarse][run]") {
    // The state saved between coarse steps 5 and 6 holds the pool of the bursts so far: resumed
    // from it (on a copy of the toy at that point) the run ends at the same step, time and state,
    // bit for bit. Resumed without the pool it has to fill it again and ends later.
    struct Inside final : ProjectiveRunObserver {
        const test::OuEnsembleStepper* stepper = nullptr;
        std::optional<test::OuEnsembleStepper> copy;
        std::optional<ProjectiveRunState> state;
        void between_steps(const ProjectiveRun& r) override {
            if (r.state().coarse_steps != 5) return;
            copy.emplace(*stepper);
            state = r.state();
        }
    };
    CpiSettings settings = fixed_settings();
    settings.fixed.dt = 4.0;
    settings.finish_at_end_state = true;
    settings.finish_on_drift = true;
    test::OuEnsembleStepper toy(Eigen::VectorXd::Constant(3, 0.1), 0.3, 8, 0.05,
                                Eigen::VectorXd::Constant(3, 10.0), 7);
    ProjectiveRun run(settings, toy, variable("ou"));
    Inside seen;
    seen.stepper = &toy;
    run.add_observer(seen);
    const ProjectiveRunOutcome whole = run.run(400.0);
    REQUIRE(!std::isnan(whole.end_state_time));
    REQUIRE(seen.state);
    REQUIRE_FALSE(seen.state->drift.empty());
    const auto resume = [&](const ProjectiveRunState& state) {
        test::OuEnsembleStepper copy = *seen.copy;
        ProjectiveRun resumed(settings, copy, variable("ou"));
        const ProjectiveRunOutcome rest = resumed.run(400.0, state);
        return std::pair{rest, copy};
    };
    const auto [rest, end] = resume(*seen.state);
    CHECK(rest.end_state_time == whole.end_state_time);
    CHECK(rest.coarse_steps == whole.coarse_steps);
    CHECK(end.time() == toy.time());
    CHECK(end.mean() == toy.mean());  // bit for bit
    ProjectiveRunState bare = *seen.state;
    bare.drift.clear();
    CHECK(resume(bare).first.coarse_steps > whole.coarse_steps);
}

TEST_CASE("cpi.finish = steady ends the run after the coarse step that finds the end state",
          "[unit][coarse][run]") {
    // The toy comes to rest at t = 33 (inside the burst of the fourth cycle, 30-32... 40-42:
    // bursts at 0-2, 10-12, 20-22, 30-32, 40-42): the first sample at rest is t = 40.1, in the
    // fifth coarse step, after which the run ends at 50 (that step's jump) instead of 100; the
    // status names the time of the end state. Without the key the same toy runs to 100.
    for (const bool finish : {true, false}) {
        RestingStepper toy(slow_toy(), 33.0);
        CpiSettings settings = fixed_settings();
        settings.finish_at_end_state = finish;
        ProjectiveRun run(settings, toy, variable("x"));
        const ProjectiveRunOutcome out = run.run(100.0);
        INFO("cpi.finish = " << (finish ? "steady" : "duration"));
        if (finish) {
            CHECK(out.end_state_time == Approx(40.1).margin(1e-9));
            CHECK(out.coarse_steps == 5);
            CHECK(toy.time() == Approx(50.0).margin(1e-9));
            CHECK(out.end_status.rfind("completed (end state at t = 40.1, 40.1 time units", 0) ==
                  0);
        } else {
            CHECK(std::isnan(out.end_state_time));
            CHECK(out.end_status == "completed");
            CHECK(toy.time() == Approx(100.0).margin(1e-9));
        }
    }
    // The key: duration (default) or steady, nothing else.
    const auto read = [](const std::string& value) {
        ParamTable table = ParamTable::from_text("cpi.finish = " + value + "\n", "scene.cfg", "/s");
        return CpiSettings::from_params(table.root().scope("cpi"), 0.5);
    };
    CHECK(read("steady").finish_at_end_state);
    CHECK(read("steady").finish_on_drift);
    CHECK(read("at_rest").finish_at_end_state);
    CHECK_FALSE(read("at_rest").finish_on_drift);  // every realization at rest, nothing else
    CHECK_FALSE(read("duration").finish_at_end_state);
    CHECK_FALSE(read("duration").finish_on_drift);
    CHECK_THAT(test::input_error([&] { read("never"); }).what(),
               Catch::Contains("scene.cfg:1") && Catch::Contains("cpi.finish") &&
                   Catch::Contains("duration") && Catch::Contains("steady"));
}

TEST_CASE("cpi.jump_until: the jumps end there, then bursts of direct simulation to the end",
          "[unit][coarse][run]") {
    // Cycles of 10 (bursts 1 + 1, DT 8) from t = 0: bursts end at 2, 12, 22. With jumps until
    // t = 25 the jump after the burst ending at 22 is shortened to DT = 3, and from t = 25 on every
    // coarse step is a burst without a jump or a lift; the run still ends at 100 exactly (the
    // last burst stretched to it).
    struct Steps final : ProjectiveRunObserver {
        std::vector<ProjectiveStepRecord> records;
        void step_done(const ProjectiveRun&, const ProjectiveStepRecord& rec) override {
            records.push_back(rec);
        }
    };
    auto toy = slow_toy();
    CpiSettings settings = fixed_settings();
    settings.jump_until = 25.0;  // fixed DT with it: the multistep integrator (its controller)
    settings.multistep.burst = settings.fixed.burst;
    settings.multistep.adaptive = false;
    settings.multistep.dt = settings.fixed.dt;
    ProjectiveRun run(settings, toy, variable("x"));
    Steps steps;
    run.add_observer(steps);
    const ProjectiveRunOutcome out = run.run(100.0);
    INFO(out.end_status);
    CHECK(out.end_status == "completed");
    CHECK(toy.time() == Approx(100.0).margin(1e-9));
    CHECK(out.jumps == 3);  // DT 8, 8 and 3
    int shortened = 0;
    for (const ProjectiveStepRecord& r : steps.records)
        if (r.dt > 0.0 && r.controller.limited_by == DtLimit::jump_until) {
            ++shortened;
            CHECK(r.t_end == Approx(22.0).margin(1e-12));
            CHECK(r.dt == Approx(3.0).margin(1e-12));
        }
    CHECK(shortened == 1);
    double last_jump_end = 0.0;
    for (const ProjectiveStepRecord& r : steps.records) {
        if (r.dt > 0.0) last_jump_end = r.t_end + r.dt;
        if (r.t_end > 25.0) {
            CHECK(r.dt == 0.0);
            CHECK(r.status == StepStatus::burst_only);
        }
    }
    CHECK(last_jump_end == Approx(25.0).margin(1e-12));
}

TEST_CASE("cpi.jump_until is read on the sampling grid, and refused where nothing reads it",
          "[unit][coarse][run]") {
    ParamTable table = ParamTable::from_text(
        "cpi.projection = adaptive\ncpi.tolerance = 0.16\ncpi.jump_until = 250\n", "scene.cfg",
        "/scenes");
    const CpiSettings s = CpiSettings::from_params(table.root().scope("cpi"), 0.5);
    CHECK(s.jump_until == 250.0);
    CHECK(std::isinf(CpiSettings{}.jump_until));  // not given: jumps to the end
    ParamTable fixed = ParamTable::from_text("cpi.jump_until = 40\n", "scene.cfg", "/scenes");
    CHECK(CpiSettings::from_params(fixed.root().scope("cpi"), 0.5).make_integrator({})->name() ==
          "projective_forward_euler_multistep");  // fixed DT with the controller's rule
    CHECK_THAT(cpi_refusal("cpi.projection = periods\ncpi.jump_until = 40\n"),
               Catch::Contains("cpi.jump_until") && Catch::Contains("periods"));
    CHECK_THAT(cpi_refusal("cpi.jump_until = 40.25\n"), Catch::Contains("cpi.jump_until"));
    CHECK_THAT(cpi_refusal("cpi.jump_until = -1\n"), Catch::Contains("cpi.jump_until"));
}

TEST_CASE("cpi.slope_fit: the window's increment with fixed or adaptive DT, refused where unread",
          "[unit][coarse][run]") {
    ParamTable fixed =
        ParamTable::from_text("cpi.slope_fit = increment\ncpi.dt = 40\n", "scene.cfg", "/scenes");
    const CpiSettings f = CpiSettings::from_params(fixed.root().scope("cpi"), 0.5);
    CHECK(f.multistep.slope_fit == SlopeFit::increment);
    // Fixed DT with the increment: the multistep integrator (the plain one fits least squares).
    CHECK(f.make_integrator({})->name() == "projective_forward_euler_multistep");
    ParamTable plain = ParamTable::from_text("cpi.dt = 40\n", "scene.cfg", "/scenes");
    CHECK(CpiSettings::from_params(plain.root().scope("cpi"), 0.5).multistep.slope_fit ==
          SlopeFit::least_squares);
    CHECK_THAT(cpi_refusal("cpi.slope_fit = increments\n"),
               Catch::Contains("scene.cfg:1") && Catch::Contains("cpi.slope_fit") &&
                   Catch::Contains("least_squares") && Catch::Contains("increment"));
    CHECK_THAT(cpi_refusal("cpi.projection = periods\ncpi.slope_fit = increment\n"),
               Catch::Contains("scene.cfg:2") && Catch::Contains("cpi.slope_fit") &&
                   Catch::Contains("periods"));
    CHECK_THAT(cpi_refusal("cpi.projection = adaptive\ncpi.tolerance = 0.1\ncpi.slope_fit = "
                           "increment\ncpi.window_auto = true\n"),
               Catch::Contains("scene.cfg:4") && Catch::Contains("cpi.window_auto") &&
                   Catch::Contains("increment"));
}

TEST_CASE(
    "cpi.curvature: a pooled curvature with forward Euler and the bursts' own slopes, "
    "refused where it cannot act",
    "[unit][coarse][run]") {
    ParamTable fixed =
        ParamTable::from_text("cpi.curvature = pooled\ncpi.dt = 40\n", "scene.cfg", "/scenes");
    const CpiSettings f = CpiSettings::from_params(fixed.root().scope("cpi"), 0.5);
    CHECK(f.multistep.pooled_curvature);
    // Fixed DT with a curvature: the multistep integrator (the plain one has no pool).
    CHECK(f.make_integrator({})->name() == "projective_forward_euler_multistep");
    ParamTable plain = ParamTable::from_text("cpi.dt = 40\n", "scene.cfg", "/scenes");
    CHECK_FALSE(
        CpiSettings::from_params(plain.root().scope("cpi"), 0.5).multistep.pooled_curvature);
    CHECK_THAT(cpi_refusal("cpi.curvature = fitted\n"),
               Catch::Contains("scene.cfg:1") && Catch::Contains("cpi.curvature") &&
                   Catch::Contains("none") && Catch::Contains("pooled"));
    CHECK_THAT(cpi_refusal("cpi.projection = periods\ncpi.curvature = pooled\n"),
               Catch::Contains("scene.cfg:2") && Catch::Contains("cpi.curvature") &&
                   Catch::Contains("periods"));
    CHECK_THAT(cpi_refusal("cpi.integrator = adams_bashforth2\ncpi.curvature = pooled\n"),
               Catch::Contains("scene.cfg:2") && Catch::Contains("cpi.curvature") &&
                   Catch::Contains("adams_bashforth2"));
    CHECK_THAT(cpi_refusal("cpi.slope = pooled\ncpi.curvature = pooled\n"),
               Catch::Contains("scene.cfg:2") && Catch::Contains("cpi.curvature") &&
                   Catch::Contains("cpi.slope = pooled"));
    // Two slopes are Adams-Bashforth 2's line, not a pool.
    CHECK_THAT(cpi_refusal("cpi.curvature = pooled\ncpi.pool = 2\n"),
               Catch::Contains("scene.cfg:2") && Catch::Contains("cpi.pool") &&
                   Catch::Contains("at least 3"));
}

TEST_CASE(
    "cpi.noisy_curvature = pooled: forward Euler with the bursts' own slopes and no added "
    "curvature, refused elsewhere",
    "[unit][coarse][run]") {
    const std::string adaptive = "cpi.projection = adaptive\ncpi.tolerance = 0.1\n";
    using Mode = MultistepSettings::NoisyCurvature;
    const auto mode = [](const std::string& text) {
        ParamTable t = ParamTable::from_text(text, "scene.cfg", "/scenes");
        return CpiSettings::from_params(t.root().scope("cpi"), 0.5).multistep.noisy_curvature;
    };
    CHECK(mode(adaptive) == Mode::ignored);
    CHECK(mode(adaptive + "cpi.noisy_curvature = counted\n") == Mode::counted);
    CHECK(mode(adaptive + "cpi.noisy_curvature = pooled\n") == Mode::pooled);
    CHECK_THAT(cpi_refusal(adaptive + "cpi.noisy_curvature = fitted\n"),
               Catch::Contains("scene.cfg:3") && Catch::Contains("cpi.noisy_curvature") &&
                   Catch::Contains("pooled"));
    CHECK_THAT(cpi_refusal(adaptive + "cpi.integrator = adams_bashforth2\n"
                                      "cpi.noisy_curvature = pooled\n"),
               Catch::Contains("scene.cfg:4") && Catch::Contains("cpi.noisy_curvature") &&
                   Catch::Contains("adams_bashforth2"));
    CHECK_THAT(cpi_refusal(adaptive + "cpi.curvature = pooled\ncpi.noisy_curvature = pooled\n"),
               Catch::Contains("scene.cfg:4") && Catch::Contains("cpi.noisy_curvature") &&
                   Catch::Contains("cpi.curvature = pooled"));
    CHECK_THAT(cpi_refusal(adaptive + "cpi.slope = pooled\ncpi.noisy_curvature = pooled\n"),
               Catch::Contains("scene.cfg:4") && Catch::Contains("cpi.noisy_curvature") &&
                   Catch::Contains("cpi.slope = pooled"));
    CHECK_THAT(cpi_refusal(adaptive + "cpi.pool = 1\ncpi.noisy_curvature = pooled\n"),
               Catch::Contains("scene.cfg:3") && Catch::Contains("cpi.pool") &&
                   Catch::Contains("at least 2"));
}
