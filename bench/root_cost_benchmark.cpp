// The root's per-coarse-step cost in an ensemble of R realizations: one restriction (observe,
// gather the ICDFs, average, record) and one lift (gather heights and colours, compute all R
// colour assignments on the root, scatter, apply), timed through the real EnsembleStepper with
// realizations of N particles that do not move (the DEM is not what is measured here).
//
//   mpirun -np P efdem_root_cost_benchmark N_PARTICLES PER_RANK [repeats=5] [observable=icdf]
// observable: a name of cpi.observable (icdf, ranks, ...): ranks also sorts every particle's height
// per realization and sample (the whole-bed profile) and gathers it.
// Prints: R, N, the observable, median restriction and lift wall times [s] (barrier-synchronized).
#include <mpi.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>
#include <vector>

#include "coarse/demixing/ensemble_observable.hpp"
#include "coarse/demixing/observable_table.hpp"
#include "core/rng.hpp"
#include "dem/system.hpp"
#include "mpi_driver/ensemble/dem_realization.hpp"
#include "mpi_driver/ensemble/ensemble_stepper.hpp"
#include "mpi_driver/parallel/ensemble_layout.hpp"

using namespace efdem;
using namespace efdem::mpi_driver;

namespace {
/// N spheres at random heights in a 15 x 15 column as tall as a packed bed of N (no effects).
dem::System static_bed(long n, long realization) {
    const dem::SpeciesTable species({{"light", 1.0, 1.0}, {"heavy", 2.0, 1.0}});
    RandomStream rng(1, static_cast<std::uint64_t>(realization), "bench");
    const double height = static_cast<double>(n) * 0.5236 / (0.6 * 225.0);
    dem::Particles p;
    for (long i = 0; i < n; ++i)
        p.add(i + 1, {rng.uniform(0, 15), rng.uniform(0, 15), rng.uniform(0.5, 0.5 + height)}, {},
              static_cast<dem::SpeciesId>(i % 2), species);
    dem::SystemOptions o;
    o.realization = realization;
    o.health_check_every = 0;
    return dem::System(species, dem::Domain{15, 15}, std::move(p), {}, o);
}

double median(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v[v.size() / 2];
}
}  // namespace

int main(int argc, char** argv) {
    MPI_Init(&argc, &argv);
    if (argc < 3) {
        std::fprintf(stderr, "usage: %s N_PARTICLES PER_RANK [repeats] [observable]\n", argv[0]);
        MPI_Abort(MPI_COMM_WORLD, 2);
    }
    const long n = std::atol(argv[1]);
    const int k = std::atoi(argv[2]);
    const int repeats = argc > 3 ? std::atoi(argv[3]) : 5;
    const std::string name = argc > 4 ? argv[4] : "icdf";
    const auto* row = coarse::observable_table().find(name);
    if (row == nullptr) {
        std::fprintf(stderr, "unknown observable '%s'\n", name.c_str());
        MPI_Abort(MPI_COMM_WORLD, 2);
    }
    {
        const MpiComm world(MPI_COMM_WORLD);
        const EnsembleLayout layout(world, k);
        std::vector<std::unique_ptr<Realization>> local;
        for (int j = 0; j < k; ++j)
            local.push_back(std::make_unique<DemRealization>(
                static_bed(n, layout.first_index() + j), 0, 1, RealizationOutput{}));
        StepperSettings ss;
        ss.sample_interval = 1e-4;
        ss.steps_per_sample = 1;
        const std::unique_ptr<coarse::EnsembleObservable> observable =
            row->make(coarse::ProbabilityGrid(19));
        const ColourLifter lifter;
        EnsembleStepper stepper(layout, std::move(local), ss, *observable, lifter, nullptr,
                                nullptr);
        std::vector<double> restrict_s, lift_s;
        for (int rep = 0; rep < repeats; ++rep) {
            coarse::BurstSamples burst;
            // The commands are issued by the root; the other ranks follow in serve().
            MPI_Barrier(world.comm());
            double t0 = MPI_Wtime();
            if (world.is_root()) {
                stepper.run(1e-4, burst);
                restrict_s.push_back(MPI_Wtime() - t0);
                // Lift to the current mean raised by 0.3 d_p: a typical projection.
                const Eigen::VectorXd target = burst.x.back().array() + 0.3;
                t0 = MPI_Wtime();
                stepper.lift(target, stepper.time());
                lift_s.push_back(MPI_Wtime() - t0);
                stepper.finish();
            } else {
                stepper.serve();
            }
        }
        if (world.is_root())
            std::printf(
                "R=%d N=%ld ranks=%d observable=%s restrict_seconds=%.6f lift_seconds=%.6f\n",
                layout.size(), n, world.size(), name.c_str(), median(restrict_s), median(lift_s));
    }
    MPI_Finalize();
    return 0;
}
