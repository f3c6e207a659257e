#pragma once
// Toy coarse time-steppers for the projective-integrator tests: the integrator cannot tell them
// from an ensemble of DEM runs (coarse/equation_free/coarse_stepper.hpp).
#include <cmath>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "coarse/equation_free/coarse_stepper.hpp"

namespace efdem::test {

/// dx/dt = A x advanced by a fixed propagator per sampling interval h: P = I + h A is forward
/// Euler (rho = 1 + h lambda per mode), P = exp(h A) is exact. One sample per interval;
/// the phase signal is x[0]. Lifting sets the state exactly.
class LinearToyStepper final : public coarse::CoarseStepper {
  public:
    LinearToyStepper(Eigen::MatrixXd propagator, double h, Eigen::VectorXd x0, double t0 = 0.0)
        : p_(std::move(propagator)), h_(h), x_(std::move(x0)), t_(t0) {}

    double time() const override { return t_; }
    void run(double duration, coarse::BurstSamples& out) override {
        const long n = std::lround(duration / h_);
        const double t0 = t_;
        for (long i = 1; i <= n; ++i) {
            x_ = p_ * x_;
            t_ = t0 + static_cast<double>(i) * h_;
            out.t.push_back(t_);
            out.x.push_back(x_);
            out.phase_signal.push_back(x_[0]);
        }
    }
    void lift(const Eigen::VectorXd& target, double new_time) override {
        x_ = target;
        t_ = new_time;
        ++lifts;
    }
    const Eigen::VectorXd& state() const { return x_; }
    int lifts = 0;

  private:
    Eigen::MatrixXd p_;
    double h_;
    Eigen::VectorXd x_;
    double t_;
};

/// X_i(t) = c_i + beta_i t + a sin(2 pi t/T + phi_i): a travelling-wave oscillation on a
/// demixing trend. The phase signal is component 0. Lifting to X* at t* keeps the oscillation's
/// phase (the particles are reused, physics.md §9) and moves only c: X(t*) = X*.
class SineTrendStepper final : public coarse::CoarseStepper {
  public:
    SineTrendStepper(Eigen::VectorXd c, Eigen::VectorXd beta, Eigen::VectorXd phi, double a,
                     double period, double h)
        : c_(std::move(c)),
          beta_(std::move(beta)),
          phi_(std::move(phi)),
          a_(a),
          period_(period),
          h_(h) {}

    Eigen::VectorXd value(double t) const {
        Eigen::VectorXd x = c_ + beta_ * t;
        for (Eigen::Index i = 0; i < x.size(); ++i)
            x[i] += a_ * std::sin(2 * 3.141592653589793 * t / period_ + phi_[i]);
        return x;
    }
    double time() const override { return t_; }
    void run(double duration, coarse::BurstSamples& out) override {
        const long n = std::lround(duration / h_);
        const double t0 = t_;
        for (long i = 1; i <= n; ++i) {
            t_ = t0 + static_cast<double>(i) * h_;
            out.t.push_back(t_);
            out.x.push_back(value(t_));
            if (with_phase_signal) out.phase_signal.push_back(out.x.back()[0]);
        }
    }
    void lift(const Eigen::VectorXd& target, double new_time) override {
        t_ = new_time;
        c_ += target - value(new_time);
        ++lifts;
    }
    bool with_phase_signal = true;
    int lifts = 0;

  private:
    Eigen::VectorXd c_, beta_, phi_;
    double a_, period_, h_;
    double t_ = 0.0;
};

/// R members that share a SineTrendStepper's trend and oscillation, each with its own extra
/// trend: member r is X_r(t) = X_common(t) + d_r t (d = R x dim). X is the members' mean and
/// every sample carries the members (BurstSamples::members, row r = member r). The common part
/// is the same in every member, so the spread of any linear slope estimator's member slopes is
/// that of d: the slope's standard error is std_r(d_r)/sqrt(R) exactly. Lifting moves the common
/// offset so that the members' mean meets the target.
class MemberTrendStepper final : public coarse::CoarseStepper {
  public:
    MemberTrendStepper(SineTrendStepper common, Eigen::MatrixXd member_trends)
        : common_(std::move(common)),
          d_(std::move(member_trends)),
          d_mean_(d_.colwise().mean().transpose()) {}

    double time() const override { return common_.time(); }
    void run(double duration, coarse::BurstSamples& out) override {
        const std::size_t first = out.t.size();
        common_.run(duration, out);
        for (std::size_t k = first; k < out.t.size(); ++k) {
            Eigen::MatrixXd members = d_ * out.t[k];
            members.rowwise() += out.x[k].transpose();
            out.x[k] += d_mean_ * out.t[k];
            out.members.push_back(std::move(members));
        }
    }
    void lift(const Eigen::VectorXd& target, double new_time) override {
        common_.lift(target - d_mean_ * new_time, new_time);
    }
    SineTrendStepper& common() { return common_; }

  private:
    SineTrendStepper common_;
    Eigen::MatrixXd d_;
    Eigen::VectorXd d_mean_;
};

}  // namespace efdem::test
