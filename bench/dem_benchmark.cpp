// efdem's side of bench/dem_vs_lammps.sh: the reference bed (packed_bed_12500.data.gz) with the
// LAMMPS model of lammps_reference.md (hooke, one gamma_n, history, dt = 1.8e-4, skin 0.1),
// `warmup` untimed steps then `steps` timed steps. Prints one line of key=value results.
//
//   efdem_dem_benchmark DATA_FILE [steps=5000] [warmup=500] [skin=0.1]
#include <sys/resource.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "core/param_table.hpp"
#include "core/version.hpp"
#include "dem/realization_builder.hpp"

int main(int argc, char** argv) {
    if (argc < 2) {
        std::fprintf(stderr, "usage: %s DATA_FILE [steps=N] [warmup=N] [skin=X]\n", argv[0]);
        return 2;
    }
    std::string scene =
        "dt = 1.8e-4\n"
        "effects = gravity pair_contact wall_contact\n"
        "domain.lx = 15\ndomain.ly = 15\n"
        "species.names = light heavy\nspecies.density = 1 2\nspecies.diameter = 1 1\n"
        "pair_contact.kn = 2e5\npair_contact.damping = gamma\npair_contact.gamma_n = 58.5928\n"
        "pair_contact.kt = 57142.857\npair_contact.mu = 0.1\n"
        "bed.source = lammps_data\n"
        "bed.file = \"" +
        std::string(argv[1]) + "\"\n";
    try {
        auto table = efdem::ParamTable::from_text(scene, "<benchmark>");
        long steps = 5000, warmup = 500;
        double skin = 0.1;
        for (int a = 2; a < argc; ++a) {
            const std::string arg = argv[a];
            if (arg.rfind("steps=", 0) == 0)
                steps = std::stol(arg.substr(6));
            else if (arg.rfind("warmup=", 0) == 0)
                warmup = std::stol(arg.substr(7));
            else if (arg.rfind("skin=", 0) == 0)
                skin = std::stod(arg.substr(5));
            else
                throw std::invalid_argument("unknown argument " + arg);
        }
        table.add_override("neighbor.skin=" + std::to_string(skin));
        efdem::dem::System sys = efdem::dem::build_system(table.root(), {1, 0});
        table.check_all_used();
        sys.run(warmup);
        const long builds0 = sys.neighbor_list()->builds();
        const auto t0 = std::chrono::steady_clock::now();
        sys.run(steps);
        const double seconds =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        rusage usage{};
        getrusage(RUSAGE_SELF, &usage);
        const double n = static_cast<double>(sys.particles().size());
        const auto stats = sys.thermo_stats();
        std::printf(
            "efdem particles=%.0f steps=%ld seconds=%.4f particle_steps_per_s=%.4e "
            "neighbor_builds=%ld list_entries_per_particle=%.3f contacts_per_particle=%.3f "
            "ke_per_particle=%.3e peak_rss_bytes_per_particle=%.1f build=\"%s\"\n",
            n, steps, seconds, n * static_cast<double>(steps) / seconds,
            sys.neighbor_list()->builds() - builds0,
            static_cast<double>(sys.neighbor_list()->size()) / n,
            static_cast<double>(stats.contacts) / n, sys.kinetic_energy() / n,
            static_cast<double>(usage.ru_maxrss) * 1024.0 / n, efdem::build_info().c_str());
    } catch (const std::exception& e) {
        std::fprintf(stderr, "efdem_dem_benchmark: %s\n", e.what());
        return 2;
    }
    return 0;
}
