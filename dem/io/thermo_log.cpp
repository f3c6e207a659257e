#include "dem/io/thermo_log.hpp"

#include <cerrno>

#include <fmt/format.h>

#include <system_error>

#include "core/error.hpp"
#include "core/io_error.hpp"

namespace efdem::dem {

ThermoLog::ThermoLog(const std::filesystem::path& file)
    : file_(std::fopen(file.string().c_str(), "w")), path_(file) {
    if (!file_) throw RuntimeFailure(io_failure_message(file, "the thermo log", errno));
    try {
        fmt::print(file_,
                   "step,time,ke_trans_per_particle,ke_rot_per_particle,contacts_per_particle,"
                   "wall_contacts,max_overlap,neighbor_builds\n");
    } catch (const std::system_error& e) {
        throw RuntimeFailure(io_failure_message(path_, "the thermo log", e.code().value()));
    }
    flush_or_fail(file_, path_, "the thermo log");
}

ThermoLog::~ThermoLog() {
    if (file_) std::fclose(file_);
}

void ThermoLog::write(const System& s) {
    const ThermoStats st = s.thermo_stats();
    const double n = static_cast<double>(std::max<std::size_t>(1, s.particles().size()));
    try {
        fmt::print(file_, "{},{:.10g},{:.10g},{:.10g},{:.10g},{},{:.10g},{}\n", s.step_count(),
                   s.time(), s.translational_kinetic_energy() / n,
                   s.rotational_kinetic_energy() / n, static_cast<double>(st.contacts) / n,
                   st.wall_contacts, st.max_overlap,
                   s.neighbor_list() ? s.neighbor_list()->builds() : 0);
    } catch (const std::system_error& e) {
        throw RuntimeFailure(io_failure_message(path_, "the thermo log", e.code().value()));
    }
    flush_or_fail(file_, path_, "the thermo log");
}

}  // namespace efdem::dem
