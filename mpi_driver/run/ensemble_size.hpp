#pragma once
/// \file
/// How the run's header and `efdem --check` say the ensemble's size, in words that agree in
/// number: "4 ranks x 2 per rank = 8 realizations", "1 rank x 1 per rank = 1 realization".

#include <string>

namespace efdem::mpi_driver {

std::string ensemble_size(int ranks, int per_rank);

}  // namespace efdem::mpi_driver
