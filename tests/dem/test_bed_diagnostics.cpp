// Bed diagnostics on configurations whose answers are known exactly, and the CSV time series.
#include <catch2/catch.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <sstream>

#include "core/rng.hpp"
#include "dem/beds/bed_diagnostics.hpp"
#include "dem/beds/bed_observation.hpp"
#include "dem/io/bed_time_series.hpp"
#include "tests/support/csv_table.hpp"
#include "tests/support/dem_fixtures.hpp"

using namespace efdem;
using namespace efdem::dem;

namespace {
/// `layers` layers of 4 x 4 touching spheres in a 4 x 4 box, centres at z = k + 1/2: slab
/// [k, k+1] holds exactly one layer. Species alternate by layer (light at the bottom).
Particles lattice(int layers) {
    const auto species = test::binary_species();
    Particles p;
    Tag tag = 1;
    for (int k = 0; k < layers; ++k)
        for (int a = 0; a < 4; ++a)
            for (int b = 0; b < 4; ++b)
                p.add(tag++, {a + 0.5, b + 0.5, k + 0.5}, {}, static_cast<SpeciesId>(k % 2),
                      species);
    return p;
}
}  // namespace

TEST_CASE("bed height, centre-of-mass heights and phi(z) of a simple-cubic stack",
          "[unit][diagnostics]") {
    const Particles p = lattice(10);
    // Half of the volume lies below z = 5; 95 % below the middle of the top layer, z = 9.5.
    CHECK(bed_height(p, 0.5) == Approx(5.0).margin(1e-8));
    CHECK(bed_height(p, 0.95) == Approx(9.5).margin(1e-8));
    const double h99 = bed_height(p);  // 99 %: 90 % of the top layer's spheres
    CHECK(h99 > 9.5);
    CHECK(h99 < 10.0);
    CHECK(sphere_volume_below(h99, 9.5, 0.5) == Approx(0.9 * std::numbers::pi / 6).epsilon(1e-8));
    // Light layers at 0.5, 2.5, ..., 8.5 (mean 4.5), heavy at 1.5, ..., 9.5 (mean 5.5); heavy
    // weigh twice as much: all particles (4.5 + 2 x 5.5)/3.
    CHECK(center_of_mass_height(p, 0) == Approx(4.5));
    CHECK(center_of_mass_height(p, 1) == Approx(5.5));
    CHECK(center_of_mass_height(p) == Approx((4.5 + 11.0) / 3));
    CHECK(center_of_mass_height(p, 5) == 0.0);
    CHECK(weight_per_area(p, Domain{4, 4}) == Approx(80 * std::numbers::pi / 6 * 3 / 16));
    const auto phi = solid_fraction_profile(p, Domain{4, 4}, 1.0);
    REQUIRE(phi.size() == 10);
    for (double f : phi) CHECK(f == Approx(std::numbers::pi / 6).epsilon(1e-14));
    // One sphere ejected far above barely moves the 99 % height (it holds 1/161 of the volume).
    Particles q = lattice(10);
    q.add(999, {1, 1, 500}, {}, 0, test::binary_species());
    CHECK(bed_height(q) < 10.0);
    CHECK(bed_height(Particles{}) == 0.0);
}

TEST_CASE("the bed time series is CSV as pandas reads it: column names first, one row per call",
          "[unit][diagnostics][io]") {
    const auto file = std::filesystem::temp_directory_path() / "efdem_bed_series_test.csv";
    const auto species = test::binary_species();
    test::EffectList fx;
    fx.gravity().gas(test::paper_gas(0.41), species);
    System s = test::make_system(species, {4, 4}, lattice(3), std::move(fx), 1e-3);
    {
        BedTimeSeries series(file, s);
        series.write(s);
        s.run(10);
        series.write(s);
    }
    const test::CsvTable t = test::read_csv_table(file);
    CHECK(t.header == std::vector<std::string>{"step", "time", "pressure_drop", "weight_per_area",
                                               "bed_height", "z_com", "z_com_light", "z_com_heavy",
                                               "ke_per_particle"});
    REQUIRE(t.rows.size() == 2);
    CHECK(t.ragged_rows() == 0);
    const auto& last = t.rows.back();
    CHECK(last[0] == "10");
    CHECK(std::stod(last[1]) == Approx(0.01));
    CHECK(std::stod(last[2]) == Approx(pressure_drop(s)).epsilon(1e-9));
    CHECK(std::stod(last[2]) > 0);  // gas flows up through the bed
    CHECK_THROWS_AS(BedTimeSeries("/nonexistent_dir/x.csv", s), RuntimeFailure);
}

TEST_CASE("the Lacey mixing index: 0 for species in separate layers, 1 for a random mixture",
          "[unit][diagnostics]") {
    const auto species = test::binary_species();
    // Layers of one species each (the lattice alternates species by layer): every 1-d_p layer
    // is pure, so s^2 = s0^2 and M = 0 exactly.
    CHECK(lacey_mixing_index(lattice(10), 0, 1.0) == Approx(0.0).margin(1e-12));
    // Layers of 2 d_p hold one light and one heavy layer: c_k = P in every layer, s^2 = 0, and
    // M = s0^2 / (s0^2 - sr^2) = 1 / (1 - 1/n_mean) with n_mean = 32 particles per layer.
    CHECK(lacey_mixing_index(lattice(10), 0, 2.0) == Approx(1.0 / (1.0 - 1.0 / 32)).epsilon(1e-12));
    // Species drawn at random (P = 1/2) over 10 layers of 400: E[s^2] = sr^2, so M = 1 up to
    // the fluctuation of s^2 / sr^2 (a chi^2 with 10 degrees of freedom over 10: s.d. 0.45),
    // which M carries divided by n_mean - 1 = 399: |M - 1| < 0.005 is 4.4 s.d.
    Particles p;
    RandomStream rng(7, 0, "test");
    Tag tag = 1;
    for (int k = 0; k < 4000; ++k)
        p.add(tag++, {0.5, 0.5, 0.5 + k / 400}, {},
              static_cast<SpeciesId>(rng.uniform() < 0.5 ? 0 : 1), species);
    CHECK(std::abs(lacey_mixing_index(p, 0, 1.0) - 1.0) < 0.005);
    // Undefined: one species only, or one occupied layer.
    CHECK(std::isnan(lacey_mixing_index(lattice(1), 0, 1.0)));
    CHECK(std::isnan(lacey_mixing_index(lattice(10), 0, 100.0)));
}

TEST_CASE("a bed observation: fixed-length phi(z), species heights, and a pack/unpack round trip",
          "[unit][diagnostics]") {
    const Particles p = lattice(10);
    // Fixed slab count: padded with empty slabs above the bed, cut below its top.
    const auto phi = solid_fraction_profile(p, Domain{4, 4}, 1.0, 14);
    REQUIRE(phi.size() == 14);
    CHECK(phi[9] == Approx(std::numbers::pi / 6).epsilon(1e-14));
    CHECK(phi[13] == 0.0);
    CHECK(solid_fraction_profile(p, Domain{4, 4}, 1.0, 5).size() == 5);

    BedObservationSettings s;
    s.species = 2;
    s.profile_slabs = 3;
    BedObservation o;
    o.pressure_drop = 1.5;
    o.pressure_drop_ratio = 0.25;
    o.height = 9.9;
    o.mixing_index = 0.5;
    o.species_height = {4.5, 5.5};
    o.solid_fraction = {0.1, 0.2, 0.3};
    const auto packed = o.pack();
    REQUIRE(packed.size() == BedObservation::packed_size(s));
    const BedObservation back = BedObservation::unpack(packed, s);
    CHECK(back.pressure_drop == 1.5);
    CHECK(back.pressure_drop_ratio == 0.25);
    CHECK(back.height == 9.9);
    CHECK(back.mixing_index == 0.5);
    CHECK(back.species_height == o.species_height);
    CHECK(back.solid_fraction == o.solid_fraction);
}
