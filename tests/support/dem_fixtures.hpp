#pragma once
// Small builders for DEM tests: systems made programmatically (exact initial states) and from
// scene text (the real input path).
#include <memory>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/param_table.hpp"
#include "dem/body_forces/gravity.hpp"
#include "dem/contact/contact_model.hpp"
#include "dem/contact/pair_contact.hpp"
#include "dem/contact/wall_contact.hpp"
#include "dem/gas/gas_drag.hpp"
#include "dem/scene.hpp"
#include "dem/system.hpp"

namespace efdem::test {

/// The paper's binary species: light (density 1) and heavy (density 2), both of diameter 1.
inline dem::SpeciesTable binary_species() {
    return dem::SpeciesTable({{"light", 1.0, 1.0}, {"heavy", 2.0, 1.0}});
}

/// The paper's contact model (physics.md §5): hooke, kn = 2e5, e = 0.9, kt = 2/7 kn, mu = 0.1.
inline dem::ContactSpec paper_contact(
    dem::DampingModel damping = dem::DampingModel::restitution,
    dem::TangentialModel tangential = dem::TangentialModel::history) {
    dem::ContactSpec s;
    s.normal = dem::NormalModel::hooke;
    s.kn = 2e5;
    s.damping = damping;
    s.restitution = 0.9;
    s.gamma_n = 58.5928;  // LAMMPS reference bed: e = 0.9 for a light-light pair
    s.tangential = tangential;
    s.kt = 2.0 / 7.0 * s.kn;
    s.tangential_damping = 0.5;
    s.mu = 0.1;
    return s;
}

struct EffectList {
    std::vector<std::unique_ptr<dem::Effect>> effects;
    EffectList& pair(const dem::ContactSpec& s, const dem::SpeciesTable& sp) {
        effects.push_back(std::make_unique<dem::PairContact>(s, sp));
        return *this;
    }
    EffectList& gravity(double g = 1.0) {
        effects.push_back(std::make_unique<dem::Gravity>(g));
        return *this;
    }
    EffectList& gas(const dem::GasDragSpec& s, const dem::SpeciesTable& sp) {
        effects.push_back(std::make_unique<dem::GasDrag>(s, sp));
        return *this;
    }
    EffectList& wall(const dem::ContactSpec& s, const dem::SpeciesTable& sp) {
        effects.push_back(std::make_unique<dem::WallContact>(s, sp));
        return *this;
    }
};

inline dem::System make_system(const dem::SpeciesTable& species, const dem::Domain& domain,
                               dem::Particles particles, EffectList effects, double dt,
                               double skin = 0.1) {
    dem::SystemOptions o;
    o.dt = dt;
    o.skin = skin;
    o.health_check_every = 0;
    return dem::System(species, domain, std::move(particles), std::move(effects.effects), o);
}

/// The paper's gas (physics.md §3.3): wen_yu_low_re, A = 0.114939, cap 0.70, dz = 1.
inline dem::GasDragSpec paper_gas(double superficial_velocity, double slab_thickness = 1.0) {
    dem::GasDragSpec s;
    s.superficial_velocity = superficial_velocity;
    s.slab_thickness = slab_thickness;
    s.A = dem::GasProperties{}.drag_number();
    return s;
}

/// A small valid binary scene without its `effects` line: 40 spheres on a lattice in 4 x 4,
/// not settled, the paper's contact model.
inline const std::string kSmallBinaryScene =
    "dt = 1e-4\n"
    "domain.lx = 4\n"
    "domain.ly = 4\n"
    "species.names = light heavy\n"
    "species.density = 1 2\n"
    "species.diameter = 1 1\n"
    "bed.count = 20 20\n"
    "bed.settle = false\n"
    "pair_contact.kn = 2e5\n"
    "pair_contact.restitution = 0.9\n"
    "pair_contact.mu = 0.1\n";

/// n binary-species particles (alternating light, heavy) at uniform random positions in
/// [0, l)^2 x [z_lo, z_hi) with standard-normal velocity components; overlaps are not avoided
/// (for tests of fields and forces that do not involve contacts).
inline dem::Particles random_particles(int n, double l, double z_lo, double z_hi,
                                       std::uint32_t seed) {
    const auto species = binary_species();
    std::mt19937 gen(seed);
    std::uniform_real_distribution<double> ux(0, l), uz(z_lo, z_hi);
    std::normal_distribution<double> nv(0, 1);
    dem::Particles p;
    for (int i = 0; i < n; ++i)
        p.add(i + 1, {ux(gen), ux(gen), uz(gen)}, {nv(gen), nv(gen), nv(gen)},
              static_cast<dem::SpeciesId>(i % 2), species);
    return p;
}

/// Species of a bed of two sizes: 0 = "small" (diameter 1), 1 = "large" (diameter `ratio`),
/// both of density 1.
inline dem::SpeciesTable two_size_species(double ratio) {
    return dem::SpeciesTable({{"small", 1.0, 1.0}, {"large", 1.0, ratio}});
}

/// A loose bed of two sizes without overlaps: random sequential addition in [0, l)^2 x
/// [0, height) (periodic in x, y), the large spheres first, each placed at the first of up to
/// 10,000 random trials that touches nothing; standard-normal velocities times `speed`. At a
/// solid fraction up to ~0.3 every sphere finds a place (a test error otherwise).
inline dem::Particles two_size_loose_bed(int n_small, int n_large, double ratio, double l,
                                         double height, std::uint32_t seed, double speed = 0.1) {
    const auto species = two_size_species(ratio);
    std::mt19937 gen(seed);
    std::uniform_real_distribution<double> u(0, 1);
    std::normal_distribution<double> nv(0, 1);
    dem::Particles p;
    const dem::Domain box{l, l};
    for (int i = 0; i < n_small + n_large; ++i) {
        const auto s = static_cast<dem::SpeciesId>(i < n_large ? 1 : 0);
        const double r = species.radius(s);
        for (int trial = 0;; ++trial) {
            if (trial == 10000) throw std::logic_error("two_size_loose_bed: no room left");
            const Vec3 x{l * u(gen), l * u(gen), r + (height - 2 * r) * u(gen)};
            bool free = true;
            for (std::size_t j = 0; j < p.size() && free; ++j) {
                const double reach = r + p.radius()[j];
                free = norm2(box.minimum_image(x - p.x()[j])) >= reach * reach;
            }
            if (!free) continue;
            p.add(i + 1, x, Vec3{nv(gen), nv(gen), nv(gen)} * speed, s, species);
            break;
        }
    }
    return p;
}

/// A scene table from text (file name "test.cfg").
inline ParamTable scene_table(const std::string& text) {
    return ParamTable::from_text(text, "test.cfg", EFDEM_SOURCE_DIR);
}

/// The system's gas_drag effect, to change U_s mid-run (a test error if the scene has none).
inline dem::GasDrag& gas_effect(dem::System& s) {
    for (const auto& e : s.effects())
        if (auto* g = dynamic_cast<dem::GasDrag*>(e.get())) return *g;
    throw std::logic_error("the system has no gas_drag effect");
}

}  // namespace efdem::test
