#pragma once
/// \file
/// RankObservable (cpi.observable = ranks): each light quantile expressed as its rank among ALL
/// particles of its own realization, so that what the whole bed does (a shift, an expansion, a
/// wave of the whole column) cancels and what is left is how the light species sits within its
/// bed: the paper's "upper half minus light" idea (physics.md §8) carried to every node.
///
/// Restriction: member r's light ICDF Q_L,r(p_i) is mapped to its rank u_r,i = F_r(Q_L,r(p_i))
/// in that member's whole-bed profile (whole_bed_profile.hpp), then to heights through ONE fixed
/// map, the reference: the ensemble-mean whole-bed profile of the first sample the observable
/// sees. X_r,i = Q_ref(u_r,i) is in d_p ("the height that rank has in the reference bed"), so
/// tolerances, repairs and slopes keep their units and, at the start, X is close to the ICDF. X is
/// the members' mean. The reference is the observable's saved state (kept in checkpoints).
///
/// Lifting: member r's target is Q_r(F_ref(x_i)): the rank x stands for, placed in that member's
/// own bed, which a recolouring does not move. Restricting a member right after its lift returns
/// x (to the map's rounding): lifting and restriction use the same two maps.
///
/// Repair: besides order and range, no interval between nodes may ask for more lights than the
/// bed has particles there. With phi the observed fraction (N_L / N) and u_i = F_ref(x_i), the
/// (p_i - p_{i-1}) N_L lights between nodes i-1 and i need (u_i - u_{i-1}) N >= that, i.e.
/// y_i = u_i - phi p_i non-decreasing, with y_0 >= 0 and y_{m-1} <= 1 - phi (room below the first
/// node and above the last). A projection extrapolating the pure-light top of a demixing bed
/// breaks it (the lights there cannot rise further); the lift would then move lights to
/// neighbouring intervals and miss X. The repair is the Euclidean projection of y onto that set
/// (isotonic regression and clipping, monotone_repair.hpp), which contains the true state, so it
/// brings X nearer to it, never further (docs/error_control.md "A lift that misses its target").

#include <limits>

#include "coarse/demixing/ensemble_observable.hpp"
#include "coarse/demixing/probability_grid.hpp"

namespace efdem::coarse {

class RankObservable final : public EnsembleObservable {
  public:
    explicit RankObservable(const ProbabilityGrid& grid) : m_(grid.size()), p_(grid.values()) {}
    std::string_view name() const override { return "ranks"; }
    std::string_view label() const override { return "light ranks in the whole bed"; }
    Eigen::Index dimension() const override { return m_; }
    ReferenceIcdf reference() const override { return ReferenceIcdf::whole_bed; }
    /// X = the members' mean of restrict_members(); the first call fixes the reference map.
    Eigen::VectorXd restrict_ensemble(const Eigen::MatrixXd& icdf,
                                      const Eigen::MatrixXd& profiles) override;
    bool restricts_members() const override { return true; }
    /// Row r = Q_ref(F_r(Q_L,r)); a row of NaN where member r's ICDF or profile is not finite
    /// (a dropped realization). \pre the reference is set (a restrict_ensemble() came first).
    Eigen::MatrixXd restrict_members(const Eigen::MatrixXd& icdf,
                                     const Eigen::MatrixXd& profiles) const override;
    /// Q_r(F_ref(x)), with `profile` member r's whole-bed profile. \pre the reference is set.
    Eigen::VectorXd lift_target(const Eigen::VectorXd& x,
                                const Eigen::VectorXd& profile) const override;
    /// Non-decreasing and inside the reference bed's heights [Q_ref(0), Q_ref(1)] (the range the
    /// lift maps onto each member's own [lowest, highest] particle), then, where the observed
    /// fraction is known, no interval with more lights than particles (see the file comment;
    /// nodes the second step does not move keep their value bit for bit); `range` is not needed.
    RepairHook repair_hook(FeasibleRange range) const override;
    /// \pre `fraction` in (0, 1], or NaN (unknown: the light-count repair is skipped).
    void set_observed_fraction(double fraction) override;
    /// The reference profile (kWholeBedNodes heights) then the observed fraction (NaN if not
    /// known), or empty before the first sample. restore_state() also takes the reference alone
    /// (checkpoints written before the fraction was kept: it is told again at the next sample).
    std::vector<double> saved_state() const override;
    void restore_state(const std::vector<double>& state) override;

  private:
    /// The light-count step of the repair, on a monotone X inside the reference bed.
    RepairReport repair_light_counts(Eigen::VectorXd& x) const;

    Eigen::Index m_;
    Eigen::VectorXd p_;          ///< the p-grid's nodes
    Eigen::VectorXd reference_;  ///< empty until the first restriction
    double observed_fraction_ = std::numeric_limits<double>::quiet_NaN();
};

}  // namespace efdem::coarse
