#pragma once
// Toy coarse time-steppers with known steady states for the steady-state solvers
// (coarse/equation_free/steady/newton_krylov.hpp, continuation.hpp): all of them can keep their
// state (common random numbers), as EnsembleStepper can.
#include <cmath>
#include <cstdint>
#include <functional>
#include <optional>
#include <random>
#include <tuple>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "coarse/equation_free/coarse_stepper.hpp"

namespace efdem::test {

/// x' = A (x - x*) advanced exactly by P = exp(A h) per sampling interval h:
/// x <- x* + P (x - x*). The coarse map over tau = K h is Phi(X) = x* + P^K (X - x*), whose
/// fixed point is x* and whose eigenvalues are exp(lambda_k tau). Lifting sets the state.
class AffineToyStepper final : public coarse::CoarseStepper {
  public:
    AffineToyStepper(Eigen::MatrixXd propagator, Eigen::VectorXd fixed_point, double h)
        : p_(std::move(propagator)), x_star_(std::move(fixed_point)), h_(h), x_(x_star_) {}

    double time() const override { return t_; }
    void run(double duration, coarse::BurstSamples& out) override {
        const long n = std::lround(duration / h_);
        for (long i = 0; i < n; ++i) {
            x_ = x_star_ + p_ * (x_ - x_star_);
            t_ += h_;
            out.t.push_back(t_);
            out.x.push_back(x_);
        }
    }
    void lift(const Eigen::VectorXd& target, double new_time) override {
        x_ = target;
        t_ = new_time;
    }
    bool can_keep_state() const override { return true; }
    void keep_state() override { kept_.emplace(x_, t_); }
    void return_to_kept_state() override {
        std::tie(x_, t_) = *kept_;
        kept_.reset();
    }
    void confirm_kept_state() override { kept_.reset(); }

  private:
    Eigen::MatrixXd p_;
    Eigen::VectorXd x_star_;
    double h_;
    Eigen::VectorXd x_;
    double t_ = 0.0;
    std::optional<std::pair<Eigen::VectorXd, double>> kept_;
};

/**
 * \brief R members of dY = f(Y; lambda) dt + sigma dW in m components: per step dt one
 *        classical RK4 step of the drift, then the noise increment sigma sqrt(dt) xi (each
 *        member its own stream). One sample every `steps_per_sample` steps, carrying the members.
 *
 * With sigma = 0 the fixed points of the coarse map are the drift's zeros exactly (every RK4
 * stage vanishes there) and dPhi/dX = R(dt Df)^(tau/dt), R the RK4 polynomial, = exp(Df tau) up
 * to O(tau dt^4). A lift sets every member to the target (the spread collapses). keep_state()
 * keeps members, streams and clock. set_parameter() changes lambda (continuation).
 */
class SdeEnsembleStepper final : public coarse::CoarseStepper {
  public:
    using Drift = std::function<Eigen::VectorXd(const Eigen::VectorXd&, double)>;
    SdeEnsembleStepper(Drift drift, double sigma, int members, double dt, int steps_per_sample,
                       const Eigen::VectorXd& x0, std::uint64_t seed)
        : f_(std::move(drift)),
          sigma_(sigma),
          dt_(dt),
          per_sample_(steps_per_sample),
          y_(members, x0.size()) {
        y_.rowwise() = x0.transpose();
        for (int r = 0; r < members; ++r)
            rng_.emplace_back(seed * 1000 + static_cast<std::uint64_t>(r));
    }
    void set_parameter(double lambda) { lambda_ = lambda; }

    double time() const override { return t_; }
    void run(double duration, coarse::BurstSamples& out) override {
        const long samples = std::lround(duration / (dt_ * per_sample_));
        std::normal_distribution<double> normal;
        const double amp = sigma_ * std::sqrt(dt_);
        for (long s = 0; s < samples; ++s) {
            for (Eigen::Index r = 0; r < y_.rows(); ++r) {
                Eigen::VectorXd y = y_.row(r).transpose();
                for (int k = 0; k < per_sample_; ++k) {
                    const Eigen::VectorXd k1 = f_(y, lambda_);
                    const Eigen::VectorXd k2 = f_(y + 0.5 * dt_ * k1, lambda_);
                    const Eigen::VectorXd k3 = f_(y + 0.5 * dt_ * k2, lambda_);
                    const Eigen::VectorXd k4 = f_(y + dt_ * k3, lambda_);
                    y += dt_ / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
                    if (sigma_ > 0)
                        for (Eigen::Index i = 0; i < y.size(); ++i)
                            y[i] += amp * normal(rng_[static_cast<std::size_t>(r)]);
                }
                y_.row(r) = y.transpose();
            }
            t_ += dt_ * per_sample_;
            out.t.push_back(t_);
            out.x.push_back(y_.colwise().mean().transpose());
            out.members.push_back(y_);
        }
    }
    void lift(const Eigen::VectorXd& target, double new_time) override {
        y_.rowwise() = target.transpose();
        t_ = new_time;
    }
    bool can_keep_state() const override { return true; }
    void keep_state() override { kept_.emplace(Kept{y_, rng_, t_}); }
    void return_to_kept_state() override {
        y_ = kept_->y;
        rng_ = kept_->rng;
        t_ = kept_->t;
        kept_.reset();
    }
    void confirm_kept_state() override { kept_.reset(); }

  private:
    struct Kept {
        Eigen::MatrixXd y;
        std::vector<std::mt19937_64> rng;
        double t;
    };
    Drift f_;
    double sigma_, dt_;
    int per_sample_;
    Eigen::MatrixXd y_;
    std::vector<std::mt19937_64> rng_;
    double lambda_ = 0.0, t_ = 0.0;
    std::optional<Kept> kept_;
};

}  // namespace efdem::test
