// The four parts of the EnsembleStepper, each on its own, at 1, 2 and 4 ranks with the same
// R = 4 toy realizations (tests/mpi/toy_realization.hpp): sampling (gathered in realization
// order, so the mean has the same bits on every layout), lifting (mean and members targets,
// the per-realization lifting streams, a lift of some realizations only), snapshots (a state
// taken and restored gives the same samples bit for bit; samples are held back while they can
// be taken back) and failure agreement (a failure or a stop signal on one rank is seen by all;
// drop, and rebuild from a donor with the donor's state).
#include <catch2/catch.hpp>

#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "coarse/demixing/ensemble_observable.hpp"
#include "mpi_driver/ensemble/ensemble_lifting.hpp"
#include "mpi_driver/ensemble/ensemble_sampler.hpp"
#include "mpi_driver/ensemble/ensemble_snapshots.hpp"
#include "mpi_driver/ensemble/ensemble_stepper.hpp"
#include "mpi_driver/ensemble/failure_agreement.hpp"
#include "mpi_driver/parallel/ensemble_layout.hpp"
#include "tests/mpi/toy_realization.hpp"

using namespace efdem;
using namespace efdem::mpi_driver;

namespace {
constexpr int kR = 4;  // realizations, at 1, 2 or 4 ranks
constexpr double kH = 0.01;

int per_rank(const MpiComm& world) {
    REQUIRE(kR % world.size() == 0);
    return kR / world.size();
}

Eigen::MatrixXd toy_matrix() {
    Eigen::MatrixXd a(3, 3);
    a << -0.1, 0.0, 0.0, 1.0, -20.0, 0.0, 0.0, 0.5, -0.5;
    return a;
}

/// This rank's toys, realization r starting at `start(r)`.
template <class Start>
Realizations toys(const EnsembleLayout& layout, Start start) {
    Realizations local;
    for (int j = 0; j < layout.per_rank(); ++j) {
        const long r = layout.first_index() + j;
        local.push_back(std::make_unique<test::ToyRealization>(r, toy_matrix(), start(r), kH));
    }
    return local;
}

Eigen::VectorXd spread_start(long r) {
    return Eigen::Vector3d(1.0 + 0.1 * static_cast<double>(r), 0.2 * static_cast<double>(r),
                           0.5 - 0.05 * static_cast<double>(r));
}

const test::ToyRealization& toy(const Realizations& local, std::size_t j) {
    return dynamic_cast<const test::ToyRealization&>(*local[j]);
}

std::vector<char> everyone() {
    return std::vector<char>(kR, 1);
}

/// A sink that keeps what it is given (the root's).
struct ListSink final : SampleSink {
    std::vector<SampleRecord> samples;
    std::vector<FailureRecord> failed;
    void sample(const SampleRecord& s) override { samples.push_back(s); }
    void failure(const FailureRecord& f) override { failed.push_back(f); }
};

/// What the lifting cases start from: the toy ensemble spread out, lifted by the toy lifter
/// with master seed 7.
struct ToyLifting {
    MpiComm world{MPI_COMM_WORLD};
    EnsembleLayout layout{world, per_rank(world)};
    Realizations local = toys(layout, spread_start);
    coarse::IcdfObservable observable{3};
    test::ToyLifter lifter;
    EnsembleLifting lifting{layout, 3, 7, lifter};
};

SamplingSettings sampling3() {
    SamplingSettings s;
    s.quantiles = 3;  // the toy's state is its 3-node "ICDF"
    return s;
}
}  // namespace

// --- sampling -------------------------------------------------------------------------------

TEST_CASE("sampling gathers in realization order: the mean has the same bits on any layout",
          "[mpi][ensemble][sampling]") {
    // Component 0 is chosen so that the order of the sum changes its bits: in realization order
    // ((1e16 + 1) - 1e16) + 1 = 1 (1e16 + 1 rounds to 1e16), in any order that pairs the two 1e16
    // first it is 2. A gather in rank order or any other order would change the mean.
    const double big[kR] = {1e16, 1.0, -1e16, 1.0};
    const MpiComm world(MPI_COMM_WORLD);
    const EnsembleLayout layout(world, per_rank(world));
    Realizations local = toys(layout, [&](long r) {
        return Eigen::Vector3d(big[r], 0.1 * static_cast<double>(r), 3.0 - static_cast<double>(r));
    });
    coarse::IcdfObservable observable(3);
    EnsembleSampler sampler(layout, sampling3(), observable);
    coarse::BurstSamples burst;
    const SampleRecord* rec = sampler.take(local, everyone(), 0.0, {}, &burst);
    if (!world.is_root()) {
        CHECK(rec == nullptr);
        CHECK(burst.t.empty());
        return;
    }
    REQUIRE(rec != nullptr);
    REQUIRE(rec->realizations.rows() == kR);
    for (int r = 0; r < kR; ++r) {
        CHECK(rec->realizations(r, 0) == big[r]);  // row r is realization r
        CHECK(rec->realizations(r, 2) == 3.0 - r);
    }
    const double in_order = (((big[0] + big[1]) + big[2]) + big[3]) / kR;
    const double paired = (((big[0] + big[2]) + big[1]) + big[3]) / kR;
    REQUIRE(in_order != paired);  // the data can tell the orders apart
    CHECK(rec->mean[0] == in_order);
    CHECK(rec->mean[0] == 0.25);
    CHECK(rec->realizations_used == kR);
    // Variance of {0, 0.1, 0.2, 0.3}: 1/60, unbiased; a few roundings in the sums.
    CHECK(rec->variance[1] == Approx(1.0 / 60.0).epsilon(1e-12));
    // The burst gets the same sample, with the members in realization order.
    REQUIRE(burst.x.size() == 1);
    CHECK(burst.x[0] == rec->mean);
    REQUIRE(burst.members.size() == 1);
    CHECK(burst.members[0] == rec->realizations);
    CHECK(sampler.height_range() == std::make_pair(-1e16, 1e16));
}

TEST_CASE("sampling leaves a dropped realization out of the means, as a row of NaN",
          "[mpi][ensemble][sampling]") {
    const MpiComm world(MPI_COMM_WORLD);
    const EnsembleLayout layout(world, per_rank(world));
    Realizations local = toys(layout, spread_start);
    coarse::IcdfObservable observable(3);
    EnsembleSampler sampler(layout, sampling3(), observable);
    std::vector<char> active = everyone();
    active[1] = 0;
    const SampleRecord* rec = sampler.take(local, active, 0.0, {}, nullptr);
    if (!world.is_root()) return;
    REQUIRE(rec != nullptr);
    CHECK(rec->realizations_used == 3);
    for (int i = 0; i < 3; ++i) CHECK(std::isnan(rec->realizations(1, i)));
    const Eigen::VectorXd expect =
        ((spread_start(0) + spread_start(2)) + spread_start(3)) / 3.0;  // realization order
    CHECK(rec->mean == expect);
    CHECK(std::isnan(rec->com[1]));
    CHECK(rec->com[3] == spread_start(3)[0]);
}

// --- lifting --------------------------------------------------------------------------------

TEST_CASE("lifting to the mean target puts every realization there; `only` lifts just those",
          "[mpi][ensemble][lifting]") {
    ToyLifting f;
    auto& [world, layout, local, observable, lifter, lifting] = f;
    const Eigen::VectorXd target = Eigen::Vector3d(2.0, -0.5, 0.25);
    EnsembleLifting::Request request;
    request.new_time = 3.5;
    request.target = world.is_root() ? &target : nullptr;
    lifting.lift(local, everyone(), observable, request);
    for (std::size_t j = 0; j < local.size(); ++j) {
        CHECK(toy(local, j).state() == Eigen::VectorXd(target));
        CHECK(local[j]->time() == 3.5);
    }
    // A rebuild lifts only realization 3: the others keep their state and their clock.
    std::vector<char> only(kR, 0);
    only[3] = 1;
    const Eigen::VectorXd second = Eigen::Vector3d(-1.0, 1.0, 4.0);
    request.new_time = 5.0;
    request.target = world.is_root() ? &second : nullptr;
    request.only = &only;
    lifting.lift(local, everyone(), observable, request);
    for (std::size_t j = 0; j < local.size(); ++j) {
        const bool rebuilt = local[j]->index() == 3;
        CHECK(toy(local, j).state() == Eigen::VectorXd(rebuilt ? second : target));
        CHECK(local[j]->time() == (rebuilt ? 5.0 : 3.5));
    }
    if (world.is_root()) {
        REQUIRE(lifting.last().changed.size() == static_cast<std::size_t>(kR));
        CHECK(std::isnan(lifting.last().max_deviation[0]));  // not lifted
        CHECK(lifting.last().max_deviation[3] == 0.0);
    }
    CHECK(lifting.count() == 2);
}

TEST_CASE("lifting to members moves every realization by the same increment, keeping its offset",
          "[mpi][ensemble][lifting]") {
    ToyLifting f;
    auto& [world, layout, local, observable, lifter, lifting] = f;
    const Eigen::VectorXd target = Eigen::Vector3d(2.0, -0.5, 0.25);
    EnsembleLifting::Request request;
    request.new_time = 1.0;
    request.members = true;
    request.target = world.is_root() ? &target : nullptr;
    lifting.lift(local, everyone(), observable, request);
    // The mean before, summed in realization order as the root does.
    Eigen::VectorXd mean = Eigen::VectorXd::Zero(3);
    for (long r = 0; r < kR; ++r) mean += spread_start(r);
    mean /= kR;
    for (std::size_t j = 0; j < local.size(); ++j) {
        const long r = local[j]->index();
        const Eigen::VectorXd now = toy(local, j).state();
        // Exactly the root's arithmetic: X_r + (X - mean).
        CHECK(now == Eigen::VectorXd(spread_start(r) + (Eigen::VectorXd(target) - mean)));
        // And the fact it stands for: the offset from the target is the offset from the old
        // mean (two roundings of numbers below 3: 1e-14 is a hundred ulps).
        CHECK((now - Eigen::VectorXd(target) - (spread_start(r) - mean)).cwiseAbs().maxCoeff() <
              1e-14);
        // They did not collapse onto X: realization r is 0.1 (r - 1.5) above it in component 0.
        CHECK(now[0] - target[0] == Approx(0.1 * (static_cast<double>(r) - 1.5)).margin(1e-14));
    }
}

namespace {
/// A lifter that draws from the realization's stream: the lifted state is the target plus
/// three uniform numbers of that stream, so the state tells which stream lifted it.
class DrawingLifter final : public Lifter {
  public:
    LiftOutcome lift(const Eigen::VectorXd& target, const LiftPayload&,
                     const coarse::ProbabilityGrid&, RandomStream& rng) const override {
        LiftOutcome o;
        for (Eigen::Index i = 0; i < target.size(); ++i)
            o.payload.reals.push_back(target[i] + rng.uniform());
        return o;
    }
};

Eigen::VectorXd drawn(std::uint64_t seed, std::uint64_t stream, int lifts) {
    RandomStream rng(seed, stream, "lifting");
    Eigen::VectorXd x(3);
    for (int k = 0; k < lifts; ++k)
        for (Eigen::Index i = 0; i < 3; ++i) x[i] = rng.uniform();
    return x;
}
}  // namespace

TEST_CASE("every realization is lifted with its own stream, on whichever rank it lives",
          "[mpi][ensemble][lifting]") {
    const MpiComm world(MPI_COMM_WORLD);
    const EnsembleLayout layout(world, per_rank(world));
    Realizations local = toys(layout, spread_start);
    coarse::IcdfObservable observable(3);
    DrawingLifter lifter;
    const std::uint64_t seed = 42;
    EnsembleLifting lifting(layout, 3, seed, lifter);
    const Eigen::VectorXd zero = Eigen::VectorXd::Zero(3);
    EnsembleLifting::Request request;
    request.target = world.is_root() ? &zero : nullptr;
    lifting.lift(local, everyone(), observable, request);
    lifting.lift(local, everyone(), observable, request);
    // The second lift's draws are the 4th to 6th numbers of RandomStream(seed, r, "lifting").
    for (std::size_t j = 0; j < local.size(); ++j)
        CHECK(toy(local, j).state() ==
              drawn(seed, static_cast<std::uint64_t>(local[j]->index()), 2));
    // A rebuilt realization gets a fresh stream: number r + R * failures.
    if (world.is_root()) lifting.renew_stream(2, 1);
    lifting.lift(local, everyone(), observable, request);
    for (std::size_t j = 0; j < local.size(); ++j) {
        const long r = local[j]->index();
        CHECK(toy(local, j).state() ==
              (r == 2 ? drawn(seed, 2 + kR, 1) : drawn(seed, static_cast<std::uint64_t>(r), 3)));
    }
    // The streams are part of the stepper's state (root): saved and put back exactly.
    StepperState saved;
    lifting.save(saved);
    lifting.lift(local, everyone(), observable, request);
    const Eigen::VectorXd after = toy(local, 0).state();
    lifting.restore(saved);
    lifting.lift(local, everyone(), observable, request);
    CHECK(toy(local, 0).state() == after);
}

// --- snapshots ------------------------------------------------------------------------------

TEST_CASE("a snapshot taken and restored gives the same samples bit for bit",
          "[mpi][ensemble][snapshots]") {
    const MpiComm world(MPI_COMM_WORLD);
    const EnsembleLayout layout(world, per_rank(world));
    Realizations local = toys(layout, spread_start);
    coarse::IcdfObservable observable(3);
    EnsembleSampler sampler(layout, sampling3(), observable);
    for (auto& r : local) r->advance(7);
    const std::vector<RealizationState> snap = EnsembleSnapshots::save_realizations(local);
    auto burst = [&] {
        coarse::BurstSamples out;
        for (int s = 0; s < 3; ++s) {
            for (auto& r : local) r->advance(5);
            sampler.take(local, everyone(), local.front()->time(), {}, &out);
        }
        return out;
    };
    const coarse::BurstSamples first = burst();
    EnsembleSnapshots::restore_realizations(local, snap);
    for (std::size_t j = 0; j < local.size(); ++j) CHECK(toy(local, j).steps() == 7);
    const coarse::BurstSamples again = burst();
    if (!world.is_root()) return;
    REQUIRE(first.x.size() == 3);
    REQUIRE(again.x.size() == 3);
    for (std::size_t k = 0; k < 3; ++k) {
        CHECK(again.t[k] == first.t[k]);
        CHECK(again.x[k] == first.x[k]);
        CHECK(again.members[k] == first.members[k]);
    }
    CHECK(first.x[0] != first.x[2]);  // the toy moved: equal samples are not trivially equal
}

TEST_CASE("samples are held back from the sink while a snapshot may take them back",
          "[mpi][ensemble][snapshots]") {
    const MpiComm world(MPI_COMM_WORLD);
    ListSink sink;
    EnsembleSnapshots snapshots(world.is_root() ? &sink : nullptr);
    auto sample = [](double t) {
        SampleRecord s;
        s.time = t;
        return s;
    };
    auto times = [&] {
        std::vector<double> t;
        for (const auto& s : sink.samples) t.push_back(s.time);
        return t;
    };
    snapshots.record(sample(0));  // no snapshot: to the sink at once
    snapshots.keep({});
    snapshots.record(sample(1));
    CHECK(sink.samples.size() == (world.is_root() ? 1u : 0u));
    snapshots.go_back();  // rejected: sample 1 never reaches the sink
    snapshots.keep({});
    snapshots.record(sample(2));
    snapshots.confirm();  // kept, no resume point: sample 2 goes out
    EnsembleSnapshot resume;
    resume.time = 2.0;
    snapshots.set_resume_point(resume);
    snapshots.record(sample(3));  // after the resume point: held
    snapshots.keep({});
    snapshots.record(sample(4));
    snapshots.release();  // what the kept state cannot take back: sample 3
    snapshots.go_back();  // sample 4 dropped
    snapshots.record(sample(5));
    snapshots.back_to_resume_point();  // a failure: back to the resume point, sample 5 dropped
    CHECK(snapshots.has(EnsembleSnapshots::Use::resume));
    CHECK(!snapshots.has(EnsembleSnapshots::Use::kept));
    CHECK(snapshots.get(EnsembleSnapshots::Use::resume).time == 2.0);
    snapshots.record(sample(6));
    snapshots.set_resume_point(resume);  // the next mark: sample 6 goes out
    if (world.is_root())
        CHECK(times() == std::vector<double>{0, 2, 3, 6});
    else
        CHECK(sink.samples.empty());
    CHECK(snapshots.held() == 0);
}

namespace {
/// The R toys behind an EnsembleStepper (5 substeps per sample).
struct ToyEnsemble {
    explicit ToyEnsemble(const MpiComm& world, SampleSink* sink = nullptr)
        : layout(world, per_rank(world)),
          stepper(layout, toys(layout, spread_start), settings(), observable, lifter,
                  world.is_root() ? sink : nullptr, nullptr) {}
    static StepperSettings settings() {
        StepperSettings ss;
        ss.sample_interval = 5 * kH;
        ss.steps_per_sample = 5;
        ss.quantiles = 3;
        return ss;
    }
    EnsembleLayout layout;
    coarse::IcdfObservable observable{3};
    test::ToyLifter lifter;
    EnsembleStepper stepper;
};
}  // namespace

TEST_CASE("the stepper's kept state: a rejected jump is redone bit for bit, its samples unseen",
          "[mpi][ensemble][snapshots]") {
    const MpiComm world(MPI_COMM_WORLD);
    ListSink sink;
    ToyEnsemble toy(world, &sink);
    EnsembleStepper& stepper = toy.stepper;
    if (!world.is_root()) {
        stepper.serve();
        return;
    }
    coarse::BurstSamples warm, rejected, redone;
    stepper.run(0.1, warm);  // 2 samples, recorded at once
    stepper.keep_state();
    stepper.lift(Eigen::Vector3d(1.0, 0.0, 0.0), stepper.time() + 1.0);
    stepper.run(0.15, rejected);
    const double micro = stepper.micro_time();
    stepper.return_to_kept_state();
    CHECK(stepper.micro_time() == micro);  // the discarded work stays in the cost
    CHECK(stepper.last_sample().time == warm.t.back());
    stepper.keep_state();
    stepper.lift(Eigen::Vector3d(1.0, 0.0, 0.0), stepper.time() + 1.0);
    stepper.run(0.15, redone);
    stepper.confirm_kept_state();
    stepper.finish();
    REQUIRE(redone.x.size() == 3);
    for (std::size_t k = 0; k < 3; ++k) {
        CHECK(redone.t[k] == rejected.t[k]);
        CHECK(redone.x[k] == rejected.x[k]);
    }
    // The sink saw the warm-up and the kept burst, not the rejected one: 2 + 3 samples.
    REQUIRE(sink.samples.size() == 5);
    CHECK(sink.samples[2].time == redone.t[0]);
    CHECK(sink.samples[2].mean == redone.x[0]);
}

// --- failure agreement ----------------------------------------------------------------------

namespace {
FailurePolicy policy(FailurePolicy::Action action, long max_failures = 2) {
    FailurePolicy p;
    p.action = action;
    p.max_failures = max_failures;
    return p;
}

/// Realization R - 1 (on the last rank) fails; nobody else.
std::vector<RealizationFailure> last_fails(const Realizations& local) {
    std::vector<RealizationFailure> out;
    for (const auto& r : local)
        if (r->index() == kR - 1) out.push_back({r->index(), "planted failure"});
    return out;
}
}  // namespace

TEST_CASE("a failure on one rank is agreed by every rank: drop (direct) takes it out",
          "[mpi][ensemble][failures]") {
    const MpiComm world(MPI_COMM_WORLD);
    const EnsembleLayout layout(world, per_rank(world));
    Realizations local = toys(layout, spread_start);
    ListSink sink;
    FailureAgreement agreement(layout, policy(FailurePolicy::Action::drop),
                               [] { return std::string("no checkpoint"); });
    CHECK(agreement.agree(local, {}, 0, false, false, &sink).signal == 0);  // nothing to agree on
    CHECK(agreement.active_count() == kR);
    const int signal = agreement.agree(local, last_fails(local), 0, false, false, &sink).signal;
    CHECK(signal == 0);
    // Every rank, not only the failing one, knows it now.
    CHECK(agreement.active_count() == kR - 1);
    CHECK(!agreement.is_active(kR - 1));
    CHECK(agreement.failures() == 1);
    CHECK(!agreement.pending());  // direct: dropped at once, nothing to rebuild
    if (world.is_root()) {
        REQUIRE(sink.failed.size() == 1);
        CHECK(sink.failed[0].realization == kR - 1);
        CHECK(sink.failed[0].action == "dropped");
        CHECK(sink.failed[0].reason == "planted failure");
        CHECK(sink.failed[0].realizations_left == kR - 1);
    }
}

TEST_CASE("a failure under ensemble.on_failure = abort ends the run on every rank",
          "[mpi][ensemble][failures]") {
    const MpiComm world(MPI_COMM_WORLD);
    const EnsembleLayout layout(world, per_rank(world));
    Realizations local = toys(layout, spread_start);
    FailureAgreement agreement(layout, policy(FailurePolicy::Action::abort),
                               [] { return std::string("no checkpoint"); });
    std::string what;
    try {
        agreement.agree(local, last_fails(local), 0, false, true, nullptr);
    } catch (const RunFailed& e) {
        what = e.what();
    }
    CHECK(!what.empty());  // thrown on every rank
    if (world.is_root())
        CHECK(what.find("realization 3 at t = 0: planted failure") != std::string::npos);
}

TEST_CASE("a stop signal received by one rank is agreed by every rank",
          "[mpi][ensemble][failures]") {
    const MpiComm world(MPI_COMM_WORLD);
    const EnsembleLayout layout(world, per_rank(world));
    Realizations local = toys(layout, spread_start);
    FailureAgreement agreement(layout, policy(FailurePolicy::Action::abort),
                               [] { return std::string(); });
    const bool last = world.rank() == world.size() - 1;
    const int mine = last ? 15 : 0;  // SIGTERM on the last rank
    const FailureAgreement::Agreed whole = agreement.agree(local, {}, mine, false, true, nullptr);
    CHECK(whole.signal == 15);
    CHECK(!whole.cut);  // every rank finished the sample: it may be used
    // The last rank stopped inside the next sample: no rank may use that one.
    const FailureAgreement::Agreed cut = agreement.agree(local, {}, mine, last, true, nullptr);
    CHECK(cut.signal == 15);
    CHECK(cut.cut);
    CHECK(agreement.active_count() == kR);
}

TEST_CASE("replace: the failed realization is rebuilt from its donor with the donor's state",
          "[mpi][ensemble][failures]") {
    const MpiComm world(MPI_COMM_WORLD);
    const EnsembleLayout layout(world, per_rank(world));
    Realizations local = toys(layout, spread_start);
    for (auto& r : local) r->advance(3);
    // The resume point: every rank's states now.
    const std::vector<RealizationState> at_resume = EnsembleSnapshots::save_realizations(local);
    for (auto& r : local) r->advance(4);  // the step in which realization 3 fails
    ListSink sink;
    FailureAgreement agreement(layout, policy(FailurePolicy::Action::replace),
                               [] { return std::string(); });
    agreement.agree(local, last_fails(local), 0, false, true, &sink);
    REQUIRE(agreement.pending());  // cpi: waits for the rebuild, on every rank
    EnsembleSnapshots::restore_realizations(local, at_resume);
    const FailureAgreement::Rebuild plan = agreement.plan_rebuild(true);
    REQUIRE(plan.replace);
    REQUIRE(plan.failed == std::vector<long>{kR - 1});
    CHECK(plan.donors == std::vector<long>{0});  // the next one, wrapping around
    CHECK(plan.rebuilt[kR - 1] == 1);
    CHECK(plan.rebuilt[0] == 0);
    // Realization 0 lives on rank 0, realization 3 on the last rank: at 2 and 4 ranks the state
    // crosses ranks.
    agreement.send_donor_states(plan, at_resume, local);
    test::ToyRealization donor(0, toy_matrix(), spread_start(0), kH);
    donor.advance(3);
    for (std::size_t j = 0; j < local.size(); ++j) {
        const long r = local[j]->index();
        CHECK(r == layout.first_index() + static_cast<long>(j));  // keeps its own index
        const test::ToyRealization& t = toy(local, j);
        if (r == kR - 1) {
            CHECK(t.state() == donor.state());
            CHECK(t.time() == donor.time());
        } else {
            test::ToyRealization own(r, toy_matrix(), spread_start(r), kH);
            own.advance(3);
            CHECK(t.state() == own.state());
        }
    }
    agreement.finish_rebuild(plan, 0.03, &sink);
    CHECK(!agreement.pending());
    CHECK(agreement.active_count() == kR);  // replaced: still in the ensemble
    CHECK(agreement.failures() == 1);
    if (world.is_root()) {
        REQUIRE(sink.failed.size() == 1);
        CHECK(sink.failed[0].action == "replaced");
        CHECK(sink.failed[0].donor == 0);
        CHECK(sink.failed[0].resumed_at == 0.03);
    }
}

TEST_CASE("drop in cpi: the failed realization leaves the ensemble at the rebuild",
          "[mpi][ensemble][failures]") {
    const MpiComm world(MPI_COMM_WORLD);
    const EnsembleLayout layout(world, per_rank(world));
    Realizations local = toys(layout, spread_start);
    FailureAgreement agreement(layout, policy(FailurePolicy::Action::drop),
                               [] { return std::string(); });
    agreement.agree(local, last_fails(local), 0, false, true, nullptr);
    REQUIRE(agreement.pending());
    CHECK(agreement.active_count() == kR);  // until the rebuild
    const FailureAgreement::Rebuild plan = agreement.plan_rebuild(true);
    CHECK(!plan.replace);
    CHECK(plan.donors == std::vector<long>{-1});
    CHECK(agreement.active_count() == kR - 1);
    CHECK(!agreement.is_active(kR - 1));
    agreement.finish_rebuild(plan, 0.0, nullptr);
    CHECK(!agreement.pending());
}
