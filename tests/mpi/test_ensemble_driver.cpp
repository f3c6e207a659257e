// The ensemble driver over MPI, run at 1, 2 and 4 ranks with the same R = 4 realizations:
// gathers and averages equal the serial computation, scatters reach the right realization, and
// a coarse projective run of a linear toy model through EnsembleStepper reproduces the serial
// projective integrator bit for bit, members (each realization's coarse vector) included.
#include <catch2/catch.hpp>

#include <algorithm>
#include <limits>
#include <memory>

#include "coarse/demixing/ensemble_observable.hpp"
#include "coarse/equation_free/projective/projective_forward_euler.hpp"
#include "mpi_driver/ensemble/ensemble_stepper.hpp"
#include "mpi_driver/parallel/ensemble_layout.hpp"
#include "mpi_driver/run/driver.hpp"
#include "tests/mpi/toy_realization.hpp"

using namespace efdem;
using namespace efdem::mpi_driver;

namespace {
constexpr int kRealizations = 4;

int per_rank(const MpiComm& world) {
    REQUIRE(kRealizations % world.size() == 0);  // run at 1, 2 or 4 ranks
    return kRealizations / world.size();
}

/// Realization r's row: a pattern that identifies r.
Eigen::VectorXd row_of(long r, int m) {
    Eigen::VectorXd v(m);
    for (int i = 0; i < m; ++i) v[i] = 100.0 * static_cast<double>(r) + i + 0.25;
    return v;
}
}  // namespace

TEST_CASE("gather_rows orders realizations by global index and averages like a serial loop",
          "[mpi][ensemble]") {
    const MpiComm world(MPI_COMM_WORLD);
    const EnsembleLayout layout(world, per_rank(world));
    std::vector<Eigen::VectorXd> local;
    for (int j = 0; j < layout.per_rank(); ++j)
        local.push_back(row_of(layout.first_index() + j, 5));
    const Eigen::MatrixXd all = layout.gather_rows(local);
    if (!world.is_root()) {
        CHECK(all.size() == 0);
        return;
    }
    REQUIRE(all.rows() == kRealizations);
    Eigen::MatrixXd serial(kRealizations, 5);
    for (int r = 0; r < kRealizations; ++r) serial.row(r) = row_of(r, 5).transpose();
    CHECK(all == serial);
    // The mean is summed in realization order: identical bits for any rank layout.
    const Eigen::VectorXd mean = coarse::ensemble_mean(all);
    Eigen::VectorXd expect = Eigen::VectorXd::Zero(5);
    for (int r = 0; r < kRealizations; ++r) expect += serial.row(r).transpose();
    expect /= kRealizations;
    CHECK(mean == expect);
    const Eigen::VectorXd var = coarse::ensemble_variance(all, mean);
    // Rows differ by 100 per realization: variance of {0,100,200,300} = 16666.67 per node.
    for (int i = 0; i < 5; ++i) CHECK(var[i] == Approx(50000.0 / 3.0).epsilon(1e-14));
}

TEST_CASE("arrays of different lengths are gathered and scattered to the right realization",
          "[mpi][ensemble]") {
    const MpiComm world(MPI_COMM_WORLD);
    const EnsembleLayout layout(world, per_rank(world));
    // Realization r's array: length r % 3 + 2, entries 10 r + i + shift.
    auto array_of = [](long r, int shift = 0) {
        std::vector<std::uint8_t> a;
        for (long i = 0; i < r % 3 + 2; ++i)
            a.push_back(static_cast<std::uint8_t>(10 * r + i + shift));
        return a;
    };
    std::vector<std::vector<std::uint8_t>> local;
    std::vector<std::size_t> lengths;
    for (int j = 0; j < layout.per_rank(); ++j) {
        local.push_back(array_of(layout.first_index() + j));
        lengths.push_back(local.back().size());
    }
    const auto gathered = layout.gather_arrays(local);
    if (world.is_root()) {
        REQUIRE(gathered.size() == kRealizations);
        for (int r = 0; r < kRealizations; ++r) CHECK(gathered[r] == array_of(r));
    }
    // Scatter back a changed version: each realization must receive its own.
    std::vector<std::vector<std::uint8_t>> to_send;
    if (world.is_root())
        for (int r = 0; r < kRealizations; ++r) to_send.push_back(array_of(r, 1));
    const auto mine = layout.scatter_arrays(to_send, lengths);
    REQUIRE(static_cast<int>(mine.size()) == layout.per_rank());
    for (int j = 0; j < layout.per_rank(); ++j)
        CHECK(mine[j] == array_of(layout.first_index() + j, 1));
}

namespace {
// The toy: a fast mode (-20) coupled to a slow one (-0.1), state dimension 3.
Eigen::MatrixXd toy_matrix() {
    Eigen::MatrixXd a(3, 3);
    a << -0.1, 0.0, 0.0, 1.0, -20.0, 0.0, 0.0, 0.5, -0.5;
    return a;
}
Eigen::VectorXd toy_start(long r) {
    return Eigen::Vector3d(1.0 + 0.1 * static_cast<double>(r), 0.0, 0.5);
}
constexpr double kH = 0.01;

/// The serial reference: the same R toy realizations in one process, restricted by the same
/// ensemble mean and lifted by setting every state to the target.
class SerialToyStepper final : public coarse::CoarseStepper {
  public:
    SerialToyStepper() {
        for (long r = 0; r < kRealizations; ++r)
            toys_.emplace_back(r, toy_matrix(), toy_start(r), kH);
    }
    double time() const override { return toys_.front().time(); }
    void run(double duration, coarse::BurstSamples& out) override {
        const long samples = std::lround(duration / (5 * kH));
        for (long s = 0; s < samples; ++s) {
            Eigen::MatrixXd all(kRealizations, 3);
            for (long r = 0; r < kRealizations; ++r) {
                toys_[static_cast<std::size_t>(r)].advance(5);
                all.row(r) = toys_[static_cast<std::size_t>(r)].state().transpose();
            }
            out.t.push_back(time());
            out.x.push_back(coarse::ensemble_mean(all));
            out.phase_signal.push_back(coarse::ensemble_mean(all)[0]);
            out.members.push_back(all);
        }
    }
    void lift(const Eigen::VectorXd& target, double new_time) override {
        for (auto& t : toys_) {
            t.apply_lift({{target.data(), target.data() + 3}, {}});
            t.set_time(new_time);
        }
    }

  private:
    std::vector<test::ToyRealization> toys_;
};

/// The R toy realizations of this rank behind an EnsembleStepper (5 substeps per sample,
/// the toy's state as a 3-node "ICDF", exact lifting); `lift_members`: cpi.lift = members.
struct ToyEnsemble {
    /// `at_rest`: the realizations that are at rest from the start, held by a lift unless
    /// `hold` is false (cpi.at_rest = lift).
    ToyEnsemble(const MpiComm& world, bool lift_members, const std::vector<long>& at_rest = {},
                bool hold = true)
        : layout(world, per_rank(world)),
          stepper(layout, realizations(layout, at_rest),
                  settings(lift_members, hold && !at_rest.empty()), observable, lifter, nullptr,
                  nullptr) {}
    static std::vector<std::unique_ptr<Realization>> realizations(const EnsembleLayout& layout,
                                                                  const std::vector<long>& rest) {
        std::vector<std::unique_ptr<Realization>> local;
        for (int j = 0; j < layout.per_rank(); ++j) {
            const long r = layout.first_index() + j;
            auto toy = std::make_unique<test::ToyRealization>(r, toy_matrix(), toy_start(r), kH);
            toy->set_at_rest(std::find(rest.begin(), rest.end(), r) != rest.end());
            local.push_back(std::move(toy));
        }
        return local;
    }
    static StepperSettings settings(bool lift_members, bool hold_at_rest) {
        StepperSettings ss;
        ss.sample_interval = 5 * kH;
        ss.steps_per_sample = 5;
        ss.quantiles = 3;
        ss.lift_members = lift_members;
        ss.hold_at_rest = hold_at_rest;
        return ss;
    }
    /// The other ranks serve the root's commands until it finishes them; true on the root.
    bool root_or_serve() {
        if (layout.is_root()) return true;
        stepper.serve();
        return false;
    }
    EnsembleLayout layout;
    coarse::IcdfObservable observable{3};
    test::ToyLifter lifter;
    EnsembleStepper stepper;
};
}  // namespace

TEST_CASE("CPI of a linear toy model through EnsembleStepper equals the serial integrator",
          "[mpi][ensemble][cpi]") {
    const MpiComm world(MPI_COMM_WORLD);
    ToyEnsemble toy(world, false);
    EnsembleStepper& stepper = toy.stepper;
    coarse::ProjectiveEulerSettings pfe;
    pfe.burst.healing = 0.5;  // 10 fast time constants
    pfe.burst.window = 0.5;
    pfe.dt = 2.0;
    if (!world.is_root()) {
        stepper.serve();
        return;
    }
    coarse::ProjectiveForwardEuler mpi_cpi(pfe), serial_cpi(pfe);
    SerialToyStepper serial;
    for (int step = 0; step < 5; ++step) {
        const auto a = mpi_cpi.step(stepper);
        const auto b = serial_cpi.step(serial);
        INFO("outer step " << step);
        REQUIRE(a.status == b.status);
        REQUIRE(a.lifted);
        // Bit for bit: the same arithmetic in the same order.
        CHECK(a.t_end == b.t_end);
        CHECK(a.slope == b.slope);
        CHECK(a.x_end == b.x_end);
        CHECK(a.x_projected == b.x_projected);
        CHECK(a.burst.t == b.burst.t);
        // The members arrive in realization order whatever the layout (the serial stepper
        // lists them in that order), and so give the same slope s.e.
        REQUIRE(a.burst.members.size() == a.burst.t.size());
        for (std::size_t k = 0; k < a.burst.t.size(); ++k)
            CHECK(a.burst.members[k] == b.burst.members[k]);
        CHECK(a.slope_standard_error == b.slope_standard_error);
        REQUIRE(a.slope_standard_error.size() == 3);
        if (step == 0) {
            // Before the first lift the realizations differ (x0 = 1 + 0.1 r, decaying alike):
            // row r is realization r, and the slopes spread.
            for (long r = 1; r < kRealizations; ++r)
                CHECK(a.burst.members[0](r, 0) > a.burst.members[0](r - 1, 0));
            CHECK(a.slope_standard_error[0] > 0.0);
        }
    }
    CHECK(stepper.time() == Approx(15.0).margin(1e-9));  // 5 cycles of burst 1 + DT 2
    // And the slow mode was followed: x0 = 1.15 e^(-0.1 t) exactly. Projective forward Euler
    // over a cycle gives about e^(-0.1) (1 - 0.2) instead of e^(-0.3), 2.3 % low per cycle.
    coarse::BurstSamples last;
    stepper.run(5 * kH, last);
    stepper.finish();
    const double exact = 1.15 * std::exp(-0.1 * last.t.back());
    CHECK(last.x.back()[0] == Approx(exact).epsilon(0.15));
}

TEST_CASE("cpi.lift = members moves every realization by the same increment, keeping its offset",
          "[mpi][ensemble][cpi]") {
    // Four toy realizations that start apart (x0 = 1 + 0.1 r): after a lift to X*, realization r
    // is at X_r + (X* - mean X_r), so the mean is X* and the spread of a direct ensemble stays;
    // the next sample (5 Euler substeps of the toy from there) is reproduced here exactly.
    const MpiComm world(MPI_COMM_WORLD);
    ToyEnsemble toy(world, true);
    if (!toy.root_or_serve()) return;
    EnsembleStepper& stepper = toy.stepper;
    coarse::BurstSamples before, after;
    stepper.run(0.5, before);
    const Eigen::MatrixXd own = before.members.back();  // R x 3, the states now
    const Eigen::Vector3d target(2.0, 0.3, 0.7);
    stepper.lift(target, stepper.time() + 1.0);
    stepper.run(5 * kH, after);
    stepper.finish();
    const Eigen::VectorXd increment = target - coarse::ensemble_mean(own);
    const Eigen::MatrixXd a = toy_matrix();
    REQUIRE(after.members.size() == 1);
    for (int r = 0; r < kRealizations; ++r) {
        Eigen::VectorXd y = own.row(r).transpose() + increment;
        for (int k = 0; k < 5; ++k) y += kH * (a * y);
        CHECK((after.members[0].row(r).transpose() - y).cwiseAbs().maxCoeff() < 1e-14);
    }
    // The spread is the one before the lift, advanced alike (a linear model moves differences
    // exactly as states): realization 3 stays 0.3 above realization 0 in component 0, decayed.
    const double gap = own(3, 0) - own(0, 0);
    CHECK(gap > 0.25);
    CHECK(after.members[0](3, 0) - after.members[0](0, 0) ==
          Approx(gap * (1.0 - 0.1 * kH) * (1.0 - 0.1 * kH) * (1.0 - 0.1 * kH) * (1.0 - 0.1 * kH) *
                 (1.0 - 0.1 * kH))
              .epsilon(1e-12));
}

TEST_CASE("cpi.lift = own moves each realization by its own step on top of the common increment",
          "[mpi][ensemble][cpi]") {
    // As for members, plus row k of the member steps less their mean over the finite rows: the
    // members' mean still lands on the target. A non-finite row moves by the common increment
    // alone; steps whose rows do not match the realizations are not used at all.
    const MpiComm world(MPI_COMM_WORLD);
    ToyEnsemble toy(world, true);
    if (!toy.root_or_serve()) return;
    EnsembleStepper& stepper = toy.stepper;
    REQUIRE(stepper.lifts_apart());
    coarse::BurstSamples before, after, mismatched;
    stepper.run(0.5, before);
    const Eigen::MatrixXd own = before.members.back();  // R x 3, the states now
    const Eigen::Vector3d target(2.0, 0.3, 0.7);
    Eigen::MatrixXd steps(kRealizations, 3);
    steps << 0.5, 0.0, 0.1,  //
        -0.1, 0.2, 0.0,      //
        0.0, 0.0, 0.0,       //
        0.2, -0.2, 0.5;
    steps.row(2).setConstant(std::numeric_limits<double>::quiet_NaN());
    stepper.lift_apart(target, steps, stepper.time() + 1.0);
    stepper.run(5 * kH, after);
    // The same lift with a step matrix of the wrong size: every realization alike (members).
    const Eigen::MatrixXd own2 = after.members.back();
    stepper.lift_apart(target, Eigen::MatrixXd::Ones(kRealizations - 1, 3), stepper.time() + 1.0);
    stepper.run(5 * kH, mismatched);
    stepper.finish();
    const Eigen::VectorXd increment = target - coarse::ensemble_mean(own);
    // Mean over the finite rows 0, 1, 3: (0.2, 0, 0.2).
    const Eigen::Vector3d mean_step(0.6 / 3, 0.0, 0.6 / 3);
    const Eigen::MatrixXd a = toy_matrix();
    REQUIRE(after.members.size() == 1);
    Eigen::VectorXd lifted_mean = Eigen::VectorXd::Zero(3);
    for (int r = 0; r < kRealizations; ++r) {
        Eigen::VectorXd y = own.row(r).transpose() + increment;
        if (r != 2) y += steps.row(r).transpose() - mean_step;
        lifted_mean += y / kRealizations;
        for (int k = 0; k < 5; ++k) y += kH * (a * y);
        CHECK((after.members[0].row(r).transpose() - y).cwiseAbs().maxCoeff() < 1e-14);
    }
    CHECK((lifted_mean - target).cwiseAbs().maxCoeff() < 1e-14);
    const Eigen::VectorXd increment2 = target - coarse::ensemble_mean(own2);
    for (int r = 0; r < kRealizations; ++r) {
        Eigen::VectorXd y = own2.row(r).transpose() + increment2;
        for (int k = 0; k < 5; ++k) y += kH * (a * y);
        CHECK((mismatched.members[0].row(r).transpose() - y).cwiseAbs().maxCoeff() < 1e-14);
    }
}

TEST_CASE("cpi.at_rest = hold leaves a realization at rest where it is; the others land the mean",
          "[mpi][ensemble][cpi]") {
    // Realization 1 is at rest (a toy that does not move); the ensemble is lifted to X*. Held,
    // it keeps its state bit for bit and its clock follows the jump; the three others carry the
    // whole increment: with lift = mean each goes to (4 X* - X_1) / 3, with members each by
    // (4 X* - sum X_r) / 3 from its own X_r, with own also by its step less the moving rows'
    // mean (the held row's step is not used). In every case the mean of the four is X*
    // (to rounding: sums of four numbers of order 1, 1e-14), as without holding.
    const MpiComm world(MPI_COMM_WORLD);
    for (const char* mode : {"mean", "members", "own"}) {
        const bool members = std::string(mode) != "mean";
        ToyEnsemble toy(world, members, {1});
        if (!toy.root_or_serve()) continue;
        INFO("cpi.lift = " << mode);
        EnsembleStepper& stepper = toy.stepper;
        coarse::BurstSamples before, after;
        stepper.run(0.5, before);
        const Eigen::MatrixXd own = before.members.back();  // R x 3, the states now
        const Eigen::Vector3d target(2.0, 0.3, 0.7);
        Eigen::MatrixXd steps = Eigen::MatrixXd::Zero(kRealizations, 3);
        steps << 0.5, 0.0, 0.1,  //
            9.0, 9.0, 9.0,       // the held realization's: not used
            0.0, -0.3, 0.0,      //
            0.1, 0.0, 0.5;
        const double new_time = stepper.time() + 1.0;
        if (std::string(mode) == "own")
            stepper.lift_apart(target, steps, new_time);
        else
            stepper.lift(target, new_time);
        const LiftRecord lifted = stepper.last_lift();
        stepper.run(5 * kH, after);  // the toy's next sample: states advanced by 5 Euler substeps
        stepper.finish();
        REQUIRE(lifted.at_rest.size() == static_cast<std::size_t>(kRealizations));
        const Eigen::VectorXd sum = own.colwise().sum().transpose();
        const Eigen::VectorXd increment = (kRealizations * target - sum) / 3.0;
        const Eigen::Vector3d mean_step = (steps.row(0) + steps.row(2) + steps.row(3)) / 3.0;
        const Eigen::MatrixXd a = toy_matrix();
        Eigen::VectorXd lifted_mean = Eigen::VectorXd::Zero(3);
        for (int r = 0; r < kRealizations; ++r) {
            Eigen::VectorXd y = own.row(r).transpose();
            if (r == 1) {
                CHECK(lifted.at_rest[1] == 1);
                CHECK(lifted.changed[1] == 0);
            } else {
                CHECK(lifted.at_rest[static_cast<std::size_t>(r)] == 0);
                if (!members)
                    y = (kRealizations * target - own.row(1).transpose()) / 3.0;
                else
                    y += increment;
                if (std::string(mode) == "own") y += steps.row(r).transpose() - mean_step;
            }
            lifted_mean += y / kRealizations;
            if (r != 1)  // the held toy does not move
                for (int k = 0; k < 5; ++k) y += kH * (a * y);
            if (r == 1)
                CHECK(after.members[0].row(r).transpose() == y);  // bit for bit
            else
                CHECK((after.members[0].row(r).transpose() - y).cwiseAbs().maxCoeff() < 1e-14);
        }
        CHECK((lifted_mean - target).cwiseAbs().maxCoeff() < 1e-14);
        CHECK(after.t.back() == Approx(new_time + 5 * kH).margin(1e-12));
    }
}

TEST_CASE("cpi.at_rest = hold with every realization at rest lifts none; lift (off) lifts all",
          "[mpi][ensemble][cpi]") {
    const MpiComm world(MPI_COMM_WORLD);
    {
        // All at rest: nothing can carry the increment, so nothing moves; the clocks jump.
        ToyEnsemble toy(world, false, {0, 1, 2, 3});
        if (toy.root_or_serve()) {
            coarse::BurstSamples before, after;
            toy.stepper.run(0.5, before);
            toy.stepper.lift(Eigen::Vector3d(2.0, 0.3, 0.7), toy.stepper.time() + 1.0);
            const LiftRecord lifted = toy.stepper.last_lift();
            toy.stepper.run(5 * kH, after);
            toy.stepper.finish();
            CHECK(after.members[0] == before.members.back());
            CHECK(std::count(lifted.at_rest.begin(), lifted.at_rest.end(), 1) == kRealizations);
        }
    }
    {
        // Without hold (the settings' default, as cpi.at_rest = lift) a toy at rest is lifted.
        ToyEnsemble toy(world, false, {1}, false);
        if (toy.root_or_serve()) {
            coarse::BurstSamples before, after;
            toy.stepper.run(0.5, before);
            const Eigen::Vector3d target(2.0, 0.3, 0.7);
            toy.stepper.lift(target, toy.stepper.time() + 1.0);
            toy.stepper.run(5 * kH, after);
            toy.stepper.finish();
            CHECK(after.members[0].row(1).transpose() == Eigen::VectorXd(target));  // at rest
        }
    }
}
