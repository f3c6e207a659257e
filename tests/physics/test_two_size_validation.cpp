// [.validation] beds of two sizes with the polydisperse closure (gas_drag.polydisperse =
// van_der_hoef, docs/effects/gas_drag.md "Spheres of several sizes"), issue 37 item 1:
//  * one-size beds of d = 1 and d = 2 (the second the first scaled by 2): Darcy below U_mf, the
//    weight per area above, each U_mf against the closure's closed form, and their ratio the
//    closure's d^2 (the paper's law at d = 1 is its exact limit);
//  * a fluidized bed of both sizes at one density: Delta P = W/A and the small spheres above the
//    large ones (size segregation; the large sink as jetsam, Rowe, Nienow & Agbim 1972).
// Hidden from the default tier (minutes): scripts/run_validation.sh runs it with the gas
// validation and plots its CSV files (scripts/plot_validation.py) for docs/validation.md §6.
#include <catch2/catch.hpp>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <numeric>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "dem/beds/bed_diagnostics.hpp"
#include "dem/realization_builder.hpp"
#include "tests/support/dem_fixtures.hpp"
#include "tests/support/validation_output.hpp"

using namespace efdem;
using namespace efdem::dem;

namespace {

constexpr double kDt = 1.5e-4;  // t_c/24 of a small-small contact (a large pair's is longer)

/// A settled bed of the paper's contacts and gas (at U_s = 0) with the polydisperse closure:
/// `counts` spheres of `diameters` (one density), in a box x box periodic cross-section.
System settled(const std::vector<long>& counts, const std::vector<double>& diameters, double box,
               std::uint64_t seed) {
    std::string names, dens, diam, count;
    for (std::size_t k = 0; k < counts.size(); ++k) {
        names += fmt::format(" s{}", k);
        dens += " 1";
        diam += fmt::format(" {}", diameters[k]);
        count += fmt::format(" {}", counts[k]);
    }
    const std::string text = fmt::format(
        "dt = {}\neffects = gravity pair_contact wall_contact gas_drag\n"
        "domain.lx = {}\ndomain.ly = {}\ndomain.lid = 300\n"
        "species.names ={}\nspecies.density ={}\nspecies.diameter ={}\n"
        "pair_contact.kn = 2e5\npair_contact.restitution = 0.9\npair_contact.mu = 0.1\n"
        "bed.count ={}\ngas_drag.superficial_velocity = 0\n"
        "gas_drag.polydisperse = van_der_hoef\n",
        kDt, box, box, names, dens, diam, count);
    auto t = test::scene_table(text);
    System s = build_system(t.root(), {seed, 0});
    t.check_all_used();
    return s;
}

struct Averages {
    double dp = 0, dp_sd = 0, height = 0;
};

/// Time averages over `duration` after `relax` time units, sampled every 0.1.
Averages average(System& s, double relax, double duration) {
    s.run(std::lround(relax / s.dt()));
    std::vector<double> dp;
    double height = 0;
    const long n = std::lround(duration / 0.1);
    for (long k = 0; k < n; ++k) {
        s.run(std::lround(0.1 / s.dt()));
        dp.push_back(pressure_drop(s));
        height += bed_height(s.particles());
    }
    Averages a;
    a.dp = std::accumulate(dp.begin(), dp.end(), 0.0) / static_cast<double>(n);
    for (double x : dp) a.dp_sd += (x - a.dp) * (x - a.dp);
    a.dp_sd = std::sqrt(a.dp_sd / static_cast<double>(n));
    a.height = height / static_cast<double>(n);
    return a;
}

}  // namespace

TEST_CASE(
    "Delta P(U_s) of one-size beds of d = 1 and d = 2: Darcy, the weight above U_mf, and "
    "U_mf in the ratio d^2",
    "[.validation][gas][two_sizes]") {
    std::FILE* f =
        std::fopen((test::validation_out_dir() / "dp_sweep_sizes.csv").string().c_str(), "w");
    REQUIRE(f != nullptr);
    std::fprintf(f,
                 "# Delta P(U_s), one-size beds of 500 spheres: d = 1 in 5 x 5, d = 2 in 10 x 10 "
                 "(the first scaled by 2), gas_drag.polydisperse = van_der_hoef\n"
                 "diameter,u_s,u_over_umf,pressure_drop,pressure_drop_sd,weight_per_area,"
                 "u_mf_darcy\n");
    double u_mf[2] = {0, 0}, u_closure[2] = {0, 0};
    for (int k = 0; k < 2; ++k) {
        const double d = k == 0 ? 1.0 : 2.0;
        System s = settled({500}, {d}, 5.0 * d, 3);
        const double wa = weight_per_area(s);
        // The closure's U_mf of a uniform layer at the packed bulk fraction (physics.md §6.1
        // with the diameter): the sweep's scale; the Darcy slope measures the bed's own.
        const auto phi = solid_fraction_profile(s.particles(), s.domain(), d);
        double phi_bulk = 0;
        int n = 0;
        const double h = bed_height(s.particles());
        for (std::size_t j = 3; static_cast<double>(j + 4) * d <= h; ++j) phi_bulk += phi[j], ++n;
        phi_bulk /= n;
        const double u_pred = test::gas_effect(s).minimum_fluidization_velocity(1.0, phi_bulk, d);
        double darcy = 0;
        for (double ratio : {0.5, 0.8, 1.5, 2.5}) {
            test::gas_effect(s).set_superficial_velocity(ratio * u_pred);
            const bool packed = ratio < 1;
            const Averages a = average(s, packed ? 2.0 : 10.0, packed ? 2.0 : 20.0);
            if (packed) {
                // Darcy: Delta P / U_s the same at both packed points (the bed does not move).
                if (darcy == 0) darcy = a.dp / (ratio * u_pred);
                CHECK(a.dp / (ratio * u_pred) == Approx(darcy).epsilon(0.01));
                u_mf[k] = wa / darcy;
            } else {
                // Fluidized: the gas carries the bed. 2 % for d = 1 (as the one-size gas
                // validation); 3 % for d = 2, whose spheres relax to the gas 4 times more slowly
                // (tau ~ d^2 in units of sqrt(d_p/g)), so its slugs collapse onto the floor harder
                // (measured 0.979 W/A, sd 0.029, at 2.5 U_mf; 0.993 for d = 1).
                CHECK(a.dp == Approx(wa).epsilon(d == 1.0 ? 0.02 : 0.03));
            }
            std::fprintf(f, "%g,%.5f,%.3f,%.5f,%.5f,%.5f,%.5f\n", d, ratio * u_pred, ratio, a.dp,
                         a.dp_sd, wa, u_mf[k]);
            test::validation_report(
                fmt::format("  d = {}: U_s = {:.4f} ({:.1f} U_mf,pred): Delta P = {:.4f} W/A "
                            "(sd {:.3f}), H = {:.2f}",
                            d, ratio * u_pred, ratio, a.dp / wa, a.dp_sd / wa, a.height));
        }
        test::validation_report(
            fmt::format("one-size bed d = {}: phi_bulk {:.4f}, W/A {:.4f}, U_mf from Darcy {:.4f}, "
                        "closure at phi_bulk {:.4f}",
                        d, phi_bulk, wa, u_mf[k], u_pred));
        // The uniform-layer prediction ignores the looser floor and surface layers: 15 %, as
        // for one size in the gas validation.
        CHECK(u_pred == Approx(u_mf[k]).epsilon(0.15));
        u_closure[k] = u_pred;
    }
    std::fclose(f);
    // The d = 2 bed is the d = 1 bed scaled by 2 (same count, box and lattice in units of d), but
    // it settles a little denser (phi_bulk 0.623 against 0.620: heavier spheres, other settling
    // dynamics), so the closure's d^2 is compared at each bed's own bulk fraction. What is left
    // (measured: the ratio 3.58 against the closure's 3.82 at the two phi_bulk, 6 %) is the
    // looser floor and surface layers, whose share of the resistance differs: within 10 %.
    const double ratio = u_mf[1] / u_mf[0], closure_ratio = u_closure[1] / u_closure[0];
    test::validation_report(
        fmt::format("U_mf(d = 2) / U_mf(d = 1) = {:.4f}; the closure's at each phi_bulk {:.4f} "
                    "(d^2 = 4 at equal phi)",
                    ratio, closure_ratio));
    CHECK(ratio == Approx(closure_ratio).epsilon(0.10));
    CHECK(closure_ratio == Approx(4.0).epsilon(0.05));  // d^2, up to the packings' difference
}

TEST_CASE("a fluidized bed of two sizes: Delta P = W/A, and the small spheres above the large",
          "[.validation][gas][two_sizes]") {
    // bench/scenes/two_sizes_bed.cfg: 800 small (d = 1) and 100 large (d = 2) in 10 x 10, equal
    // volumes, one density, U_s = 0.6 (U_mf 0.12 small, 0.49 large, 0.22 the mixture).
    std::FILE* f =
        std::fopen((test::validation_out_dir() / "two_sizes_bed.csv").string().c_str(), "w");
    REQUIRE(f != nullptr);
    std::fprintf(f,
                 "# 800 d = 1 + 100 d = 2 in 10 x 10, U_s = 0.6, two realizations from the "
                 "packed state\nrealization,time,pressure_drop_ratio,z_com_small,z_com_large\n");
    for (std::uint64_t seed : {1u, 2u}) {
        System s = settled({800, 100}, {1.0, 2.0}, 10.0, seed);
        const double wa = weight_per_area(s);
        test::gas_effect(s).set_superficial_velocity(0.6);
        double ratio_sum = 0, gap_sum = 0;
        long n_ratio = 0, n_gap = 0;
        for (long k = 1; k <= 600; ++k) {  // 60 time units, sampled every 0.1
            s.run(std::lround(0.1 / s.dt()));
            const double t = 0.1 * static_cast<double>(k);
            const double r = pressure_drop(s) / wa;
            const double zs = center_of_mass_height(s.particles(), 0);
            const double zl = center_of_mass_height(s.particles(), 1);
            if (k % 5 == 0) std::fprintf(f, "%lu,%.1f,%.5f,%.4f,%.4f\n", seed, t, r, zs, zl);
            if (t > 10) ratio_sum += r, ++n_ratio;
            if (t > 50) gap_sum += zs - zl, ++n_gap;
        }
        const double ratio = ratio_sum / static_cast<double>(n_ratio);
        const double gap = gap_sum / static_cast<double>(n_gap);
        test::validation_report(
            fmt::format("two-size bed, seed {}: Delta P/(W/A) = {:.4f} (t > 10); z_small - "
                        "z_large = {:+.2f} d_p (t > 50)",
                        seed, ratio, gap));
        // The gas carries the bed but for what rests on the floor: slugs collapsing onto it (a
        // one-size bed in the same box at the same U_s: 0.985, docs/validation.md §6) and the
        // large spheres gathering at the bottom at only 1.2 times their own U_mf (as the heavy
        // ones of a binary-density bed near their U_mf, §2: 0.90 accepted there). Measured 0.977
        // and 0.972; asserted between 0.95 and 1.01.
        CHECK(ratio > 0.95);
        CHECK(ratio < 1.01);
        // Size segregation, small above large: measured 4.17 +- 0.21 d_p over an ensemble of 4
        // (docs/validation.md §6); a mixed bed has 0 and its fluctuations are ~0.5 d_p.
        CHECK(gap > 2.0);
    }
    std::fclose(f);
}
