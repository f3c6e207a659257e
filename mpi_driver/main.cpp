// efdem: wiring only. Parse the command line, read the scene collectively, build this rank's
// realizations, then hand over to the driver of the chosen mode.
#include <cstdio>
#include <exception>

#include "core/error.hpp"
#include "core/log.hpp"
#include "core/version.hpp"
#include "dem/effect_registry.hpp"
#include "dem/scene.hpp"
#include "mpi_driver/check_report.hpp"
#include "mpi_driver/mpi_broadcast.hpp"
#include "mpi_driver/mpi_session.hpp"
#include "mpi_driver/run_options.hpp"
#include "mpi_driver/run_settings.hpp"
#include "mpi_driver/scene_input.hpp"

using namespace efdem;
using namespace efdem::mpi_driver;

namespace {
void print_effects() {
    std::printf("effects a scene can list (effects = name name ...):\n");
    for (const auto& e : dem::effect_registry().entries())
        std::printf("  %-16.*s %.*s\n", static_cast<int>(e.name.size()), e.name.data(),
                    static_cast<int>(e.summary.size()), e.summary.data());
    std::printf("documentation: docs/effects/<name>.md\n");
}
}  // namespace

int main(int argc, char** argv) {
    MpiSession mpi(&argc, &argv);
    log::configure(mpi.rank(), mpi.size(), log::Level::info);

    RunOptions options;
    try {
        options = RunOptions::parse(argc, argv);
    } catch (const InputError& e) {
        if (mpi.is_root()) log::error("{}", e.what());
        return kExitInputError;
    }
    switch (options.action) {
        case RunOptions::Action::help:
            if (mpi.is_root()) std::printf("%s", RunOptions::usage().c_str());
            return kExitOk;
        case RunOptions::Action::version:
            if (mpi.is_root())
                std::printf("efdem %s (git %s; %s)\n", version().c_str(), git_hash().c_str(),
                            build_info().c_str());
            return kExitOk;
        case RunOptions::Action::list_effects:
            if (mpi.is_root()) print_effects();
            return kExitOk;
        default: break;
    }
    if (const std::string mismatch = mpi.launcher_mismatch(); !mismatch.empty()) {
        log::error("{}", mismatch);
        return kExitInputError;
    }

    // Set-up: every rank reads the same scene and builds its realizations. Failures are agreed
    // on collectively, so that all ranks stop together and the root prints one message.
    const bool check = options.action == RunOptions::Action::check;
    int code = kExitOk;
    std::string message;
    std::optional<ParamTable> table;
    std::optional<RunSettings> settings;
    std::vector<dem::System> systems;
    try {
        table.emplace(read_scene(mpi, options.scene, options.overrides));
        Params root = table->root();
        settings = RunSettings::from_params(root);
        const int k = check ? 1 : settings->realizations_per_rank;
        const std::vector<std::string> effect_names = root.get<std::vector<std::string>>("effects");
        for (int j = 0; j < k; ++j) {
            const long realization = check ? 0 : static_cast<long>(mpi.rank()) * k + j;
            systems.push_back(dem::build_system(root, {settings->seed, realization, check}));
        }
        table->check_all_used(
            [&](const ParamEntry& e) { return dem::unused_key_hint(e, effect_names); });
    } catch (const InputError& e) {
        code = kExitInputError;
        message = e.what();
    } catch (const RuntimeFailure& e) {
        code = kExitRuntimeFailure;
        message = e.what();
    } catch (const std::exception& e) {
        code = kExitRuntimeFailure;
        message = std::string("unexpected failure during set-up: ") + e.what();
    }
    const Agreement agreed = agree_on_failure(mpi.comm(), code, message);
    if (agreed.exit_code != kExitOk) {
        if (mpi.is_root()) log::error("{}", agreed.message);
        return agreed.exit_code;
    }
    if (check) {
        if (mpi.is_root())
            std::printf("%s", check_report(*table, *settings, systems.front(), mpi.size()).c_str());
        return kExitOk;
    }
    if (mpi.is_root())
        log::error("modes 'direct' and 'cpi' are not available in this build yet; use --check");
    return kExitInputError;
}
