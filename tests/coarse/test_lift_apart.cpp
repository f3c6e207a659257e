// cpi.lift = own (MultistepSettings::lift_apart): an ensemble whose members relax to different
// end states at different rates, the toy of a bed whose realizations stop demixing one after
// another (issue 34). Lifting every member to the mean, or moving all by the same increment,
// drags a member that has stopped along with the others; moving each by its own slope's jump
// keeps it where it stopped, and the members' mean follows the exact one.
#include <catch2/catch.hpp>

#include <cmath>
#include <optional>
#include <vector>

#include <Eigen/Core>

#include "coarse/equation_free/coarse_stepper.hpp"
#include "coarse/equation_free/projective/multistep_projective_integrator.hpp"
#include "tests/coarse/fixed_schedule.hpp"

using namespace efdem::coarse;

namespace {

/// Member r relaxes to its own end state, dx_r/dt = k_r (c_r - x_r) (one coarse component),
/// advanced exactly over each sampling interval h. The samples carry the members. lift() sets
/// every member to the target; lift_apart() moves member r to x_r + (target - mean x) +
/// (step_r - mean step), what EnsembleLifting does.
class RelaxingMembers final : public CoarseStepper {
  public:
    RelaxingMembers(Eigen::VectorXd ends, Eigen::VectorXd rates, double h)
        : c_(std::move(ends)), k_(std::move(rates)), h_(h), x_(Eigen::VectorXd::Zero(c_.size())) {}

    double time() const override { return t_; }
    void run(double duration, BurstSamples& out) override {
        const long n = std::lround(duration / h_);
        const double t0 = t_;
        const Eigen::ArrayXd decay = (-k_.array() * h_).exp();
        for (long i = 1; i <= n; ++i) {
            x_ = (c_.array() + (x_ - c_).array() * decay).matrix();
            t_ = t0 + static_cast<double>(i) * h_;
            out.t.push_back(t_);
            out.x.push_back(Eigen::VectorXd::Constant(1, x_.mean()));
            out.members.push_back(x_);  // R x 1
        }
    }
    void lift(const Eigen::VectorXd& target, double new_time) override {
        x_.setConstant(target[0]);
        t_ = new_time;
    }
    bool lifts_apart() const override { return true; }
    void lift_apart(const Eigen::VectorXd& target, const Eigen::MatrixXd& member_steps,
                    double new_time) override {
        REQUIRE(member_steps.rows() == x_.size());
        REQUIRE(member_steps.cols() == 1);
        const Eigen::VectorXd steps = member_steps.col(0).array() - member_steps.col(0).mean();
        x_ = (x_.array() + (target[0] - x_.mean()) + steps.array()).matrix();
        t_ = new_time;
        ++apart;
    }
    /// The members' mean of the exact flow from x = 0 at t = 0.
    double exact_mean(double t) const {
        return (c_.array() * (1.0 - (-k_.array() * t).exp())).mean();
    }
    double mean() const { return x_.mean(); }
    int apart = 0;

  private:
    Eigen::VectorXd c_, k_;
    double h_;
    Eigen::VectorXd x_;
    double t_ = 0.0;
};

/// Fixed DT = 10 with bursts of 1 + 4 (8 samples of 0.5 in the window): k DT <= 1, so forward
/// Euler is stable and accurate for every member.
/// `recorded`: the jumps whose record says how far they moved the members apart.
double end_mean(bool apart, bool members_alike, RelaxingMembers& toy, double t_end, int& recorded) {
    MultistepSettings s = efdem::test::fixed_schedule(1.0, 4.0, 10.0);
    s.lift_apart = apart;
    MultistepProjectiveIntegrator integrator(s);
    integrator.set_end_time(t_end);
    // members_alike: cpi.lift = members, every member moved by the common increment (steps 0).
    struct Alike final : CoarseStepper {
        explicit Alike(RelaxingMembers& t) : toy(t) {}
        RelaxingMembers& toy;
        double time() const override { return toy.time(); }
        void run(double d, BurstSamples& out) override { toy.run(d, out); }
        void lift(const Eigen::VectorXd& target, double new_time) override {
            toy.lift_apart(target, Eigen::MatrixXd::Zero(4, 1), new_time);
        }
    } alike(toy);
    CoarseStepper& stepper = members_alike ? static_cast<CoarseStepper&>(alike) : toy;
    while (toy.time() < t_end - 1e-9 && t_end - toy.time() >= 5.0 - 1e-9) {
        const ProjectiveStepRecord rec = integrator.step(stepper);
        REQUIRE(rec.advanced());
        if (std::isfinite(rec.controller.member_step)) {
            CHECK(rec.controller.member_step > 0.0);
            ++recorded;
        }
    }
    REQUIRE(toy.time() == Approx(t_end).margin(1e-9));
    return toy.mean();
}

RelaxingMembers four_members() {
    // End states 2, 4, 6, 8 reached at rates 0.1 ... 0.0125: the fast ones stop first.
    return RelaxingMembers((Eigen::VectorXd(4) << 2.0, 4.0, 6.0, 8.0).finished(),
                           (Eigen::VectorXd(4) << 0.1, 0.05, 0.025, 0.0125).finished(), 0.5);
}

}  // namespace

TEST_CASE("cpi.lift = own keeps members that have stopped where they stopped",
          "[unit][coarse][multistep]") {
    const double t_end = 300.0;
    RelaxingMembers own = four_members(), mean = four_members(), alike = four_members();
    const double exact = own.exact_mean(t_end);  // 4.952
    int recorded_own = 0, recorded_mean = 0, recorded_alike = 0;
    const double e_own = end_mean(true, false, own, t_end, recorded_own) - exact;
    const double e_mean = end_mean(false, false, mean, t_end, recorded_mean) - exact;
    const double e_alike = end_mean(false, true, alike, t_end, recorded_alike) - exact;
    INFO("end-mean errors: own " << e_own << ", mean " << e_mean << ", members " << e_alike);
    CHECK(own.apart > 10);  // every jump lifted apart (20 cycles of 15)
    CHECK(mean.apart == 0);
    CHECK(recorded_own == own.apart);  // /cpi/controller/member_step of every jump apart
    CHECK(recorded_mean + recorded_alike == 0);
    // Forward Euler per member (k DT <= 1, cycles of 15): 0.010 computed by a separate script of
    // the same scheme; 0.05 leaves room for the window's placement.
    CHECK(std::abs(e_own) < 0.05);
    // Lifting to the mean makes every member relax from the mean: the ensemble goes to
    // mean(k c)/mean(k) = 3.47 instead of 5 as the lifts repeat (-1.33 at t = 300).
    CHECK(e_mean < -1.0);
    // The same increment for all drags the stopped members up and holds the slow ones back
    // (-0.19): far more than own's error.
    CHECK(std::abs(e_alike) > 4.0 * std::abs(e_own));
    CHECK(std::abs(e_alike) > 0.1);
}
