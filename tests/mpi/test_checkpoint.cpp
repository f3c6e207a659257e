// Checkpoint pieces that need no file: a realization's saved state put into a freshly built
// realization continues bit for bit, and so does one put back after a sample cut by a stop;
// checksums see one changed bit; which scene keys a restart
// may change; checkpoint file names. (Whole-program restart tests: tests/scripts/restart_*.sh.)
#include <catch2/catch.hpp>

#include <cstring>
#include <limits>

#include "core/error.hpp"
#include "core/param_table.hpp"
#include "dem/realization_builder.hpp"
#include "mpi_driver/checkpoint/restart_check.hpp"
#include "mpi_driver/checkpoint_data/checkpoint_format.hpp"
#include "mpi_driver/ensemble/dem_realization.hpp"

using namespace efdem;
using namespace efdem::mpi_driver;

namespace {
constexpr const char* kScene = R"(effects = gravity pair_contact wall_contact gas_drag
dt = 1e-4
domain.lx = 4.28
domain.ly = 4.28
domain.lid = 60
species.names = light heavy
species.density = 1 2
species.diameter = 1 1
pair_contact.kn = 2e5
pair_contact.restitution = 0.9
pair_contact.mu = 0.1
gas_drag.superficial_velocity = 0.41
bed.count = 64 64
bed.settle = false
)";

DemRealization build(long realization) {
    ParamTable table = ParamTable::from_text(kScene, "checkpoint_test.cfg");
    dem::System sys = dem::build_system(table.root(), {3, realization, false});
    return DemRealization(std::move(sys), 0, 1, RealizationOutput{});
}

bool same_bits(const std::vector<Vec3>& a, const std::vector<Vec3>& b) {
    return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(Vec3)) == 0;
}
}  // namespace

TEST_CASE("a saved realization restored into a fresh one continues bit for bit",
          "[mpi][checkpoint]") {
    DemRealization original = build(2);
    original.advance(6000);  // falling, colliding, neighbour list rebuilt, springs loaded
    const RealizationState saved = original.save_state();
    REQUIRE_FALSE(saved.pairs.empty());
    DemRealization restored = build(2);
    restored.restore_state(saved);
    CHECK(restored.save_state().checksum() == saved.checksum());
    original.advance(4000);
    restored.advance(4000);
    const RealizationState a = original.save_state(), b = restored.save_state();
    CHECK(a.time == b.time);
    CHECK(a.step == b.step);
    CHECK(same_bits(a.x, b.x));
    CHECK(same_bits(a.v, b.v));
    CHECK(same_bits(a.omega, b.omega));
    CHECK(a.checksum() == b.checksum());
}

TEST_CASE("a sample cut by a stop goes back to its start and is then run bit for bit as uncut",
          "[mpi][checkpoint]") {
    // What a stop signal inside a sample does in a direct run (EnsembleStepper::do_run): the
    // realization asks every kStopCheckSteps steps, stops, and is put back to the sample's start.
    DemRealization uncut = build(1), cut = build(1);
    uncut.advance(3000);
    cut.advance(3000);
    const RealizationState start = cut.save_state();
    long asked = 0;
    const bool whole = cut.advance_unless_stopped(5000, [&asked] { return ++asked > 3; });
    CHECK_FALSE(whole);
    CHECK(asked == 4);  // asked before each chunk: three ran, the fourth was refused
    CHECK(cut.save_state().step == start.step + 3 * DemRealization::kStopCheckSteps);
    cut.restore_state(start);
    // Asked all through and never stopping: the same steps as one uninterrupted call.
    CHECK(cut.advance_unless_stopped(5000, [] { return false; }));
    uncut.advance(5000);
    const RealizationState a = uncut.save_state(), b = cut.save_state();
    CHECK(a.step == b.step);
    CHECK(same_bits(a.x, b.x));
    CHECK(same_bits(a.v, b.v));
    CHECK(a.checksum() == b.checksum());
}

TEST_CASE("a state that does not fit the realization is refused", "[mpi][checkpoint]") {
    DemRealization r = build(0);
    RealizationState s = r.save_state();
    SECTION("another realization") {
        s.index = 5;
        CHECK_THROWS_WITH(r.restore_state(s), Catch::Contains("holds realization 5"));
    }
    SECTION("another particle count") {
        s.x.pop_back();
        CHECK_THROWS_WITH(r.restore_state(s), Catch::Contains("the checkpoint has 127 particles"));
    }
    SECTION("an unknown tag") {
        s.tag[3] = 999999;
        CHECK_THROWS_WITH(r.restore_state(s), Catch::Contains("tag 999999"));
    }
}

TEST_CASE("the checksum of a realization sees one flipped bit", "[mpi][checkpoint]") {
    RealizationState s = build(1).save_state();
    const std::uint64_t before = s.checksum();
    std::uint64_t bits = 0;
    std::memcpy(&bits, &s.v[17].z, sizeof bits);
    bits ^= 1;
    std::memcpy(&s.v[17].z, &bits, sizeof bits);
    CHECK(s.checksum() != before);
    CHECK(from_stored(to_stored(before)) == before);
}

TEST_CASE("a restart may change run length, output and layout keys, not physics",
          "[mpi][checkpoint]") {
    for (const char* key : {"run.duration", "output.prefix", "checkpoint.interval",
                            "restart.allow_physics_change", "debug.checkpoint_delay",
                            "watchdog.max_overlap", "ensemble.realizations_per_rank", "cpi.finish"})
        CHECK(may_change_on_restart(key));
    for (const char* key : {"dt", "seed", "pair_contact.kn", "cpi.dt", "mode", "observe.interval"})
        CHECK_FALSE(may_change_on_restart(key));

    CheckpointHeader h;
    h.realizations = 4;
    h.parameters = "dt = 1e-4\npair_contact.kn = 2e5\nrun.duration = 6\n";
    CHECK(
        check_restart("c.h5", h, "dt = 1e-4\npair_contact.kn = 2e5\nrun.duration = 60\n", 4, false)
            .empty());
    CHECK_THROWS_WITH(
        check_restart("c.h5", h, "dt = 1e-4\npair_contact.kn = 3e5\nrun.duration = 6\n", 4, false),
        Catch::Contains("c.h5: checkpoint was written by a scene with different physics: "
                        "pair_contact.kn = 3e5 (checkpoint: 2e5)"));
    CHECK_THAT(check_restart("c.h5", h, "dt = 1e-4\npair_contact.kn = 3e5\n", 4, true),
               Catch::Contains("pair_contact.kn = 3e5 (checkpoint: 2e5)"));
    CHECK_THROWS_WITH(check_restart("c.h5", h, h.parameters, 2, false),
                      Catch::Contains("holds 4 realizations but this run has 2"));
    // Keys added since: absent from the checkpoint, accepted at what the runs before them did
    // (cpi.window_max: any value, it acts only with cpi.window_auto), refused otherwise with
    // that value named.
    CHECK(check_restart("c.h5", h,
                        h.parameters +
                            "cpi.slope = burst\ncpi.window_auto = false\ncpi.window_max = 80\n"
                            "cpi.noisy_curvature = counted\n",
                        4, false)
              .empty());
    CHECK_THROWS_WITH(
        check_restart("c.h5", h, h.parameters + "cpi.noisy_curvature = ignored\n", 4, false),
        Catch::Contains("cpi.noisy_curvature = ignored (not in the checkpoint, whose run did "
                        "cpi.noisy_curvature = counted)"));
    // The cpi block acts only in a cpi (or steady) run: a direct run continues from a checkpoint
    // written before a cpi key whatever its value (cpi.relabel_nodes = matched is not what such
    // checkpoints did), and with any cpi value changed; a cpi run only at the old behaviour.
    CheckpointHeader direct = h, cpi = h;
    direct.parameters += "mode = direct\ncpi.tolerance = 0.16\n";
    cpi.parameters += "mode = cpi\n";
    CHECK(check_restart("c.h5", direct, direct.parameters + "cpi.at_rest = hold\n", 4, false)
              .empty());
    CHECK(check_restart("c.h5", direct,
                        h.parameters + "mode = direct\ncpi.tolerance = 0.32\n"
                                       "cpi.relabel_nodes = matched\n",
                        4, false)
              .empty());
    CHECK(check_restart("c.h5", direct, h.parameters + "mode = direct\n", 4, false).empty());
    CHECK_THROWS_WITH(
        check_restart("c.h5", cpi, cpi.parameters + "cpi.relabel_nodes = matched\n", 4, false),
        Catch::Contains("cpi.relabel_nodes = matched (not in the checkpoint, whose run did "
                        "cpi.relabel_nodes = random)"));
    // Physics stays physics in a direct run.
    CHECK_THROWS_WITH(check_restart("c.h5", direct,
                                    "dt = 1e-4\npair_contact.kn = 3e5\nrun.duration = 6\n"
                                    "mode = direct\ncpi.tolerance = 0.16\n",
                                    4, false),
                      Catch::Contains("pair_contact.kn = 3e5 (checkpoint: 2e5)"));
    CHECK(check_restart("c.h5", cpi, cpi.parameters + "cpi.at_rest = lift\n", 4, false).empty());
    // A restart continues a run in its own mode, whatever restart.allow_physics_change says (a
    // direct checkpoint continued as cpi ended in an HDF5 error creating /cpi).
    for (const bool allow : {false, true})
        CHECK_THROWS_WITH(
            check_restart("c.h5", direct, h.parameters + "mode = cpi\n", 4, allow),
            Catch::Contains("c.h5") &&
                Catch::Contains("written by a mode = direct run and this run has mode = cpi") &&
                Catch::Contains("restart with mode = direct"));
    CHECK_THROWS_WITH(
        check_restart("c.h5", cpi, cpi.parameters + "cpi.at_rest = hold\n", 4, false),
        Catch::Contains("cpi.at_rest = hold (not in the checkpoint, whose run did cpi.at_rest = "
                        "lift)"));
}

TEST_CASE("a restart may end the jumps (cpi.jump_until) from its checkpoint on, not before it",
          "[mpi][checkpoint]") {
    // A cpi run from t = 10 checkpointed at t = 310 (300 units in): its jumps went on to 300 with
    // no key, to 250 with cpi.jump_until = 250. A new value is accepted when no jump made so far
    // broke it (>= min(old value, 300)), refused with the bound otherwise; without the
    // checkpoint's time it is physics like any other key.
    CheckpointHeader h;
    h.realizations = 4;
    h.driver.t_origin = 10.0;
    h.parameters = "mode = cpi\nrun.duration = 1000\n";
    const auto restart = [&](const std::string& then, const std::string& now, double t) {
        CheckpointHeader c = h;
        c.parameters += then;
        return check_restart("c.h5", c, h.parameters + now, 4, false, t);
    };
    CHECK(restart("", "cpi.jump_until = 300\n", 310.0).empty());  // stop jumping now
    CHECK(restart("", "cpi.jump_until = 400\n", 310.0).empty());
    CHECK(restart("cpi.jump_until = 250\n", "cpi.jump_until = 400\n", 310.0).empty());  // resume
    CHECK(restart("cpi.jump_until = 250\n", "", 310.0).empty());  // to the end
    CHECK(restart("cpi.jump_until = 400\n", "cpi.jump_until = 300\n", 310.0).empty());
    CHECK_THROWS_WITH(restart("", "cpi.jump_until = 250\n", 310.0),
                      Catch::Contains("c.h5") && Catch::Contains("cpi.jump_until = 250") &&
                          Catch::Contains("went on until 300") &&
                          Catch::Contains("cpi.jump_until >= 300"));
    CHECK_THROWS_WITH(restart("cpi.jump_until = 250\n", "cpi.jump_until = 200\n", 310.0),
                      Catch::Contains("cpi.jump_until >= 250"));
    CHECK_THROWS_WITH(
        restart("", "cpi.jump_until = 400\n", std::numeric_limits<double>::quiet_NaN()),
        Catch::Contains("different physics") &&
            Catch::Contains("cpi.jump_until = 400 (not in the checkpoint)"));
}

TEST_CASE("checkpoint file names sort in writing order and exclude .tmp files",
          "[mpi][checkpoint]") {
    CHECK(checkpoint_file_name("run", 12) == "run_ckpt_00000012.h5");
    CHECK(is_checkpoint_file_name("run_ckpt_00000012.h5", "run"));
    CHECK_FALSE(is_checkpoint_file_name("run_ckpt_00000012.h5.tmp", "run"));
    CHECK_FALSE(is_checkpoint_file_name("other_ckpt_00000012.h5", "run"));
    CHECK_FALSE(is_checkpoint_file_name("run_ckpt_0000001x.h5", "run"));
}
