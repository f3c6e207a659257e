// MultistepState: the multistep integrator's state by name, read from the positional layouts of
// checkpoint formats 2 and 3 (from_layout), and compared field by field. The stored checkpoint
// files of every format are tested end to end by tests/scripts/checkpoint_formats.sh.
#include <catch2/catch.hpp>

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "coarse/equation_free/projective/multistep_state.hpp"

using namespace efdem::coarse;

namespace {

/// Layout 3 with two slopes of two nodes: every value distinct, so that a value read from the
/// wrong position shows.
std::vector<double> layout3() {
    const double nan = std::numeric_limits<double>::quiet_NaN();
    return {3.0,  2.0,  2.0,               // layout, n, m
            9.0,  nan,  0.75, 1.0,         // t_end, dt_last, dt_cap, rejections in a row
            1.0,  -0.1, 0.9,  1.5,         // decay ok, rate, ratio, delay
            10.0, 11.0,                    // x_end
            4.0,  0.1,  0.2,  0.01, 0.02,  // tau, slope, se
            7.5,  0.3,  0.4,  0.03, 0.04,  // tau, slope, se
            3.0,  1.0,  1.0,  0.0,  1.5,  1.8, 2.2, 2.9, 0.05, 0.01,  // totals
            1.0};                                                     // curvature_only_front
}

}  // namespace

TEST_CASE("a format 2/3 integrator state is read by name", "[unit][coarse][multistep]") {
    const std::string text = "decay message\nin-phase wave\na wave the members share";
    const MultistepState s = MultistepState::from_layout(layout3(), text);
    CHECK(s.t_end == 9.0);
    CHECK(std::isnan(s.controller.dt_last));
    CHECK(s.controller.dt_cap == 0.75);
    CHECK(s.controller.consecutive_rejections == 1);
    CHECK(s.decay.ok);
    CHECK(s.decay.rate == -0.1);
    CHECK(s.decay.ratio == 0.9);
    CHECK(s.decay.delay == 1.5);
    CHECK(s.decay.message == "decay message");
    CHECK(s.hold_kind == DtLimit::in_phase_wave);
    CHECK(s.hold == "a wave the members share");
    REQUIRE(s.x_end.size() == 2);
    CHECK(s.x_end[1] == 11.0);
    REQUIRE(s.history.size() == 2);
    CHECK(s.history[1].tau == 7.5);
    CHECK(s.history[1].slope[0] == 0.3);
    CHECK(s.history[1].se[1] == 0.04);
    CHECK(s.totals.attempts == 3);
    CHECK(s.totals.rejected == 1);
    CHECK(s.totals.dt_tolerance_4r == 2.9);
    CHECK(s.totals.truncation == 0.01);
    CHECK(s.curvature_only_front);

    // Layout 2: the same without the last value (no curvature-only node).
    std::vector<double> two = layout3();
    two[0] = 2.0;
    two.pop_back();
    const MultistepState t = MultistepState::from_layout(two, text);
    CHECK(!t.curvature_only_front);
    CHECK(t.history.size() == 2);

    // Field by field: NaN (dt_last before the first kept jump) is never equal, as in the vector
    // of doubles the test of a resumed run compared before.
    MultistepState u = s;
    CHECK(!(u == s));
    u.controller.dt_last = 1.0;
    MultistepState v = u;
    CHECK(u == v);
    v.history[0].se[0] = 0.5;
    CHECK(!(u == v));
}

TEST_CASE("a malformed format 2/3 integrator state is refused", "[unit][coarse][multistep]") {
    const std::string text = "\n\n";
    std::vector<double> r = layout3();
    r.pop_back();  // layout 3 one value short
    CHECK_THROWS_AS(MultistepState::from_layout(r, text), std::invalid_argument);
    r = layout3();
    r[0] = 5.0;
    CHECK_THROWS_AS(MultistepState::from_layout(r, text), std::invalid_argument);
    CHECK_THROWS_AS(MultistepState::from_layout(layout3(), "one line"), std::invalid_argument);
    CHECK_THROWS_AS(MultistepState::from_layout(layout3(), "\nsomething else\n"),
                    std::invalid_argument);
}
