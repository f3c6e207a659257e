#pragma once
// A linear toy micro-model for the ensemble driver: x' = A x integrated by forward Euler with
// step h; it reports its state as its "ICDF" and is lifted by setting its state to the target.
// Through EnsembleStepper it exercises the whole driver path (commands, gathers, averages,
// lifts, scatters) with an exactly known coarse dynamics. Its state (x, t, steps) is saved and
// restored exactly (one Vec3 (x_i, 0, 0) per component), so the kept state, the resume point and
// a rebuild from a donor work on it as on a DEM realization.
#include <Eigen/Core>

#include "mpi_driver/ensemble/realization.hpp"

namespace efdem::test {

class ToyRealization final : public mpi_driver::Realization {
  public:
    ToyRealization(long index, Eigen::MatrixXd a, Eigen::VectorXd x0, double h)
        : index_(index), a_(std::move(a)), x_(std::move(x0)), h_(h) {}
    long index() const override { return index_; }
    double time() const override { return t_; }
    void set_time(double t) override { t_ = t; }
    double dt() const override { return h_; }
    long particles() const override { return 1; }
    bool advance_unless_stopped(long steps, const StopCheck&) override {
        for (long s = 0; s < steps; ++s) {
            if (!at_rest_) x_ += h_ * (a_ * x_);  // at rest: a state the toy does not leave
            t_ += h_;
        }
        steps_ += steps;
        return true;  // a toy sample is short: it never stops inside one
    }
    mpi_driver::Observation observe(const coarse::ProbabilityGrid&,
                                    mpi_driver::ReferenceNeeds) const override {
        mpi_driver::Observation o;
        o.icdf = x_;
        o.com = x_[0];
        o.z_min = x_.minCoeff();
        o.z_max = x_.maxCoeff();
        return o;
    }
    mpi_driver::LiftPayload lift_input() const override {
        return {{x_.data(), x_.data() + x_.size()}, {}};
    }
    std::pair<std::size_t, std::size_t> lift_output_sizes() const override {
        return {static_cast<std::size_t>(x_.size()), 0};
    }
    void apply_lift(const mpi_driver::LiftPayload& p) override {
        x_ = Eigen::Map<const Eigen::VectorXd>(p.reals.data(),
                                               static_cast<Eigen::Index>(p.reals.size()));
    }
    mpi_driver::RealizationState save_state() const override {
        mpi_driver::RealizationState s;
        s.index = index_;
        s.time = t_;
        s.step = steps_;
        for (Eigen::Index i = 0; i < x_.size(); ++i) s.x.push_back(Vec3{x_[i], 0.0, 0.0});
        return s;
    }
    void restore_state(const mpi_driver::RealizationState& s) override {
        x_.resize(static_cast<Eigen::Index>(s.x.size()));
        for (std::size_t i = 0; i < s.x.size(); ++i) x_[static_cast<Eigen::Index>(i)] = s.x[i].x;
        t_ = s.time;
        steps_ = s.step;
    }
    bool at_rest() const override { return at_rest_; }
    void set_at_rest(bool rest) { at_rest_ = rest; }
    const Eigen::VectorXd& state() const { return x_; }
    long steps() const { return steps_; }

  private:
    long index_;
    Eigen::MatrixXd a_;
    Eigen::VectorXd x_;
    double h_;
    double t_ = 0;
    long steps_ = 0;
    bool at_rest_ = false;
};

/// Lifting of the toy: the state becomes the target exactly.
class ToyLifter final : public mpi_driver::Lifter {
  public:
    mpi_driver::LiftOutcome lift(const Eigen::VectorXd& target, const mpi_driver::LiftPayload&,
                                 const coarse::ProbabilityGrid&, RandomStream&) const override {
        mpi_driver::LiftOutcome o;
        o.payload.reals.assign(target.data(), target.data() + target.size());
        return o;
    }
};

}  // namespace efdem::test
