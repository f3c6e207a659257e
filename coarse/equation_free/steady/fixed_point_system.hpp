#pragma once
/// \file
/// G(X) = F(X; lambda) = Phi_tau(X; lambda) - X at a fixed parameter: the steady-state problem
/// for the Newton-Krylov loop, on a CoarseMap.

#include "coarse/equation_free/steady/coarse_map.hpp"
#include "coarse/equation_free/steady/newton_system.hpp"

namespace efdem::coarse {

class FixedPointSystem final : public NewtonSystem {
  public:
    /// `map` must outlive the system. `parameter`: for a map with a parameter hook.
    explicit FixedPointSystem(CoarseMap& map, Eigen::Index dimension, double parameter = 0.0)
        : map_(map), n_(dimension), parameter_(parameter) {}

    Eigen::Index dimension() const override { return n_; }
    SystemEvaluation begin(const Eigen::VectorXd& y) override;
    Eigen::VectorXd jacobian_times(const Eigen::VectorXd& v) override {
        return map_.derivative(v) - v;
    }
    SystemEvaluation trial(const Eigen::VectorXd& y) override;
    void end() override { map_.end(); }
    long evaluations() const override { return map_.evaluations(); }
    double micro_time() const override { return map_.micro_time(); }

  private:
    CoarseMap& map_;
    Eigen::Index n_;
    double parameter_;
};

}  // namespace efdem::coarse
