// cpi.healing_auto: the post-lift transient test (estimators/post_lift_transient.hpp) finds a
// fast mode a lift leaves behind and does not find one where there is none, and the multistep
// integrator heals for cpi.healing only while bursts after a lift show one.
#include <catch2/catch.hpp>

#include <cmath>

#include <Eigen/Core>

#include "coarse/equation_free/estimators/post_lift_transient.hpp"
#include "coarse/equation_free/projective/multistep_projective_integrator.hpp"
#include "tests/coarse/toy_steppers.hpp"

using namespace efdem;
using namespace efdem::coarse;

namespace {

/// 19 OU components: 0-9 slow (k = 1e-4), 10-18 fast (k = 1, relaxing to 0 within ~3 time
/// units). A lift sets every member to the target plus `kick` on the fast components: kick 0
/// leaves them where the slow dynamics has them (near 0), kick 1 starts a fast relaxation that
/// a burst's first half shows and its second half does not.
class KickedOu final : public test::OuEnsembleView {
  public:
    KickedOu(double kick, std::uint64_t seed)
        : OuEnsembleView(
              test::OuEnsembleStepper(rates(), 0.05, 4, 0.1, Eigen::VectorXd::Zero(19), seed)),
          kick_(kick) {}
    static Eigen::VectorXd rates() {
        Eigen::VectorXd k = Eigen::VectorXd::Constant(19, 1e-4);
        k.tail(9).setConstant(1.0);
        return k;
    }
    void lift(const Eigen::VectorXd& target, double new_time) override {
        Eigen::VectorXd x = target;
        x.tail(9).array() += kick_;
        toy_.lift(x, new_time);
    }

  private:
    double kick_;
};

/// Share of `n` lifted bursts of length 10 in which the transient test finds a transient.
double resolved_share(double kick, int n) {
    KickedOu toy(kick, 11);
    int resolved = 0;
    for (int b = 0; b < n; ++b) {
        const double t_lift = toy.time();
        toy.lift(Eigen::VectorXd::Constant(19, 0.0), t_lift);
        BurstSamples s;
        toy.run(10.0, s);
        const MeanSignificance e = post_lift_transient(s.t, s.members, t_lift);
        REQUIRE(e.measured);
        resolved += e.resolved;
    }
    return static_cast<double>(resolved) / n;
}

}  // namespace

TEST_CASE("the post-lift transient test finds a fast mode the lift left, and none where none is",
          "[unit][coarse][healing]") {
    // Kick 1 on 9 fast components (decay e^-t): the early half's mean residual is ~0.2 against a
    // standard error of ~0.02 from 4 members: found every time. No kick: noise alone, found
    // only by chance (threshold three standard deviations above 1, mean_significance.hpp): at
    // most 8 % of 100 bursts.
    CHECK(resolved_share(1.0, 20) == 1.0);
    const double noise = resolved_share(0.0, 100);
    INFO("no transient, resolved in " << noise);
    CHECK(noise < 0.08);
}

TEST_CASE("cpi.healing_auto heals for cpi.healing only while bursts after a lift show a transient",
          "[unit][coarse][healing]") {
    for (const double kick : {0.0, 1.0}) {
        INFO("kick " << kick);
        KickedOu toy(kick, 3);
        MultistepSettings s;
        s.burst.healing = 5.0;
        s.burst.window = 5.0;
        s.healing_auto = true;
        s.healing_min = 1.0;
        s.control = {.tolerance = 0.05, .dt_min = 2.0, .dt_max = 20.0};
        MultistepProjectiveIntegrator integrator(s);
        integrator.set_end_time(200.0);
        int lifted = 0, short_healing = 0, tested = 0;
        while (200.0 - toy.time() >= 10.0 - 1e-9) {
            const ProjectiveStepRecord r = integrator.step(toy);
            REQUIRE(r.advanced());
            // The burst after a jump keeps its length (a direct burst may run to the run's end).
            if (r.lifted) CHECK(r.burst_length == Approx(10.0));
            if (r.healing < 5.0) {
                ++short_healing;
                CHECK(r.healing == 1.0);
            }
            if (r.lifted) {
                ++lifted;
                tested += std::isfinite(r.controller.transient);
            }
        }
        REQUIRE(lifted >= 5);
        CHECK(tested == lifted);  // every burst after a lift is tested
        INFO(short_healing << " short healings in " << lifted << " lifts");
        if (kick == 0.0) {
            CHECK(short_healing >= lifted - 2);  // no transient: short healings after the first
        } else {
            CHECK(short_healing == 0);  // every lift leaves a transient: always the full healing
        }
        const IntegratorState saved = integrator.save_state();
        CHECK(saved->healing == (kick == 0.0 ? 1.0 : 5.0));
    }
}
