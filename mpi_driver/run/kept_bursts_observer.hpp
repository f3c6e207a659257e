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
    void step_done(const coarse::ProjectiveRun& run,
                   const coarse::ProjectiveStepRecord& record) override;
    const std::vector<double>& times() const { return times_; }
    const std::vector<Eigen::VectorXd>& states() const { return states_; }

  private:
    std::vector<double> times_;
    std::vector<Eigen::VectorXd> states_;
};

}  // namespace efdem::mpi_driver
