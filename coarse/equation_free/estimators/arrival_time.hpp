#pragma once
/// \file
/// arrival_time: when a trajectory reached a state and stayed there, to within a radius. A cpi
/// run handed to the steady solver (cpi.hand_off = steady) states the time its process took to
/// reach the end state the solve found: the first of its kept bursts' end states from which every
/// later one lies within the solve's stopping threshold of the answer (docs/steady_states.md).
/// Generic: no MPI, no DEM.

#include <vector>

#include <Eigen/Core>

namespace efdem::coarse {

/// The earliest times[k] such that |states[j] - target| <= radius for every j >= k (Euclidean
/// norm); NaN when the last state is farther (or there is none). A state of another size than
/// `target` (a coarse variable that changed during the run) counts as farther.
/// \pre times.size() == states.size(), radius >= 0.
double arrival_time(const std::vector<double>& times, const std::vector<Eigen::VectorXd>& states,
                    const Eigen::VectorXd& target, double radius);

}  // namespace efdem::coarse
