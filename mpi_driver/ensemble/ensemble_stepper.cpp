#include "mpi_driver/ensemble/ensemble_stepper.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include <fmt/format.h>

#include "core/contracts.hpp"
#include "core/error.hpp"
#include "mpi_driver/ensemble/stop_signal.hpp"

namespace efdem::mpi_driver {

EnsembleStepper::EnsembleStepper(const EnsembleLayout& layout,
                                 std::vector<std::unique_ptr<Realization>> local,
                                 const StepperSettings& settings,
                                 coarse::EnsembleObservable& observable, const Lifter& lifter,
                                 RunRecorder* recorder, Progress* progress)
    : layout_(layout),
      local_(std::move(local)),
      settings_(settings),
      observable_(&observable),
      lifter_(lifter),
      recorder_(recorder),
      progress_(progress),
      grid_(settings.quantiles) {
    EFDEM_EXPECTS(static_cast<int>(local_.size()) == layout.per_rank());
    active_.assign(static_cast<std::size_t>(layout_.size()), 1);
    if (layout_.is_root())
        for (int r = 0; r < layout_.size(); ++r)
            lifting_.emplace_back(settings.seed, static_cast<std::uint64_t>(r), "lifting");
    long n = 0;
    for (const auto& r : local_) n += r->particles();
    total_particles_ = static_cast<double>(layout_.sum(n));
}

double EnsembleStepper::time() const {
    // The clock of one in the ensemble where there is one (a dropped realization's clock is
    // moved on with the ensemble's, but by sums of its own).
    for (const auto& r : local_)
        if (is_active(*r)) return r->time();
    return local_.front()->time();
}

int EnsembleStepper::active_realizations() const {
    return static_cast<int>(std::count(active_.begin(), active_.end(), char{1}));
}

bool EnsembleStepper::needs_top_half() const {
    return observable_->needs_top_half() ||
           (settings_.recorded && settings_.recorded->needs_top_half());
}

std::string EnsembleStepper::where_saved() const {
    // The failed state is not written: it is not healthy. The newest checkpoint is the last
    // healthy state saved.
    if (!writer_) return "there is no checkpoint to restart from (this efdem has no HDF5)";
    if (!periodic_checkpoints_ && last_checkpoint_.empty())
        return "checkpointing is off (checkpoint.interval = 0): there is no checkpoint to restart "
               "from";
    if (last_checkpoint_.empty())
        return "no checkpoint had been written yet (checkpoint.interval sets how often one is)";
    return fmt::format(
        "the failed state is not checkpointed; the newest checkpoint, {} (t = {:.6g}), "
        "holds the last saved healthy state (restart=FILE)",
        last_checkpoint_.string(), last_checkpoint_time_);
}

namespace {
/// "realization R: MESSAGE", unless the message names it already.
std::string naming(long realization, const std::string& message) {
    const std::string who = fmt::format("realization {}: ", realization);
    return message.rfind(who, 0) == 0 ? message : who + message;
}
}  // namespace

void EnsembleStepper::fail(const std::string& message, long realization) const {
    // Used where the ranks cannot agree first (keeping or restoring states, checkpoints).
    layout_.mpi().abort(fmt::format("{}; {}", naming(realization, message), where_saved()),
                        kExitRuntimeFailure);
}

int EnsembleStepper::agree(const std::vector<Failure>& failures, bool with_signal) {
    int local[2] = {with_signal ? stop_signal_received() : 0, static_cast<int>(failures.size())};
    int global[2] = {0, 0};
    MPI_Allreduce(local, global, 2, MPI_INT, MPI_MAX, layout_.mpi().comm());
    if (global[1] > 0) on_failures(failures);
    return global[0];
}

std::vector<std::string> EnsembleStepper::gather_failure_messages(
    const std::vector<Failure>& failures) const {
    std::vector<std::vector<std::uint8_t>> mine(local_.size());
    for (const Failure& f : failures)
        mine[static_cast<std::size_t>(f.realization - layout_.first_index())].assign(
            f.message.begin(), f.message.end());
    std::vector<std::string> out;
    for (const auto& m : layout_.gather_arrays(mine)) out.emplace_back(m.begin(), m.end());
    return out;
}

void EnsembleStepper::on_failures(const std::vector<Failure>& failures) {
    // Which realizations failed: every rank learns the same set.
    const auto R = static_cast<std::size_t>(layout_.size());
    std::vector<int> mine(R, 0), all(R, 0);
    for (const Failure& f : failures) mine[static_cast<std::size_t>(f.realization)] = 1;
    MPI_Allreduce(mine.data(), all.data(), static_cast<int>(R), MPI_INT, MPI_MAX,
                  layout_.mpi().comm());
    std::vector<long> failed;
    for (std::size_t r = 0; r < R; ++r)
        if (all[r]) failed.push_back(static_cast<long>(r));
    const FailurePolicy& policy = settings_.on_failure;
    const long total = failures_ + static_cast<long>(failed.size());
    const int healthy = active_realizations() - static_cast<int>(failed.size());
    const bool drop = policy.action == FailurePolicy::Action::drop;
    // Why the run cannot survive these failures (empty: it can; abort needs no reason).
    std::string fatal;
    if (total > policy.max_failures)
        fatal = fmt::format("{} realization failures, more than ensemble.max_failures = {}", total,
                            policy.max_failures);
    else if ((drop ? healthy : healthy + static_cast<int>(failed.size())) < policy.min_active ||
             healthy < 1)
        fatal = fmt::format("only {} healthy realization(s) would remain; the run needs {}",
                            healthy, policy.min_active);
    if (policy.action == FailurePolicy::Action::abort) fail_agreed(failures);
    if (!fatal.empty()) {
        std::vector<Failure> told = failures;
        for (Failure& f : told) f.message += "; the run ends: " + fatal;
        fail_agreed(told);
    }
    for (const Failure& f : failures)
        std::fprintf(
            stderr,
            "efdem: [rank %d of %d] warning: realization %ld at t = %.6g: %s; %s "
            "(ensemble.on_failure)\n",
            layout_.mpi().rank(), layout_.mpi().size(), f.realization, time(), f.message.c_str(),
            drop ? "dropped from the ensemble" : "to be rebuilt from a healthy realization");
    std::fflush(stderr);
    const std::vector<std::string> reasons = gather_failure_messages(failures);
    failures_ = total;
    if (!has_resume_point_) {
        // Direct: every whole sample is a safe point; the realization leaves the ensemble here.
        EFDEM_EXPECTS(drop);
        for (long f : failed) active_[static_cast<std::size_t>(f)] = 0;
        if (layout_.is_root() && recorder_)
            for (long f : failed)
                recorder_->failure({time(), f, reasons[static_cast<std::size_t>(f)], "dropped", -1,
                                    time(), active_realizations()});
        return;
    }
    // cpi: the coarse step is redone from its resume point with the changed ensemble.
    failed_pending_ = failed;
    failed_reasons_ = reasons;
    failed_time_ = time();
    changed_ = true;
}

void EnsembleStepper::fail_agreed(const std::vector<Failure>& failures) {
    // The failing rank says what failed (with its rank in the prefix); the root gets the
    // messages so that the run file can say it too.
    for (const Failure& f : failures) {
        const std::string text =
            fmt::format("{}; {}", naming(f.realization, f.message), where_saved());
        std::fprintf(stderr, "efdem: [rank %d of %d] error: %s\n", layout_.mpi().rank(),
                     layout_.mpi().size(), text.c_str());
    }
    std::fflush(stderr);
    const std::vector<std::string> all = gather_failure_messages(failures);
    std::string summary;
    for (std::size_t r = 0; r < all.size(); ++r)
        if (!all[r].empty())
            summary += fmt::format("{}realization {} at t = {:.6g}: {}",
                                   summary.empty() ? "" : "; ", r, time(), all[r]);
    throw RunFailed(summary.empty() ? std::string("a realization failed (see the messages above)")
                                    : summary);
}

EnsembleStepper::Message EnsembleStepper::broadcast(Message m) const {
    double buf[3] = {static_cast<double>(static_cast<int>(m.command)), m.value,
                     m.top_half ? 1.0 : 0.0};
    MPI_Bcast(buf, 3, MPI_DOUBLE, 0, layout_.mpi().comm());
    return {static_cast<Command>(static_cast<int>(buf[0])), buf[1], buf[2] != 0.0};
}

void EnsembleStepper::run(double duration, coarse::BurstSamples& out) {
    if (interrupted_) throw RunInterrupted(interrupted_, time());
    const bool top = needs_top_half();
    broadcast({Command::run, duration, top});
    const long wanted = std::lround(duration / settings_.sample_interval);
    const long got = do_run(wanted, top, &out);
    if (changed_) throw EnsembleChanged();
    if (got < wanted) throw RunInterrupted(interrupted_, time());
}

void EnsembleStepper::lift(const Eigen::VectorXd& target, double new_time) {
    const bool top = observable_->needs_top_half();
    const bool members = settings_.lift_members && observable_->restricts_members();
    broadcast({members ? Command::lift_members : Command::lift, new_time, top});
    do_lift(new_time, top, &target, members);
}

void EnsembleStepper::finish(int exit_code) {
    if (exit_code != kExitInterrupted) flush_since_mark();
    finish_code_ = exit_code;
    broadcast({Command::finish, static_cast<double>(exit_code), false});
}

void EnsembleStepper::record(const SampleRecord& s) {
    if (!recorder_) return;
    if (provisional_)
        pending_.push_back(s);  // recorded when the jump before it is kept
    else if (has_resume_point_)
        since_mark_.push_back(s);
    else
        recorder_->sample(s);
}

void EnsembleStepper::flush_since_mark() {
    if (recorder_)
        for (const SampleRecord& s : since_mark_) recorder_->sample(s);
    since_mark_.clear();
}

void EnsembleStepper::mark_resume_point(const DriverState& driver) {
    EFDEM_EXPECTS(!provisional_);
    broadcast({Command::mark, 0.0, false});
    do_mark();
    resume_driver_ = driver;
    resume_sample_ = last_sample_;
    resume_x_ = last_x_;
    flush_since_mark();
}

std::vector<RealizationState> EnsembleStepper::saved_realizations(const char* when) const {
    std::vector<RealizationState> states;
    try {
        for (const auto& r : local_) states.push_back(r->save_state());
    } catch (const std::exception& e) {
        fail(std::string("keeping the state ") + when + ": " + e.what(), local_.front()->index());
    }
    return states;
}

void EnsembleStepper::do_mark() {
    resume_states_ = saved_realizations("between coarse steps");
    resume_time_ = time();
    resume_stepper_ = saved_state();
    has_resume_point_ = true;
}

std::filesystem::path EnsembleStepper::checkpoint_resume_point() {
    EFDEM_EXPECTS(writer_ != nullptr && has_resume_point_);
    const long sequence = resume_driver_.coarse_steps;
    broadcast({Command::checkpoint_mark, static_cast<double>(sequence), false});
    CheckpointHeader header;
    header.stepper = resume_stepper_;
    header.driver = resume_driver_;
    return do_checkpoint(sequence, &header, true);
}

void EnsembleStepper::keep_state() {
    broadcast({Command::keep, 0.0, false});
    do_keep();
}

void EnsembleStepper::return_to_kept_state() {
    broadcast({Command::go_back, 0.0, false});
    do_go_back();
}

void EnsembleStepper::set_parameter(double value) {
    broadcast({Command::set_parameter, value, false});
    do_set_parameter(value);
}

void EnsembleStepper::do_set_parameter(double value) {
    EFDEM_EXPECTS(!settings_.parameter.empty());
    for (auto& r : local_) r->set_parameter(settings_.parameter, value);
}

void EnsembleStepper::confirm_kept_state() {
    broadcast({Command::confirm, 0.0, false});
    do_confirm();
}

void EnsembleStepper::do_keep() {
    kept_ = saved_realizations("before a projective jump");
    kept_stepper_ = saved_state();
    kept_sample_ = last_sample_;
    pending_.clear();
    provisional_ = true;
}

void EnsembleStepper::do_go_back() {
    EFDEM_EXPECTS(provisional_ && kept_.size() == local_.size());
    try {
        for (std::size_t j = 0; j < local_.size(); ++j) local_[j]->restore_state(kept_[j]);
    } catch (const std::exception& e) {
        fail(std::string("going back to the state before a rejected jump: ") + e.what(),
             local_.front()->index());
    }
    // The rejected burst's work was done: it stays in the cost.
    const double micro = micro_time_, steps = particle_steps_;
    restore_state(kept_stepper_);
    micro_time_ = micro;
    particle_steps_ = steps;
    last_sample_ = kept_sample_;
    pending_.clear();
    kept_.clear();
    provisional_ = false;
}

void EnsembleStepper::do_confirm() {
    EFDEM_EXPECTS(provisional_);
    provisional_ = false;
    for (const SampleRecord& s : pending_) record(s);
    pending_.clear();
    kept_.clear();
}

void EnsembleStepper::serve() {
    while (true) {
        const Message m = broadcast({Command::finish, 0.0, false});
        switch (m.command) {
            case Command::run:
                do_run(std::lround(m.value / settings_.sample_interval), m.top_half, nullptr);
                break;
            case Command::lift:
                do_lift(m.value, m.top_half, nullptr, false);
                break;
            case Command::lift_members:
                do_lift(m.value, m.top_half, nullptr, true);
                break;
            case Command::checkpoint:
                do_checkpoint(std::lround(m.value), nullptr, false);
                break;
            case Command::keep:
                do_keep();
                break;
            case Command::go_back:
                do_go_back();
                break;
            case Command::confirm:
                do_confirm();
                break;
            case Command::mark:
                do_mark();
                break;
            case Command::checkpoint_mark:
                do_checkpoint(std::lround(m.value), nullptr, true);
                break;
            case Command::rebuild:
                do_rebuild(m.top_half);
                break;
            case Command::set_parameter:
                do_set_parameter(m.value);
                break;
            case Command::finish:
                finish_code_ = static_cast<int>(m.value);
                return;
        }
    }
}

std::filesystem::path EnsembleStepper::checkpoint(long sequence, const DriverState& driver) {
    EFDEM_EXPECTS(writer_ != nullptr && !provisional_);
    flush_since_mark();  // the checkpoint stores the output files with every sample so far
    broadcast({Command::checkpoint, static_cast<double>(sequence), false});
    CheckpointHeader header;
    header.stepper = saved_state();
    header.driver = driver;
    return do_checkpoint(sequence, &header, false);
}

std::filesystem::path EnsembleStepper::do_checkpoint(long sequence, const CheckpointHeader* header,
                                                     bool at_resume_point) {
    std::vector<RealizationState> states;
    try {
        if (!at_resume_point)
            for (const auto& r : local_) states.push_back(r->save_state());
        last_checkpoint_ =
            writer_->write(sequence, at_resume_point ? resume_states_ : states, header);
        last_checkpoint_time_ = at_resume_point ? resume_time_ : time();
        return last_checkpoint_;
    } catch (const CheckpointSpaceError& e) {
        // Every rank knows it at once: they end together, and the root marks the run file.
        if (layout_.is_root()) std::fprintf(stderr, "efdem: error: %s\n", e.what());
        throw RunFailed(e.what());
    } catch (const std::exception& e) {
        layout_.mpi().abort(fmt::format("writing checkpoint {}: {}", sequence, e.what()),
                            kExitRuntimeFailure);
    }
}

StepperState EnsembleStepper::saved_state() const {
    StepperState s;
    s.samples_taken = samples_taken_;
    s.micro_time = micro_time_;
    s.particle_steps = particle_steps_;
    s.height_lo = height_range_.first;
    s.height_hi = height_range_.second;
    for (const auto& l : lifting_) s.lifting.push_back(l.state());
    s.observable = observable_->saved_state();
    if (settings_.recorded) s.recorded = settings_.recorded->saved_state();
    s.active.assign(active_.begin(), active_.end());
    s.failures = failures_;
    return s;
}

void EnsembleStepper::restore_state(const StepperState& s) {
    samples_taken_ = s.samples_taken;
    if (!s.active.empty()) {
        EFDEM_EXPECTS(s.active.size() == active_.size());
        for (std::size_t r = 0; r < active_.size(); ++r) active_[r] = s.active[r] != 0 ? 1 : 0;
    }
    failures_ = s.failures;
    micro_time_ = s.micro_time;
    particle_steps_ = s.particle_steps;
    height_range_ = {s.height_lo, s.height_hi};
    if (!layout_.is_root()) return;
    EFDEM_EXPECTS(s.lifting.size() == lifting_.size());
    for (std::size_t r = 0; r < lifting_.size(); ++r) lifting_[r].set_state(s.lifting[r]);
    observable_->restore_state(s.observable);
    if (settings_.recorded) settings_.recorded->restore_state(s.recorded);
}

long EnsembleStepper::do_run(long samples, bool top_half, coarse::BurstSamples* out) {
    const InjectedFailure& inject = settings_.failure;
    std::vector<Failure> failures;
    for (long s = 0; s < samples; ++s) {
        for (auto& r : local_) {
            if (!is_active(
                    *r)) {  // dropped after a failure: not advanced, but its clock keeps time
                r->set_time(r->time() + static_cast<double>(settings_.steps_per_sample) * r->dt());
                continue;
            }
            try {
                r->advance(settings_.steps_per_sample);
                if (!injected_fired_ && r->index() == inject.realization &&
                    r->time() >= inject.time) {
                    injected_fired_ = true;
                    throw RuntimeFailure("injected failure (debug.fail_realization)", r->index());
                }
            } catch (const std::exception& e) {
                failures.push_back({r->index(), e.what()});
            }
        }
        const int signal = agree(failures, true);
        failures.clear();
        micro_time_ += static_cast<double>(settings_.steps_per_sample) * local_.front()->dt();
        particle_steps_ += static_cast<double>(settings_.steps_per_sample) * total_particles_;
        if (changed_) return s;  // cpi: the step is redone from its resume point
        take_sample(top_half, out);
        ++samples_taken_;
        for (auto& r : local_) {
            if (!is_active(*r)) continue;
            try {
                r->after_sample(samples_taken_);
            } catch (const std::exception& e) {
                failures.push_back({r->index(), e.what()});
            }
        }
        agree(failures, false);
        failures.clear();
        if (changed_) return s + 1;
        if (signal != 0) {
            interrupted_ = signal;
            return s + 1;
        }
    }
    return samples;
}

namespace {
/// The rows of `all` listed in `rows` (all rows when every realization is in the ensemble).
Eigen::MatrixXd rows_of(const Eigen::MatrixXd& all, const std::vector<Eigen::Index>& rows) {
    if (all.size() == 0 || static_cast<Eigen::Index>(rows.size()) == all.rows()) return all;
    Eigen::MatrixXd out(static_cast<Eigen::Index>(rows.size()), all.cols());
    for (std::size_t k = 0; k < rows.size(); ++k)
        out.row(static_cast<Eigen::Index>(k)) = all.row(rows[k]);
    return out;
}
}  // namespace

namespace {
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

void EnsembleStepper::take_sample(bool top, coarse::BurstSamples* out) {
    const double start = MPI_Wtime();
    const auto m = static_cast<Eigen::Index>(grid_.values().size());
    const double nan = std::numeric_limits<double>::quiet_NaN();
    const auto bed_width =
        settings_.bed ? static_cast<Eigen::Index>(dem::BedObservation::packed_size(*settings_.bed))
                      : 0;
    std::vector<Eigen::VectorXd> icdf, top_icdf, scalars, bed;
    for (const auto& r : local_) {
        if (!is_active(*r)) {  // dropped: a row of NaN in the record, not in the means
            icdf.push_back(Eigen::VectorXd::Constant(m, nan));
            if (top) top_icdf.push_back(Eigen::VectorXd::Constant(m, nan));
            scalars.push_back(Eigen::Vector4d::Constant(nan));
            if (bed_width > 0) bed.push_back(Eigen::VectorXd::Constant(bed_width, nan));
            continue;
        }
        Observation o = r->observe(grid_, top);
        icdf.push_back(std::move(o.icdf));
        if (top) top_icdf.push_back(std::move(o.top));
        scalars.push_back(Eigen::Vector4d(o.com, o.z_min, o.z_max, o.mean_height));
        if (bed_width > 0) {
            EFDEM_ASSERT(static_cast<Eigen::Index>(o.bed.size()) == bed_width);
            bed.push_back(Eigen::Map<const Eigen::VectorXd>(o.bed.data(), bed_width));
        }
    }
    const Eigen::MatrixXd all_icdf = layout_.gather_rows(icdf);
    const Eigen::MatrixXd all_top_rows = top ? layout_.gather_rows(top_icdf) : Eigen::MatrixXd();
    const Eigen::MatrixXd all_scalar_rows = layout_.gather_rows(scalars);
    const Eigen::MatrixXd all_bed_rows =
        bed_width > 0 ? layout_.gather_rows(bed) : Eigen::MatrixXd();
    if (!layout_.is_root()) {
        overhead_.restrict_seconds += MPI_Wtime() - start;
        ++overhead_.samples;
        return;
    }
    std::vector<Eigen::Index> in;
    for (std::size_t r = 0; r < active_.size(); ++r)
        if (active_[r]) in.push_back(static_cast<Eigen::Index>(r));
    const Eigen::MatrixXd used_icdf = rows_of(all_icdf, in);
    const Eigen::MatrixXd all_top = rows_of(all_top_rows, in);
    const Eigen::MatrixXd all_scalars = rows_of(all_scalar_rows, in);

    SampleRecord& rec = last_sample_;
    rec.time = time();
    rec.realizations = all_icdf;
    rec.realizations_used = static_cast<int>(in.size());
    rec.mean = coarse::ensemble_mean(used_icdf);
    rec.variance = coarse::ensemble_variance(used_icdf, rec.mean);
    rec.com = all_scalar_rows.col(0);
    if (settings_.bed) {
        rec.bed = bed_record(all_bed_rows, *settings_.bed);
        rec.bed_mean = bed_record(coarse::ensemble_mean(rows_of(all_bed_rows, in)).transpose(),
                                  *settings_.bed);
    }
    rec.top_mean = top ? coarse::ensemble_mean(all_top) : Eigen::VectorXd();
    height_range_ = {all_scalars.col(1).minCoeff(), all_scalars.col(2).maxCoeff()};
    const Eigen::VectorXd x = observable_->restrict_ensemble(used_icdf, all_top);
    last_x_ = x;
    rec.compact = observable_->needs_top_half() ? x : Eigen::VectorXd();
    rec.compact_status = observable_->status();
    if (!observable_->needs_top_half() && settings_.recorded) {
        rec.compact = settings_.recorded->restrict_ensemble(used_icdf, all_top);
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
            out->members.push_back(observable_->restrict_members(used_icdf, all_top));
    }
    record(rec);
    overhead_.restrict_seconds += MPI_Wtime() - start;
    ++overhead_.samples;
    if (progress_) progress_->update(rec.time, particle_steps_, "");
}

void EnsembleStepper::do_lift(double new_time, bool top, const Eigen::VectorXd* target,
                              bool members, const std::vector<char>* only) {
    const double start = MPI_Wtime();
    auto lifted_here = [&](long index) {
        return active_[static_cast<std::size_t>(index)] != 0 &&
               (!only || (*only)[static_cast<std::size_t>(index)] != 0);
    };
    const auto m = static_cast<Eigen::Index>(grid_.values().size());
    const double nan = std::numeric_limits<double>::quiet_NaN();
    // cpi.lift = members: every realization's own X now, to move each by the same increment
    // (a rebuild after a failure lifts to the target itself).
    EFDEM_EXPECTS(!members || !only);
    std::vector<std::vector<double>> reals;
    std::vector<std::vector<std::uint8_t>> bytes;
    std::vector<Eigen::VectorXd> top_icdf, own_icdf;
    std::vector<std::size_t> out_reals, out_bytes;
    for (const auto& r : local_) {
        if (!lifted_here(
                r->index())) {  // dropped, or not among `only`: nothing sent, nothing changed
            reals.emplace_back();
            bytes.emplace_back();
            if (top) top_icdf.push_back(Eigen::VectorXd::Constant(m, nan));
            if (members) own_icdf.push_back(Eigen::VectorXd::Constant(m, nan));
            out_reals.push_back(0);
            out_bytes.push_back(0);
            continue;
        }
        LiftPayload in = r->lift_input();
        reals.push_back(std::move(in.reals));
        bytes.push_back(std::move(in.bytes));
        if (top || members) {
            Observation o = r->observe(grid_, top);
            if (top) top_icdf.push_back(std::move(o.top));
            if (members) own_icdf.push_back(std::move(o.icdf));
        }
        const auto [nr, nb] = r->lift_output_sizes();
        out_reals.push_back(nr);
        out_bytes.push_back(nb);
    }
    const auto all_reals = layout_.gather_arrays(reals);
    const auto all_bytes = layout_.gather_arrays(bytes);
    const Eigen::MatrixXd all_top = top ? layout_.gather_rows(top_icdf) : Eigen::MatrixXd();
    const Eigen::MatrixXd all_own = members ? layout_.gather_rows(own_icdf) : Eigen::MatrixXd();

    std::vector<std::vector<double>> lifted_reals;
    std::vector<std::vector<std::uint8_t>> lifted_bytes;
    if (layout_.is_root()) {
        last_lift_ = LiftRecord{};
        // Each lifted realization's own X and their mean, in realization order (the same sum on
        // any layout); the increment target - mean moves every one of them alike.
        Eigen::MatrixXd own;
        Eigen::VectorXd increment;
        if (members) {
            own = observable_->restrict_members(all_own, all_top);
            EFDEM_ASSERT(own.rows() == layout_.size() && own.cols() == target->size());
            Eigen::VectorXd sum = Eigen::VectorXd::Zero(target->size());
            long n = 0;
            for (int r = 0; r < layout_.size(); ++r)
                if (lifted_here(r)) {
                    sum += own.row(r).transpose();
                    ++n;
                }
            EFDEM_ASSERT(n > 0);
            increment = *target - sum / static_cast<double>(n);
        }
        for (int r = 0; r < layout_.size(); ++r) {
            if (!lifted_here(r)) {
                last_lift_.changed.push_back(0);
                last_lift_.max_deviation.push_back(std::numeric_limits<double>::quiet_NaN());
                last_lift_.messages.emplace_back(active_[static_cast<std::size_t>(r)] ? ""
                                                                                      : "dropped");
                lifted_reals.emplace_back();
                lifted_bytes.emplace_back();
                continue;
            }
            Eigen::VectorXd x = *target;
            std::string repaired;
            if (members) {
                x = own.row(r).transpose() + increment;
                if (member_repair_) {
                    const coarse::RepairReport report = member_repair_(x);
                    if (report.changed())
                        repaired = fmt::format(
                            "its own target (X_r + increment) repaired by up to {:.3g} d_p",
                            report.max_adjustment);
                }
            }
            const Eigen::VectorXd goal = observable_->lift_target(
                x, top ? Eigen::VectorXd(all_top.row(r).transpose()) : Eigen::VectorXd());
            LiftOutcome res = lifter_.lift(goal, {all_reals[r], all_bytes[r]}, grid_, lifting_[r]);
            last_lift_.changed.push_back(res.changed);
            last_lift_.max_deviation.push_back(res.max_deviation);
            last_lift_.messages.push_back(repaired.empty() || res.message.empty()
                                              ? repaired + res.message
                                              : repaired + "; " + res.message);
            lifted_reals.push_back(std::move(res.payload.reals));
            lifted_bytes.push_back(std::move(res.payload.bytes));
        }
    }
    const auto my_reals = layout_.scatter_arrays(lifted_reals, out_reals);
    const auto my_bytes = layout_.scatter_arrays(lifted_bytes, out_bytes);
    for (std::size_t j = 0; j < local_.size(); ++j) {
        if (lifted_here(local_[j]->index())) {
            local_[j]->apply_lift({my_reals[j], my_bytes[j]});
            local_[j]->set_time(new_time);
        } else if (!only) {
            // A dropped realization's clock follows the jump too: a rank whose realizations were
            // all dropped still knows the ensemble's time.
            local_[j]->set_time(new_time);
        }
    }
    overhead_.lift_seconds += MPI_Wtime() - start;
    ++overhead_.lifts;
}

void EnsembleStepper::rebuild_after_failure() {
    EFDEM_EXPECTS(changed_ && has_resume_point_);
    broadcast({Command::rebuild, 0.0, observable_->needs_top_half()});
    do_rebuild(observable_->needs_top_half());
}

void EnsembleStepper::send_states(const std::vector<long>& failed,
                                  const std::vector<long>& donors) {
    // The donor's state at the resume point goes to the failed realization's rank.
    const long k = layout_.per_rank();
    const int me = layout_.mpi().rank();
    for (std::size_t i = 0; i < failed.size(); ++i) {
        if (donors[i] < 0) continue;
        const int from = static_cast<int>(donors[i] / k), to = static_cast<int>(failed[i] / k);
        RealizationState state;
        if (from == me) state = resume_states_[static_cast<std::size_t>(donors[i] % k)];
        if (from != to) {
            if (me == from) {
                const std::vector<std::uint8_t> bytes = pack(state);
                const long n = static_cast<long>(bytes.size());
                MPI_Send(&n, 1, MPI_LONG, to, 71, layout_.mpi().comm());
                MPI_Send(bytes.data(), static_cast<int>(n), MPI_BYTE, to, 72, layout_.mpi().comm());
            } else if (me == to) {
                long n = 0;
                MPI_Recv(&n, 1, MPI_LONG, from, 71, layout_.mpi().comm(), MPI_STATUS_IGNORE);
                std::vector<std::uint8_t> bytes(static_cast<std::size_t>(n));
                MPI_Recv(bytes.data(), static_cast<int>(n), MPI_BYTE, from, 72,
                         layout_.mpi().comm(), MPI_STATUS_IGNORE);
                state = unpack(bytes);
            }
        }
        if (me == to) {
            state.index = failed[i];
            local_[static_cast<std::size_t>(failed[i] % k)]->restore_state(state);
        }
    }
}

void EnsembleStepper::do_rebuild(bool top_half) {
    EFDEM_EXPECTS(changed_ && has_resume_point_);
    const bool replace = settings_.on_failure.action == FailurePolicy::Action::replace;
    const std::vector<char> active_now = active_;
    const long failures_now = failures_;
    // 1. Every realization back to where the interrupted coarse step began.
    try {
        for (std::size_t j = 0; j < local_.size(); ++j) local_[j]->restore_state(resume_states_[j]);
    } catch (const std::exception& e) {
        fail(std::string("going back to the resume point after a failure: ") + e.what(),
             local_.front()->index());
    }
    const double micro = micro_time_, steps = particle_steps_;  // the lost work stays counted
    restore_state(resume_stepper_);
    micro_time_ = micro;
    particle_steps_ = steps;
    active_ = active_now;
    failures_ = failures_now;
    pending_.clear();
    since_mark_.clear();
    kept_.clear();
    provisional_ = false;
    // 2. Drop, or rebuild from the next healthy realization (before the first coarse step, at
    //    the run's start, from its own initial state: there is no ensemble state to lift to).
    const std::vector<long> failed = failed_pending_;
    std::vector<long> donors(failed.size(), -1);
    std::vector<char> lift_these(active_.size(), 0);
    const bool has_coarse_state = layout_.is_root() ? resume_x_.size() > 0 : true;
    int lift_flag = has_coarse_state ? 1 : 0;
    MPI_Bcast(&lift_flag, 1, MPI_INT, 0, layout_.mpi().comm());
    const auto R = static_cast<long>(active_.size());
    for (std::size_t i = 0; i < failed.size(); ++i) {
        if (!replace) {
            active_[static_cast<std::size_t>(failed[i])] = 0;
            continue;
        }
        for (long step = 1; step < R && lift_flag; ++step) {
            const long d = (failed[i] + step) % R;
            if (active_[static_cast<std::size_t>(d)] &&
                std::find(failed.begin(), failed.end(), d) == failed.end()) {
                donors[i] = d;
                break;
            }
        }
        lift_these[static_cast<std::size_t>(failed[i])] = 1;
    }
    if (replace) send_states(failed, donors);
    if (replace && layout_.is_root())
        for (long f : failed)  // a fresh lifting stream of its own, never used before
            lifting_[static_cast<std::size_t>(f)] = RandomStream(
                settings_.seed, static_cast<std::uint64_t>(f + R * failures_), "lifting");
    // 3. Lifted at once to the ensemble's coarse state at the resume point, so that the copy
    //    leaves its donor's trajectory from the first step on.
    if (replace && lift_flag)
        do_lift(resume_time_, top_half, layout_.is_root() ? &resume_x_ : nullptr, false,
                &lift_these);
    if (layout_.is_root()) {
        last_sample_ = resume_sample_;
        if (recorder_)
            for (std::size_t i = 0; i < failed.size(); ++i)
                recorder_->failure({failed_time_, failed[i],
                                    failed_reasons_[static_cast<std::size_t>(failed[i])],
                                    replace ? "replaced" : "dropped", donors[i], resume_time_,
                                    active_realizations()});
    }
    failed_pending_.clear();
    changed_ = false;
    // 4. The rebuilt ensemble is the new resume point (a stop now checkpoints it).
    do_mark();
}

}  // namespace efdem::mpi_driver
