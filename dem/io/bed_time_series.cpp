#include "dem/io/bed_time_series.hpp"

#include <fmt/format.h>

#include "core/error.hpp"
#include "dem/beds/bed_diagnostics.hpp"

namespace efdem::dem {

BedTimeSeries::BedTimeSeries(const std::filesystem::path& file, const System& s)
    : file_(std::fopen(file.string().c_str(), "w")) {
    if (!file_)
        throw RuntimeFailure("cannot open the bed time series " + file.string() + " for writing");
    fmt::print(file_, "step,time,pressure_drop,weight_per_area,bed_height,z_com");
    for (std::size_t k = 0; k < s.species().size(); ++k)
        fmt::print(file_, ",z_com_{}", s.species()[static_cast<SpeciesId>(k)].name);
    fmt::print(file_, ",ke_per_particle\n");
    std::fflush(file_);
}

BedTimeSeries::~BedTimeSeries() {
    if (file_) std::fclose(file_);
}

void BedTimeSeries::write(const System& s) {
    const Particles& p = s.particles();
    fmt::print(file_, "{},{:.10g},{:.10g},{:.10g},{:.10g},{:.10g}", s.step_count(), s.time(),
               pressure_drop(s), weight_per_area(p, s.domain()), bed_height(p),
               center_of_mass_height(p));
    for (std::size_t k = 0; k < s.species().size(); ++k)
        fmt::print(file_, ",{:.10g}", center_of_mass_height(p, static_cast<int>(k)));
    const double n = static_cast<double>(std::max<std::size_t>(1, p.size()));
    fmt::print(file_, ",{:.10g}\n", s.kinetic_energy() / n);
    std::fflush(file_);
}

}  // namespace efdem::dem
