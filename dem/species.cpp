#include "dem/species.hpp"

#include <algorithm>
#include <cctype>
#include <numbers>

#include "core/contracts.hpp"
#include "core/param_table.hpp"

namespace efdem::dem {

SpeciesTable::SpeciesTable(std::vector<Species> species) : species_(std::move(species)) {
    EFDEM_EXPECTS(!species_.empty() && species_.size() <= 255);
}

namespace {
bool valid_name(const std::string& name) {
    if (name.empty() || name.size() > 32) return false;
    return std::all_of(name.begin(), name.end(), [](char c) {
        return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-';
    });
}
}  // namespace

SpeciesTable SpeciesTable::from_params(const Params& p) {
    const auto names = p.get<std::vector<std::string>>("names");
    const auto density = p.get<std::vector<double>>("density", kDensityRange);
    const auto diameter = p.get<std::vector<double>>("diameter", kDiameterRange);
    if (names.size() > 255) p.fail("names", "lists more than 255 species", "1 to 255 names");
    for (const auto& name : names)
        if (!valid_name(name))
            p.fail("names", "has the name '" + quote_for_message(name) + "'",
                   "words of 1 to 32 letters, digits, '_' or '-' (they name output columns)");
    for (std::size_t i = 0; i < names.size(); ++i)
        for (std::size_t j = 0; j < i; ++j)
            if (names[i] == names[j])
                p.fail("names", "lists '" + quote_for_message(names[i]) + "' twice",
                       "distinct names");
    const std::string count = std::to_string(names.size());
    if (density.size() != names.size())
        p.fail("density",
               "has " + std::to_string(density.size()) + " values for " + count + " species",
               "one density per name in species.names");
    if (diameter.size() != names.size())
        p.fail("diameter",
               "has " + std::to_string(diameter.size()) + " values for " + count + " species",
               "one diameter per name in species.names");
    std::vector<Species> out;
    for (std::size_t i = 0; i < names.size(); ++i)
        out.push_back({names[i], density[i], diameter[i]});
    return SpeciesTable(std::move(out));
}

int SpeciesTable::find(const std::string& name) const {
    for (std::size_t i = 0; i < species_.size(); ++i)
        if (species_[i].name == name) return static_cast<int>(i);
    return -1;
}

double SpeciesTable::mass(SpeciesId s) const {
    const double d = species_[s].diameter;
    return species_[s].density * std::numbers::pi * d * d * d / 6.0;
}

double SpeciesTable::max_diameter() const {
    double d = 0.0;
    for (const auto& s : species_) d = std::max(d, s.diameter);
    return d;
}

double SpeciesTable::min_mass() const {
    double m = mass(0);
    for (std::size_t s = 1; s < species_.size(); ++s)
        m = std::min(m, mass(static_cast<SpeciesId>(s)));
    return m;
}

}  // namespace efdem::dem
