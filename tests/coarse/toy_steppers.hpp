#pragma once
// Toy coarse time-steppers for the projective-integrator tests: the integrator cannot tell them
// from an ensemble of DEM runs (coarse/equation_free/coarse_stepper.hpp).
#include <cmath>
#include <utility>
#include <vector>

#include <Eigen/Core>
#include <optional>
#include <random>

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

/**
 * \brief An ensemble of R Ornstein-Uhlenbeck processes in m components,
 *        dY_r = -k (.) Y_r dt + sigma dW_r, advanced exactly over each sampling interval h:
 *        Y(t+h) = e^(-k h) Y(t) + sigma sqrt((1 - e^(-2 k h))/(2 k)) xi.
 *
 * The ensemble mean obeys dX/dt = -k (.) X in expectation (sigma = 0: exactly), so the exact
 * coarse flow from X is e^(-k DT) X. A lift sets every member to the target (the spread
 * collapses, as colour lifting does). Samples carry the members. keep_state() and
 * return_to_kept_state() save and restore everything, the random streams included.
 */
class OuEnsembleStepper final : public coarse::CoarseStepper {
  public:
    OuEnsembleStepper(Eigen::VectorXd rates, double sigma, int members, double h,
                      const Eigen::VectorXd& x0, std::uint64_t seed)
        : k_(std::move(rates)), sigma_(sigma), h_(h), y_(members, k_.size()) {
        for (int r = 0; r < members; ++r) {
            y_.row(r) = x0.transpose();
            rng_.emplace_back(seed * 1000 + static_cast<std::uint64_t>(r));
        }
    }
    double time() const override { return t_; }
    void run(double duration, coarse::BurstSamples& out) override {
        const long n = std::lround(duration / h_);
        const Eigen::ArrayXd decay = (-k_.array() * h_).exp();
        const Eigen::ArrayXd amp =
            sigma_ * ((1.0 - (-2.0 * k_.array() * h_).exp()) / (2.0 * k_.array())).sqrt();
        std::normal_distribution<double> normal;
        for (long s = 0; s < n; ++s) {
            for (Eigen::Index r = 0; r < y_.rows(); ++r)
                for (Eigen::Index i = 0; i < y_.cols(); ++i)
                    y_(r, i) =
                        decay[i] * y_(r, i) + amp[i] * normal(rng_[static_cast<std::size_t>(r)]);
            ++steps_;
            t_ = t_lift_ + static_cast<double>(steps_) * h_;
            out.t.push_back(t_);
            out.x.push_back(y_.colwise().mean().transpose());
            out.members.push_back(y_);
            out.phase_signal.push_back(out.x.back()[0]);  // phase signal: component 0
            out.member_phase.push_back(y_.col(0));
        }
        work_ += static_cast<double>(n) * h_;
    }
    void lift(const Eigen::VectorXd& target, double new_time) override {
        y_.rowwise() = target.transpose();
        t_lift_ = t_ = new_time;
        steps_ = 0;
        ++lifts_;
    }
    bool can_keep_state() const override { return true; }
    void keep_state() override { kept_.emplace(Kept{t_, t_lift_, steps_, y_, rng_}); }
    void return_to_kept_state() override {
        t_ = kept_->t;
        t_lift_ = kept_->t_lift;
        steps_ = kept_->steps;
        y_ = kept_->y;
        rng_ = kept_->rng;
        kept_.reset();
    }
    void confirm_kept_state() override { kept_.reset(); }

    Eigen::VectorXd mean() const { return y_.colwise().mean().transpose(); }
    const Eigen::VectorXd& rates() const { return k_; }
    double work() const { return work_; }  ///< micro time run, discarded bursts included
    int lifts() const { return lifts_; }

  private:
    struct Kept {
        double t, t_lift;
        long steps;
        Eigen::MatrixXd y;
        std::vector<std::mt19937_64> rng;
    };
    Eigen::VectorXd k_;
    double sigma_, h_;
    Eigen::MatrixXd y_;
    std::vector<std::mt19937_64> rng_;
    double t_ = 0.0, t_lift_ = 0.0;
    long steps_ = 0;
    double work_ = 0.0;
    int lifts_ = 0;
    std::optional<Kept> kept_;
};

/// An OuEnsembleStepper seen through a change a test makes: derive and override run() (what
/// the samples show) or lift() (what a lift does); everything else is the toy's.
class OuEnsembleView : public coarse::CoarseStepper {
  public:
    explicit OuEnsembleView(OuEnsembleStepper toy) : toy_(std::move(toy)) {}
    double time() const override { return toy_.time(); }
    void run(double duration, coarse::BurstSamples& out) override { toy_.run(duration, out); }
    void lift(const Eigen::VectorXd& target, double new_time) override {
        toy_.lift(target, new_time);
    }
    bool can_keep_state() const override { return true; }
    void keep_state() override { toy_.keep_state(); }
    void return_to_kept_state() override { toy_.return_to_kept_state(); }
    void confirm_kept_state() override { toy_.confirm_kept_state(); }

  protected:
    OuEnsembleStepper toy_;
};

}  // namespace efdem::test
