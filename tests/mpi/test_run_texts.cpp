// Texts the run prints that a user reads first: the ensemble's size in the header and --check,
// and the advice at a run's start.
#include <catch2/catch.hpp>

#include <string>
#include <vector>

#include "core/param_table.hpp"
#include "dem/realization_builder.hpp"
#include "mpi_driver/run/ensemble_size.hpp"
#include "mpi_driver/run/run_advice.hpp"

using efdem::mpi_driver::ensemble_size;

TEST_CASE("the ensemble's size agrees in number", "[mpi][run]") {
    CHECK(ensemble_size(1, 1) == "1 rank x 1 per rank = 1 realization");
    CHECK(ensemble_size(2, 2) == "2 ranks x 2 per rank = 4 realizations");
    CHECK(ensemble_size(1, 3) == "1 rank x 3 per rank = 3 realizations");
}

namespace {
// A bed of light (U_mf 0.1228 at phi = 0.6) and heavy (0.2456) spheres.
std::vector<std::string> advice(const char* us, bool cpi, bool jumps_end = false) {
    const std::string scene = std::string(
                                  "effects = gravity gas_drag\ndt = 1e-4\n"
                                  "domain.lx = 4\ndomain.ly = 4\n"
                                  "species.names = light heavy\nspecies.density = 1 2\n"
                                  "species.diameter = 1 1\nbed.count = 8 8\n"
                                  "bed.settle = false\ngas_drag.superficial_velocity = ") +
                              us + "\n";
    efdem::ParamTable table = efdem::ParamTable::from_text(scene, "advice_test.cfg");
    const efdem::dem::System sys = efdem::dem::build_system(table.root(), {3, 0, false});
    return efdem::mpi_driver::run_advice(cpi, jumps_end, sys);
}
}  // namespace

TEST_CASE("a cpi run between the species' U_mf is told that CPI keeps beds moving", "[mpi][run]") {
    const std::vector<std::string> slow = advice("0.19", true);
    REQUIRE(slow.size() == 1);
    CHECK(slow.front().find("U_s = 0.19 does not fluidize heavy on its own") == 0);
    CHECK(slow.front().find("cpi.jump_until") != std::string::npos);
    CHECK(advice("0.19", true, true).empty());  // its jumps end: the beds can come to rest
    CHECK(advice("0.19", false).empty());       // a direct run computes the rest itself
    CHECK(advice("0.41", true).empty());        // both species fluidized: the bed never rests
    CHECK(advice("0.1", true).empty());         // neither: a packed bed, nothing to warn of here
}
