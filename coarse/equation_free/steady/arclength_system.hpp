#pragma once
/// \file
/// The pseudo-arclength extended system in y = (X, lambda) (Keller 1977):
///
///   G(y) = [ F(X; lambda) ; t . (y - y_pred) ],
///
/// t the unit tangent at the last branch point, y_pred = y_k + ds t the predictor. Its Jacobian
/// [F_X  F_lambda; t^T] stays regular at a simple fold, where F_X alone is singular, so the
/// corrector (NewtonKrylov) goes round the fold. Products by CRN differences along (v, mu) in
/// one map evaluation (CoarseMap::derivative with a parameter step).

#include "coarse/equation_free/steady/coarse_map.hpp"
#include "coarse/equation_free/steady/newton_system.hpp"

namespace efdem::coarse {

class ArclengthSystem final : public NewtonSystem {
  public:
    /// \pre map has a parameter hook; tangent and predicted have size n + 1; |tangent| = 1;
    /// the predicted lambda within the map's parameter bounds (CoarseMap::set_parameter_bounds).
    /// The micro model is never run at a lambda outside them: a line-search trial there counts
    /// as no decrease (|G| = inf) without a burst. A Newton step from a noisy tangent can ask for
    /// an unphysical parameter (on the DEM, e.g. a gas velocity that blows the bed into the lid).
    ArclengthSystem(CoarseMap& map, Eigen::VectorXd tangent, Eigen::VectorXd predicted);

    Eigen::Index dimension() const override { return tangent_.size(); }
    SystemEvaluation begin(const Eigen::VectorXd& y) override;
    Eigen::VectorXd jacobian_times(const Eigen::VectorXd& v) override;
    SystemEvaluation trial(const Eigen::VectorXd& y) override;
    void end() override { map_.end(); }
    long evaluations() const override { return map_.evaluations(); }
    double micro_time() const override { return map_.micro_time(); }

  private:
    SystemEvaluation assemble(const MapEvaluation& e, const Eigen::VectorXd& y) const;

    CoarseMap& map_;
    Eigen::VectorXd tangent_, predicted_;
};

}  // namespace efdem::coarse
