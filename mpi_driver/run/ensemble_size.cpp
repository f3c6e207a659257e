#include "mpi_driver/run/ensemble_size.hpp"

#include <fmt/format.h>

namespace efdem::mpi_driver {

namespace {
std::string counted(long n, const char* one, const char* many) {
    return fmt::format("{} {}", n, n == 1 ? one : many);
}
}  // namespace

std::string ensemble_size(int ranks, int per_rank) {
    return fmt::format("{} x {} per rank = {}", counted(ranks, "rank", "ranks"), per_rank,
                       counted(static_cast<long>(ranks) * per_rank, "realization", "realizations"));
}

}  // namespace efdem::mpi_driver
