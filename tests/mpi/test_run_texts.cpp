// Texts the run prints that a user reads first: the ensemble's size in the header and --check.
#include <catch2/catch.hpp>

#include "mpi_driver/run/ensemble_size.hpp"

using efdem::mpi_driver::ensemble_size;

TEST_CASE("the ensemble's size agrees in number", "[mpi][run]") {
    CHECK(ensemble_size(1, 1) == "1 rank x 1 per rank = 1 realization");
    CHECK(ensemble_size(2, 2) == "2 ranks x 2 per rank = 4 realizations");
    CHECK(ensemble_size(1, 3) == "1 rank x 3 per rank = 3 realizations");
}
