#include "mpi_driver/ensemble/ensemble_sampler.hpp"

#include <cmath>
#include <limits>

#include <mpi.h>

#include "core/contracts.hpp"
#include "mpi_driver/ensemble/reference_rows.hpp"

namespace efdem::mpi_driver {

namespace {
/// Per realization and sample: centre of mass, lowest and highest centre, mean height, at rest.
constexpr Eigen::Index kScalars = 10;

/// The rows of `all` listed in `rows` (all rows when every realization is in the ensemble).
Eigen::MatrixXd rows_of(const Eigen::MatrixXd& all, const std::vector<Eigen::Index>& rows) {
    if (all.size() == 0 || static_cast<Eigen::Index>(rows.size()) == all.rows()) return all;
    Eigen::MatrixXd out(static_cast<Eigen::Index>(rows.size()), all.cols());
    for (std::size_t k = 0; k < rows.size(); ++k)
        out.row(static_cast<Eigen::Index>(k)) = all.row(rows[k]);
    return out;
}

/// Rows of packed dem::BedObservation, as the recorders see them.
BedRecord bed_record(const Eigen::MatrixXd& packed, const dem::BedObservationSettings& settings) {
    const Eigen::Index n = packed.rows();
    BedRecord b;
    b.pressure_drop.resize(n);
    b.pressure_drop_ratio.resize(n);
    b.height.resize(n);
    b.mixing_index.resize(n);
    b.species_height.resize(n, static_cast<Eigen::Index>(settings.species));
    b.solid_fraction.resize(n, static_cast<Eigen::Index>(settings.profile_slabs));
    for (Eigen::Index r = 0; r < n; ++r) {
        const Eigen::VectorXd row = packed.row(r).transpose();
        const dem::BedObservation o = dem::BedObservation::unpack(
            {row.data(), static_cast<std::size_t>(row.size())}, settings);
        b.pressure_drop[r] = o.pressure_drop;
        b.pressure_drop_ratio[r] = o.pressure_drop_ratio;
        b.height[r] = o.height;
        b.mixing_index[r] = o.mixing_index;
        b.species_height.row(r) =
            Eigen::Map<const Eigen::RowVectorXd>(o.species_height.data(), b.species_height.cols());
        b.solid_fraction.row(r) =
            Eigen::Map<const Eigen::RowVectorXd>(o.solid_fraction.data(), b.solid_fraction.cols());
    }
    return b;
}
}  // namespace

EnsembleSampler::EnsembleSampler(const EnsembleLayout& layout, const SamplingSettings& settings,
                                 coarse::EnsembleObservable& observable)
    : layout_(layout), settings_(settings), observable_(&observable), grid_(settings.quantiles) {}

ReferenceNeeds EnsembleSampler::needs() const {
    const ReferenceNeeds own = ReferenceNeeds::of(observable_->reference());
    return settings_.recorded ? own | ReferenceNeeds::of(settings_.recorded->reference()) : own;
}

const SampleRecord* EnsembleSampler::take(const Realizations& local,
                                          const std::vector<char>& active, double time,
                                          ReferenceNeeds needs, coarse::BurstSamples* out) {
    EFDEM_EXPECTS(static_cast<int>(active.size()) == layout_.size());
    const double start = MPI_Wtime();
    const auto m = static_cast<Eigen::Index>(grid_.values().size());
    const double nan = std::numeric_limits<double>::quiet_NaN();
    const auto bed_width =
        settings_.bed ? static_cast<Eigen::Index>(dem::BedObservation::packed_size(*settings_.bed))
                      : 0;
    std::vector<Eigen::VectorXd> icdf, scalars, bed;
    ReferenceRows references(needs, m);
    for (const auto& r : local) {
        if (!active[static_cast<std::size_t>(r->index())]) {
            // Dropped: a row of NaN in the record, not in the means.
            icdf.push_back(Eigen::VectorXd::Constant(m, nan));
            references.add_missing();
            scalars.push_back(Eigen::VectorXd::Constant(kScalars, nan));
            if (bed_width > 0) bed.push_back(Eigen::VectorXd::Constant(bed_width, nan));
            continue;
        }
        Observation o = r->observe(grid_, needs);
        icdf.push_back(std::move(o.icdf));
        references.add(o);
        Eigen::VectorXd row(kScalars);
        const ThermoNumbers& th = o.thermo;
        row << o.com, o.z_min, o.z_max, o.mean_height, r->at_rest() ? 1.0 : 0.0,
            o.observed_fraction, th.ke_per_particle, th.contacts_per_particle, th.max_overlap,
            th.neighbor_builds;
        scalars.push_back(std::move(row));
        if (bed_width > 0) {
            EFDEM_ASSERT(static_cast<Eigen::Index>(o.bed.size()) == bed_width);
            bed.push_back(Eigen::Map<const Eigen::VectorXd>(o.bed.data(), bed_width));
        }
    }
    const Eigen::MatrixXd all_icdf = layout_.gather_rows(icdf);
    references.gather(layout_);
    const Eigen::MatrixXd all_scalar_rows = layout_.gather_rows(scalars);
    const Eigen::MatrixXd all_bed_rows =
        bed_width > 0 ? layout_.gather_rows(bed) : Eigen::MatrixXd();
    if (!layout_.is_root()) {
        seconds_ += MPI_Wtime() - start;
        ++count_;
        return nullptr;
    }
    std::vector<Eigen::Index> in;
    for (std::size_t r = 0; r < active.size(); ++r)
        if (active[r]) in.push_back(static_cast<Eigen::Index>(r));
    const Eigen::MatrixXd used_icdf = rows_of(all_icdf, in);
    // The reference rows of the realizations in use, for `observable` (rows of nothing for none).
    auto reference_of = [&](const coarse::EnsembleObservable& observable) {
        return rows_of(references.rows(observable.reference()), in);
    };
    const Eigen::MatrixXd all_top = rows_of(references.rows(coarse::ReferenceIcdf::top_half), in);
    const Eigen::MatrixXd all_scalars = rows_of(all_scalar_rows, in);

    SampleRecord& rec = last_;
    rec.time = time;
    rec.realizations = all_icdf;
    rec.realizations_used = static_cast<int>(in.size());
    rec.mean = coarse::ensemble_mean(used_icdf);
    rec.variance = coarse::ensemble_variance(used_icdf, rec.mean);
    rec.com = all_scalar_rows.col(0);
    rec.at_rest = all_scalar_rows.col(4);
    rec.thermo = all_scalar_rows.rightCols(4);
    if (settings_.bed) {
        rec.bed = bed_record(all_bed_rows, *settings_.bed);
        rec.bed_mean = bed_record(coarse::ensemble_mean(rows_of(all_bed_rows, in)).transpose(),
                                  *settings_.bed);
    }
    rec.top_mean = needs.top_half ? coarse::ensemble_mean(all_top) : Eigen::VectorXd();
    height_range_ = {all_scalars.col(1).minCoeff(), all_scalars.col(2).maxCoeff()};
    // The largest share among the realizations (they are equal: a lift keeps the counts): the
    // one whose intervals fill with lights first.
    double fraction = std::numeric_limits<double>::quiet_NaN();
    for (Eigen::Index r = 0; r < all_scalars.rows(); ++r)
        if (std::isfinite(all_scalars(r, 5)) &&
            (std::isnan(fraction) || all_scalars(r, 5) > fraction))
            fraction = all_scalars(r, 5);
    observable_->set_observed_fraction(fraction);
    const Eigen::MatrixXd own_reference = reference_of(*observable_);
    const Eigen::VectorXd x = observable_->restrict_ensemble(used_icdf, own_reference);
    last_x_ = x;
    // The compact fit is recorded: the integrator's X when it is the compact one, else the
    // recorded observable's.
    const bool compact = observable_->reference() == coarse::ReferenceIcdf::top_half;
    rec.compact = compact ? x : Eigen::VectorXd();
    rec.compact_status = compact ? observable_->status() : 0;
    if (!compact && settings_.recorded) {
        rec.compact =
            settings_.recorded->restrict_ensemble(used_icdf, reference_of(*settings_.recorded));
        rec.compact_status = settings_.recorded->status();
    }
    if (out) {
        out->t.push_back(rec.time);
        out->x.push_back(x);
        out->phase_signal.push_back(coarse::ensemble_mean(all_scalars)[0]);
        out->member_phase.push_back(all_scalars.col(0));
        out->member_expansion.push_back(all_scalars.col(3));
        // Rows in global realization order, as gathered: independent of the layout.
        if (observable_->restricts_members())
            out->members.push_back(observable_->restrict_members(used_icdf, own_reference));
    }
    seconds_ += MPI_Wtime() - start;
    ++count_;
    return &rec;
}

void EnsembleSampler::save(StepperState& s) const {
    s.height_lo = height_range_.first;
    s.height_hi = height_range_.second;
    s.observable = observable_->saved_state();
    if (settings_.recorded) s.recorded = settings_.recorded->saved_state();
}

void EnsembleSampler::restore(const StepperState& s) {
    height_range_ = {s.height_lo, s.height_hi};
    if (!layout_.is_root()) return;
    observable_->restore_state(s.observable);
    if (settings_.recorded) settings_.recorded->restore_state(s.recorded);
}

}  // namespace efdem::mpi_driver
