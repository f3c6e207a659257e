// The limits a scene must respect (docs/stability.md, "Limits"), each refused at set-up with a
// message that names the key and what is allowed. Most were found by scripts/fuzz_scenes.py:
// before, these inputs crashed `efdem --check` (bad_alloc, undefined conversions), hung it, or
// were accepted and failed only at run time.
#include <catch2/catch.hpp>

#include <filesystem>
#include <fstream>
#include <numbers>

#include "dem/realization_builder.hpp"
#include "tests/support/dem_fixtures.hpp"

using namespace efdem;
using namespace efdem::dem;

namespace {
const std::string kScene =
    test::kSmallBinaryScene + "effects = gravity pair_contact wall_contact\n";

/// Builds a realization of kScene with `overrides` (key=value, in order) and returns the
/// InputError it must raise.
InputError refusal(const std::vector<std::string>& overrides, const std::string& extra = {}) {
    auto t = test::scene_table(kScene + extra);
    for (const auto& o : overrides) t.add_override(o);
    try {
        build_system(t.root(), {1, 0, true});
    } catch (const InputError& e) {
        return e;
    }
    FAIL("expected an InputError");
    throw std::logic_error("unreachable");
}
}  // namespace

TEST_CASE("box lengths beyond 1e6 d_p are refused", "[unit][limits]") {
    const auto e = refusal({"domain.lx=1e7", "domain.ly=1e7"});
    CHECK(e.key() == "domain.lx");
    CHECK(e.allowed() == "a finite real number in (0, 1000000]");
    CHECK(refusal({"domain.lid=2e6"}).key() == "domain.lid");
}

TEST_CASE("species beyond three decades of the reference, or with unusable names, are refused",
          "[unit][limits]") {
    // A diameter in metres (1e-4) is the typical mistake; it would also make m_eff underflow.
    const auto d = refusal({"species.diameter=1e-4 1"});
    CHECK(d.key() == "species.diameter");
    CHECK(d.problem() == "element '1e-4' is out of range");
    CHECK(d.allowed() == "one or more finite real numbers in [0.001, 1000]");
    CHECK(refusal({"species.density=1 2000"}).allowed().find("[0.001, 1000]") != std::string::npos);
    const auto n = refusal({"species.names=light \"he avy\""});
    CHECK(n.problem() == "has the name 'he avy'");
}

TEST_CASE("a bed of more than 1e6 particles is refused before anything is allocated",
          "[unit][limits]") {
    // Without a lid nothing else stops bed.count = 1e9: it would ask for ~170 GB.
    const auto e = refusal({"bed.count=1e9 1"});
    CHECK(e.key() == "bed.count");
    CHECK(e.problem() == "adds up to 1e+09 particles, more than one realization may hold");
    CHECK(e.allowed() == "whole numbers >= 0 adding up to 1 .. 1000000 particles");
    CHECK(refusal({"bed.count=2.5 1"}).problem() == "is not a list of whole numbers");
}

TEST_CASE("lattice geometry: spacing wider than the box, a lattice taller than 1e6",
          "[unit][limits]") {
    // bed.spacing = 100 in a 4-wide box made one site per row with the jitter bound computed
    // from 100: jitter up to 49 then put spheres on top of each other.
    const auto s = refusal({"bed.spacing=100"});
    CHECK(s.key() == "bed.spacing");
    CHECK(s.allowed() == "a finite real number in [1, 4]");
    // 1e6 particles, 9 per layer of height 1.33: a column 1.5e5 high is fine; with spacing 4
    // (one per layer) it would be 4e6 high.
    const auto h = refusal({"bed.count=500000 500000", "bed.spacing=4"});
    CHECK(h.key() == "bed.count");
    CHECK(h.problem().find("needs a lattice 4e+06 high") != std::string::npos);
}

TEST_CASE("settling stages longer than 1e9 steps are refused (efdem --check reports them)",
          "[unit][limits]") {
    const auto e = refusal({"bed.settle=true", "bed.settle.max_time=1e300"});
    CHECK(e.key() == "bed.settle.max_time");
    CHECK(e.problem() == "makes a settling stage of 1e+304 steps of dt = 0.0001");
    CHECK(e.allowed() == "at most 1000000000 steps per settling stage, i.e. <= 1e+05 time units");
    CHECK(refusal({"bed.settle=true", "bed.settle.damped_time=2e5"}).key() ==
          "bed.settle.damped_time");
}

TEST_CASE("hertz restitution below 0.01 is refused (Tsuji's damping search would crawl)",
          "[unit][limits]") {
    // Found by the fuzzer: e = 2e-308 made efdem --check search for over a minute.
    const auto e = refusal({"pair_contact.normal=hertz", "pair_contact.restitution=0.001"});
    CHECK(e.key() == "pair_contact.restitution");
    CHECK(e.allowed() == "a finite real number in [0.01, 1]");
}

TEST_CASE("strong damping: the time step limit follows the damping time 2 pi m_eff/eta_n",
          "[unit][limits]") {
    // Before, an overdamped contact reported its slow relaxation time as t_c, so dt = t_c/5
    // allowed steps with dt eta_n/m_eff >> 2, where the explicit damping step overshoots.
    ContactSpec spec = test::paper_contact(DampingModel::gamma, TangentialModel::none);
    const SpeciesTable species = test::binary_species();
    const double m_eff = species.mass(0) / 2;
    const double omega0 = std::sqrt(spec.kn / m_eff);
    SECTION("e = 0.9: the contact duration, as before") {
        const ContactTable t(spec, species, ContactTable::Partner::particle);
        CHECK(t.info()[0].contact_time == Approx(3.596e-3).epsilon(1e-3));
    }
    SECTION("zeta = 3 (overdamped): 2 pi m_eff/eta_n") {
        spec.gamma_n = 2 * 3.0 * omega0;  // gamma_n = eta_n/m_eff = 2 zeta omega0
        const ContactTable t(spec, species, ContactTable::Partner::particle);
        CHECK(t.info()[0].restitution == 0);
        CHECK(t.info()[0].contact_time == Approx(2 * std::numbers::pi / spec.gamma_n));
    }
    SECTION("zeta = 0.99: damping time, not the diverging contact duration") {
        spec.gamma_n = 2 * 0.99 * omega0;
        const ContactTable t(spec, species, ContactTable::Partner::particle);
        CHECK(t.info()[0].contact_time == Approx(2 * std::numbers::pi / spec.gamma_n));
    }
}

TEST_CASE("an initial bed beyond the overlap limit is refused at set-up, naming bed.file",
          "[unit][limits]") {
    // The health check stops a run whose largest overlap exceeds 0.1 of the pair's diameter
    // sum. A bed that starts beyond it would be stopped after the first 1000 steps; it is
    // refused before anything is computed. 0.08 (below the limit) is accepted.
    auto data_file = [](const std::string& name, double gap) {
        const auto path = std::filesystem::temp_directory_path() / name;
        std::ofstream(path) << "title\n\n2 atoms\n2 atom types\n\n0 4 xlo xhi\n0 4 ylo yhi\n"
                               "0 10 zlo zhi\n\nAtoms # sphere\n\n"
                            << "1 1 1 1 1 2 2\n2 1 1 1 " << 1 + gap << " 2 2\n";
        return path.string();
    };
    const std::string extra = "bed.source = lammps_data\n";
    const auto e = refusal({"bed.file=" + data_file("efdem_overlap.data", 0.75)}, extra);
    CHECK(e.key() == "bed.file");
    CHECK(e.problem() ==
          "starts with an overlap of 0.25 diameters, beyond the limit of 0.1 at which the health "
          "check stops a run");
    auto t = test::scene_table(kScene + extra);
    t.add_override("bed.file=" + data_file("efdem_overlap_ok.data", 0.92));
    CHECK_NOTHROW(build_system(t.root(), {1, 0, true}));
}
