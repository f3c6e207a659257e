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
        fmt::print(file_, "# efdem thermo log; units: d_p, sqrt(d_p/g), rho_s g d_p^4\n"
                      "# {:>10} {:>12} {:>12} {:>12} {:>10} {:>8} {:>11} {:>8}\n",
               "step", "time", "ke_trans/N", "ke_rot/N", "contacts/N", "wall", "max_overlap", "builds");
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
        fmt::print(file_, "  {:>10} {:>12.6f} {:>12.5e} {:>12.5e} {:>10.4f} {:>8} {:>11.4e} {:>8}\n",
                   s.step_count(), s.time(), s.translational_kinetic_energy() / n,
                   s.rotational_kinetic_energy() / n, static_cast<double>(st.contacts) / n,
                   st.wall_contacts, st.max_overlap, s.neighbor_list() ? s.neighbor_list()->builds() : 0);
    } catch (const std::system_error& e) {
        throw RuntimeFailure(io_failure_message(path_, "the thermo log", e.code().value()));
    }
    flush_or_fail(file_, path_, "the thermo log");
}

}  // namespace efdem::dem
