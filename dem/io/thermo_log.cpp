#include "dem/io/thermo_log.hpp"

#include <fmt/format.h>

#include "core/error.hpp"

namespace efdem::dem {

ThermoLog::ThermoLog(const std::filesystem::path& file) : file_(std::fopen(file.string().c_str(), "w")) {
    if (!file_) throw RuntimeFailure("cannot open the thermo log " + file.string() + " for writing");
    fmt::print(file_, "# efdem thermo log; units: d_p, sqrt(d_p/g), rho_s g d_p^4\n"
                      "# {:>10} {:>12} {:>12} {:>12} {:>10} {:>8} {:>11} {:>8}\n",
               "step", "time", "ke_trans/N", "ke_rot/N", "contacts/N", "wall", "max_overlap", "builds");
}

ThermoLog::~ThermoLog() {
    if (file_) std::fclose(file_);
}

void ThermoLog::write(const System& s) {
    const ThermoStats st = s.thermo_stats();
    const double n = static_cast<double>(std::max<std::size_t>(1, s.particles().size()));
    fmt::print(file_, "  {:>10} {:>12.6f} {:>12.5e} {:>12.5e} {:>10.4f} {:>8} {:>11.4e} {:>8}\n",
               s.step_count(), s.time(), s.translational_kinetic_energy() / n,
               s.rotational_kinetic_energy() / n, static_cast<double>(st.contacts) / n,
               st.wall_contacts, st.max_overlap, s.neighbor_list() ? s.neighbor_list()->builds() : 0);
    std::fflush(file_);
}

}  // namespace efdem::dem
