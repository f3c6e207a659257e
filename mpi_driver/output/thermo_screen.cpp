#include "mpi_driver/output/thermo_screen.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "core/contracts.hpp"
#include "core/log.hpp"

namespace efdem::mpi_driver {

namespace {
constexpr const char* kColumns =
    "        Time   KinEng/N  Contacts/N  MaxOverlap  NeighBuilds  Realizations";
}  // namespace

std::string thermo_header(double interval, int realizations) {
    return fmt::format(
        "thermo every {:g}: mean over the {} realization{} in the ensemble (KinEng/N in rho_s g "
        "d_p^4; MaxOverlap: the largest, per pair diameter; NeighBuilds: builds so far)\n{}",
        interval, realizations, realizations == 1 ? "" : "s", kColumns);
}

std::string thermo_line(const SampleRecord& s) {
    double ke = 0, contacts = 0, overlap = 0, builds = 0;
    int used = 0;
    for (Eigen::Index r = 0; r < s.thermo.rows(); ++r) {
        if (std::isnan(s.thermo(r, 0))) continue;  // dropped, or not measured
        ke += s.thermo(r, 0);
        contacts += s.thermo(r, 1);
        overlap = std::max(overlap, s.thermo(r, 2));
        builds += s.thermo(r, 3);
        ++used;
    }
    if (used == 0) return "";
    const double n = used;
    return fmt::format("{:12.4f} {:10.4e} {:11.4f} {:11.4e} {:12.1f} {:13d}", s.time, ke / n,
                       contacts / n, overlap, builds / n, used);
}

ThermoScreen::ThermoScreen(double interval, int realizations)
    : interval_(interval), realizations_(realizations) {
    EFDEM_EXPECTS(interval > 0 && realizations > 0);
}

void ThermoScreen::sample(const SampleRecord& s) {
    const std::string lines = lines_for(s);
    if (!lines.empty()) log::info("{}", lines);
}

std::string ThermoScreen::lines_for(const SampleRecord& s) {
    // Samples fall on multiples of observe.interval, of which the interval is a multiple; the
    // slack absorbs the rounding of accumulated sample times. The first line comes at the first
    // multiple of the interval (a run's first sample is one sample interval after its start).
    const double slack = 1e-9 * interval_;
    if (std::isnan(next_)) next_ = std::ceil(s.time / interval_ - 1e-9) * interval_;
    if (s.time < next_ - slack) return "";
    std::string line = thermo_line(s);
    if (line.empty()) return "";
    next_ = (std::floor(s.time / interval_ + 1e-9) + 1) * interval_;
    if (header_printed_) return line;
    header_printed_ = true;
    return thermo_header(interval_, realizations_) + "\n" + line;
}

}  // namespace efdem::mpi_driver
