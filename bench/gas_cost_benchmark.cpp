// What gas_drag adds to a step of a fluidized bed (target: at most 15 %; docs/performance.md).
//
// The paper's bed (packed_bed_12500.data.gz, the paper's contact model, dt = 1e-4) is first
// fluidized at U_s for `fluidize` time units. Then, `reps` times: the reference run advances
// `gap` steps, and two twins are built from its state, one with and one without gas_drag, and
// each is timed for `steps` steps (interleaved, alternating which goes first). Short twin runs
// matter: a fluidized bed suddenly without its gas is in free fall, and its contacts open within
// about 0.02 time units (6x fewer after 0.1), which would make the gas-free step look cheap for a
// reason that has nothing to do with the gas. Both twins start with empty contact histories.
// Reported: medians of the per-step thread CPU times (the machine may be shared), the overhead
// with/without - 1, and the gas pass alone (slab update + force kernel) on the same states.
//
//   efdem_gas_cost_benchmark DATA_FILE [fluidize=5] [steps=20] [gap=200] [reps=25] [u=0.41]
#include <algorithm>
#include <cstdio>
#include <ctime>
#include <string>
#include <vector>

#include "core/param_table.hpp"
#include "core/version.hpp"
#include "dem/gas/gas_drag.hpp"
#include "dem/gas/slab_fields.hpp"
#include "dem/realization_builder.hpp"

using namespace efdem;

namespace {
/// CPU time of this thread [s]: on a shared machine it leaves out the time other processes
/// hold the core, which wall-clock time would count against whichever run it fell on.
double cpu_seconds() {
    timespec t{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
    return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

double median(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v[v.size() / 2];
}

/// The paper's bed with or without gas_drag; from the data file, or from `state` if given.
dem::System build(const std::string& data_file, bool gas, double u, const dem::Particles* state) {
    const std::string scene =
        "dt = 1e-4\n"
        "effects = gravity pair_contact wall_contact" +
        std::string(gas ? " gas_drag" : "") +
        "\n"
        "domain.lx = 15\ndomain.ly = 15\ndomain.lid = 150\n"
        "species.names = light heavy\nspecies.density = 1 2\nspecies.diameter = 1 1\n"
        "pair_contact.kn = 2e5\npair_contact.restitution = 0.9\npair_contact.mu = 0.1\n"
        "bed.source = lammps_data\nbed.file = \"" +
        data_file + "\"\n" +
        (gas ? "gas_drag.superficial_velocity = " + std::to_string(u) + "\n" : std::string());
    auto table = ParamTable::from_text(scene, "<benchmark>");
    const Params root = table.root();
    if (!state) {
        dem::System s = dem::build_system(root, {1, 0});
        table.check_all_used();
        return s;
    }
    const dem::DemScene dem_scene = dem::DemScene::from_params(root);
    auto effects = dem::make_effects(dem_scene, root);
    dem::SystemOptions options;
    options.dt = dem_scene.dt;
    options.skin = dem_scene.skin;
    return dem::System(dem_scene.species, dem_scene.domain, *state, std::move(effects), options);
}

/// CPU seconds per step of `steps` steps.
double time_steps(dem::System& s, long steps) {
    const double t0 = cpu_seconds();
    s.run(steps);
    return (cpu_seconds() - t0) / static_cast<double>(steps);
}
}  // namespace

int main(int argc, char** argv) {
    if (argc < 2) {
        std::fprintf(stderr,
                     "usage: %s DATA_FILE [fluidize=T] [steps=N] [gap=N] [reps=N] [u=U_s]\n",
                     argv[0]);
        return 2;
    }
    try {
        const std::string data = argv[1];
        double fluidize = 5.0, u = 0.41;
        long steps = 20, gap = 200, reps = 25;
        for (int a = 2; a < argc; ++a) {
            const std::string arg = argv[a];
            if (arg.rfind("fluidize=", 0) == 0)
                fluidize = std::stod(arg.substr(9));
            else if (arg.rfind("steps=", 0) == 0)
                steps = std::stol(arg.substr(6));
            else if (arg.rfind("gap=", 0) == 0)
                gap = std::stol(arg.substr(4));
            else if (arg.rfind("reps=", 0) == 0)
                reps = std::stol(arg.substr(5));
            else if (arg.rfind("u=", 0) == 0)
                u = std::stod(arg.substr(2));
            else
                throw std::invalid_argument("unknown argument " + arg);
        }
        dem::System reference = build(data, true, u, nullptr);
        reference.run(static_cast<long>(fluidize / reference.dt()));

        dem::GasDragSpec spec;
        spec.superficial_velocity = u;
        dem::GasDrag gas(spec, reference.species());
        dem::SlabFields slabs(spec.slab_thickness, 1.0);
        std::vector<double> t_with, t_without, t_gas, t_slabs;
        double contacts = 0;
        for (long r = 0; r < reps; ++r) {
            reference.run(gap);
            dem::System with = build(data, true, u, &reference.particles());
            dem::System without = build(data, false, u, &reference.particles());
            if (r % 2 == 0) {
                t_with.push_back(time_steps(with, steps));
                t_without.push_back(time_steps(without, steps));
            } else {
                t_without.push_back(time_steps(without, steps));
                t_with.push_back(time_steps(with, steps));
            }
            contacts += static_cast<double>(with.thermo_stats().contacts);
            // The gas pass alone on the same state: slab update (as System does it) + kernel.
            dem::Particles scratch = reference.particles();
            dem::ForceContext ctx{
                scratch, reference.domain(), reference.species(), nullptr, nullptr,
                &slabs,  reference.dt(),     reference.time()};
            double t_slab = 0, t_force = 0;
            for (long k = 0; k < steps; ++k) {
                const double t0 = cpu_seconds();
                slabs.update(scratch, reference.domain());
                const double t1 = cpu_seconds();
                gas.add_forces(ctx);
                t_slab += t1 - t0;
                t_force += cpu_seconds() - t1;
            }
            t_gas.push_back((t_slab + t_force) / static_cast<double>(steps));
            t_slabs.push_back(t_slab / static_cast<double>(steps));
        }

        const double n = static_cast<double>(reference.particles().size());
        const double a = median(t_without), b = median(t_with), g = median(t_gas),
                     su = median(t_slabs);
        std::printf(
            "gas_cost particles=%.0f u=%g fluidize=%g steps=%ld gap=%ld reps=%ld slabs=%zu "
            "contacts_per_particle=%.3f step_without_us=%.1f step_with_us=%.1f "
            "overhead_percent=%.1f gas_pass_us=%.1f (slab_update_us=%.1f) "
            "gas_pass_over_rest_percent=%.1f "
            "particle_steps_per_s_with=%.3e build=\"%s\"\n",
            n, u, fluidize, steps, gap, reps, slabs.size(),
            contacts / static_cast<double>(reps) / n, 1e6 * a, 1e6 * b, 100.0 * (b / a - 1.0),
            1e6 * g, 1e6 * su, 100.0 * g / (b - g), n / b, build_info().c_str());
    } catch (const std::exception& e) {
        std::fprintf(stderr, "efdem_gas_cost_benchmark: %s\n", e.what());
        return 2;
    }
    return 0;
}
