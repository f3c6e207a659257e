#include "dem/particles.hpp"

#include "core/contracts.hpp"

namespace efdem::dem {

void Particles::reserve(std::size_t n) {
    x_.reserve(n);
    v_.reserve(n);
    omega_.reserve(n);
    f_.reserve(n);
    torque_.reserve(n);
    radius_.reserve(n);
    mass_.reserve(n);
    inv_mass_.reserve(n);
    inertia_.reserve(n);
    inv_inertia_.reserve(n);
    species_.reserve(n);
    tag_.reserve(n);
}

void Particles::add(Tag tag, const Vec3& position, const Vec3& velocity, SpeciesId species,
                    const SpeciesTable& table) {
    EFDEM_EXPECTS(species < table.size());
    x_.push_back(position);
    v_.push_back(velocity);
    omega_.push_back({});
    f_.push_back({});
    torque_.push_back({});
    radius_.push_back(0.0);
    mass_.push_back(0.0);
    inv_mass_.push_back(0.0);
    inertia_.push_back(0.0);
    inv_inertia_.push_back(0.0);
    species_.push_back(species);
    tag_.push_back(tag);
    set_species(static_cast<Index>(size() - 1), species, table);
}

void Particles::set_species(Index i, SpeciesId species, const SpeciesTable& table) {
    EFDEM_EXPECTS(i < size() && species < table.size());
    species_[i] = species;
    radius_[i] = table.radius(species);
    mass_[i] = table.mass(species);
    inv_mass_[i] = 1.0 / mass_[i];
    inertia_[i] = table.inertia(species);
    inv_inertia_[i] = 1.0 / inertia_[i];
}

namespace {
template <class T>
void permute_array(std::vector<T>& a, std::span<const Index> new_to_old, std::vector<T>& scratch) {
    scratch.resize(a.size());
    for (std::size_t k = 0; k < a.size(); ++k) scratch[k] = a[new_to_old[k]];
    a.swap(scratch);
}
}  // namespace

void Particles::permute(std::span<const Index> new_to_old) {
    EFDEM_EXPECTS(new_to_old.size() == size());
    std::vector<Vec3> sv;
    std::vector<double> sd;
    for (auto* a : {&x_, &v_, &omega_, &f_, &torque_}) permute_array(*a, new_to_old, sv);
    for (auto* a : {&radius_, &mass_, &inv_mass_, &inertia_, &inv_inertia_})
        permute_array(*a, new_to_old, sd);
    std::vector<SpeciesId> ss;
    permute_array(species_, new_to_old, ss);
    std::vector<Tag> st;
    permute_array(tag_, new_to_old, st);
}

void Particles::zero_forces() {
    std::fill(f_.begin(), f_.end(), Vec3{});
    std::fill(torque_.begin(), torque_.end(), Vec3{});
}

std::size_t Particles::bytes() const {
    return size() * (5 * sizeof(Vec3) + 5 * sizeof(double) + sizeof(SpeciesId) + sizeof(Tag));
}

}  // namespace efdem::dem
