#include "mpi_driver/ensemble/ensemble_snapshots.hpp"

#include <utility>

#include "core/contracts.hpp"

namespace efdem::mpi_driver {

std::vector<RealizationState> EnsembleSnapshots::save_realizations(const Realizations& local) {
    std::vector<RealizationState> states;
    states.reserve(local.size());
    for (const auto& r : local) states.push_back(r->save_state());
    return states;
}

void EnsembleSnapshots::restore_realizations(Realizations& local,
                                             const std::vector<RealizationState>& states) {
    EFDEM_EXPECTS(states.size() == local.size());
    for (std::size_t j = 0; j < local.size(); ++j) local[j]->restore_state(states[j]);
}

const EnsembleSnapshot& EnsembleSnapshots::get(Use use) const {
    EFDEM_EXPECTS(has(use));
    return *slot(use);
}

void EnsembleSnapshots::keep(EnsembleSnapshot snapshot) {
    EFDEM_EXPECTS(!kept_);
    kept_ = std::move(snapshot);
    kept_from_ = held_.size();
}

void EnsembleSnapshots::confirm() {
    EFDEM_EXPECTS(kept_.has_value());
    kept_.reset();
    kept_from_ = held_.size();
    if (!resume_) release();
}

EnsembleSnapshot EnsembleSnapshots::go_back() {
    EFDEM_EXPECTS(kept_.has_value());
    held_.resize(kept_from_);
    EnsembleSnapshot out = std::move(*kept_);
    kept_.reset();
    return out;
}

void EnsembleSnapshots::set_resume_point(EnsembleSnapshot snapshot) {
    EFDEM_EXPECTS(!kept_);
    resume_ = std::move(snapshot);
    release();
}

void EnsembleSnapshots::back_to_resume_point() {
    EFDEM_EXPECTS(resume_.has_value());
    kept_.reset();
    held_.clear();
    kept_from_ = 0;
}

void EnsembleSnapshots::record(const SampleRecord& sample) {
    if (!sink_) return;
    if (kept_ || resume_)
        held_.push_back(sample);
    else
        sink_->sample(sample);
}

void EnsembleSnapshots::release() {
    const std::size_t n = kept_ ? kept_from_ : held_.size();
    if (sink_)
        for (std::size_t i = 0; i < n; ++i) sink_->sample(held_[i]);
    held_.erase(held_.begin(), held_.begin() + static_cast<std::ptrdiff_t>(n));
    kept_from_ = 0;  // what is held now came after the kept state (if any)
}

}  // namespace efdem::mpi_driver
