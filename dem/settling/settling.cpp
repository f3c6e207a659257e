#include "dem/settling/settling.hpp"

#include <algorithm>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "core/log.hpp"
#include "dem/body_forces/viscous_damping.hpp"
#include "dem/effect_registry.hpp"
#include "dem/system.hpp"

namespace efdem::dem {

Particles settle_bed(Particles particles, const BedSpec& bed, const DemScene& scene,
                     const Params& root, const RealizationSpec& spec,
                     const SettlingReport& report) {
    for (const char* needed : {"pair_contact", "wall_contact"}) {
        bool listed = false;
        for (const auto& n : scene.effect_names) listed |= n == needed;
        if (!listed)
            root.scope("bed").fail("settle",
                                   fmt::format("needs '{}' in 'effects' to settle the bed", needed),
                                   "false, or list pair_contact and wall_contact in effects");
    }
    // The settling run uses the scene's own contact laws and gravity, plus a damping stage.
    const std::vector<std::string> names{"gravity", "pair_contact", "wall_contact"};
    std::vector<std::unique_ptr<Effect>> effects;
    for (const auto& name : names)
        effects.push_back(effect_registry().find(name)->make(
            EffectSetup{root.scope(name), root, scene.species, scene.domain, scene.effect_names}));
    auto damping_owner = std::make_unique<ViscousDamping>(0.0);
    ViscousDamping* damping = damping_owner.get();
    effects.push_back(std::move(damping_owner));

    double top = 0;
    for (const auto& x : particles.x()) top = std::max(top, x.z);
    SystemOptions options;
    options.dt = scene.dt;
    options.skin = scene.skin;
    options.realization = spec.realization;
    System sys(scene.species, scene.domain, std::move(particles), std::move(effects), options);
    const auto steps = [&](double t) { return static_cast<long>(std::ceil(t / scene.dt)); };
    const long chunk = std::max(1L, steps(0.5));
    const double threshold = bed.settle_ke_threshold * scene.species.min_mass();
    const auto ke_per_particle = [&] {
        return sys.translational_kinetic_energy() / static_cast<double>(sys.particles().size());
    };
    SettlingProgress progress;
    progress.realization = spec.realization;
    progress.ke_threshold = threshold;
    const auto tell = [&](SettlingProgress::Stage stage, double stage_end, double ke) {
        if (!report) return;
        progress.stage = stage;
        progress.time = sys.time();
        progress.steps = sys.step_count();
        progress.stage_end = stage_end;
        progress.ke_per_particle = ke;
        report(progress);
    };
    // A stage of n steps, run in chunks so that the caller hears of it (chunks change nothing:
    // System::run(a); run(b) is run(a + b)).
    const auto run_stage = [&](SettlingProgress::Stage stage, long n) {
        const double stage_end = sys.time() + static_cast<double>(n) * scene.dt;
        for (long done = 0; done < n;) {
            const long k = std::min(chunk, n - done);
            sys.run(k);
            done += k;
            if (report) tell(stage, stage_end, ke_per_particle());
        }
    };

    const long free_fall = steps(settle_free_fall_time(top));  // the top layer reaches the bed
    tell(SettlingProgress::Stage::free_fall, static_cast<double>(free_fall) * scene.dt,
         ke_per_particle());  // the start
    run_stage(SettlingProgress::Stage::free_fall, free_fall);
    damping->set_gamma(bed.settle_damping);
    run_stage(SettlingProgress::Stage::damped, steps(bed.settle_damped_time));
    damping->set_gamma(0.0);
    const double t_start = sys.time();
    double ke = 0;
    while (true) {
        ke = ke_per_particle();
        if (ke < threshold || sys.time() - t_start >= bed.settle_max_time) break;
        tell(SettlingProgress::Stage::relaxing, t_start + bed.settle_max_time, ke);
        sys.run(chunk);
    }
    tell(SettlingProgress::Stage::done, sys.time(), ke);
    if (ke >= threshold)
        log::warn(
            "realization {}: settling stopped after {:.4g} time units with kinetic energy {:.3g} "
            "per particle, above bed.settle.ke_threshold x m_min g d = {:.3g}",
            spec.realization, sys.time(), ke, threshold);
    Particles settled = sys.particles();
    for (auto& v : settled.v()) v = Vec3{};  // the packed bed starts at rest
    for (auto& w : settled.omega()) w = Vec3{};
    return settled;
}

}  // namespace efdem::dem
