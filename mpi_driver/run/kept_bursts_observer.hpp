#pragma once
/// \file
/// KeptBurstsObserver: the end state X(t_end) of every burst a cpi run kept (a jump made or a
/// burst alone; a rejected burst is redone and not kept), for the time to the end state of
/// cpi.hand_off = steady (coarse::arrival_time). Only the bursts this process ran: a resumed
/// run's earlier ones are in the run file, not here.

#include <vector>

#include <Eigen/Core>

#include "coarse/equation_free/projective/projective_run.hpp"

namespace efdem::mpi_driver {

class KeptBurstsObserver final : public coarse::ProjectiveRunObserver {
  public:
    /// `resumed`: the run continues a checkpoint, and the bursts before it are not seen here.
    explicit KeptBurstsObserver(bool resumed = false) : resumed_(resumed) {}
    /// Whether `time` (an arrival_time over times()) may be later than the true one: the run was
    /// resumed and every burst seen here was already within the radius, so the state may have
    /// arrived before the checkpoint.
    bool only_a_bound(double time) const {
        return resumed_ && !times_.empty() && time == times_.front();
    }
    void step_done(const coarse::ProjectiveRun& run,
                   const coarse::ProjectiveStepRecord& record) override;
    const std::vector<double>& times() const { return times_; }
    const std::vector<Eigen::VectorXd>& states() const { return states_; }

  private:
    bool resumed_;
    std::vector<double> times_;
    std::vector<Eigen::VectorXd> states_;
};

}  // namespace efdem::mpi_driver
