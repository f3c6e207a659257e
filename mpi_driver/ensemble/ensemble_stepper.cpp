#include "mpi_driver/ensemble/ensemble_stepper.hpp"

#include <cmath>
#include <cstdio>

#include <fmt/format.h>

#include "core/contracts.hpp"
#include "core/error.hpp"
#include "mpi_driver/ensemble/stop_signal.hpp"

namespace efdem::mpi_driver {

EnsembleStepper::EnsembleStepper(const EnsembleLayout& layout, std::vector<std::unique_ptr<Realization>> local,
                                 const StepperSettings& settings, coarse::EnsembleObservable& observable,
                                 const Lifter& lifter, RunRecorder* recorder, Progress* progress)
    : layout_(layout), local_(std::move(local)), settings_(settings), observable_(&observable),
      lifter_(lifter), recorder_(recorder), progress_(progress), grid_(settings.quantiles) {
    EFDEM_EXPECTS(static_cast<int>(local_.size()) == layout.per_rank());
    if (layout_.is_root())
        for (int r = 0; r < layout_.size(); ++r)
            lifting_.emplace_back(settings.seed, static_cast<std::uint64_t>(r), "lifting");
    long n = 0;
    for (const auto& r : local_) n += r->particles();
    total_particles_ = static_cast<double>(layout_.sum(n));
}

double EnsembleStepper::time() const { return local_.front()->time(); }

bool EnsembleStepper::needs_top_half() const {
    return observable_->needs_top_half() || (settings_.recorded && settings_.recorded->needs_top_half());
}

std::string EnsembleStepper::where_saved() const {
    // The failed state is not written: it is not healthy. The newest checkpoint is the last
    // healthy state saved.
    if (!writer_) return "there is no checkpoint to restart from (this efdem has no HDF5)";
    if (!periodic_checkpoints_ && last_checkpoint_.empty())
        return "checkpointing is off (checkpoint.interval = 0): there is no checkpoint to restart from";
    if (last_checkpoint_.empty())
        return "no checkpoint had been written yet (checkpoint.interval sets how often one is)";
    return fmt::format("the failed state is not checkpointed; the newest checkpoint, {} (t = {:.6g}), "
                       "holds the last saved healthy state (restart=FILE)",
                       last_checkpoint_.string(), last_checkpoint_time_);
}

void EnsembleStepper::fail(const std::string& message, long realization) const {
    // Used where the ranks cannot agree first (keeping or restoring states, checkpoints).
    const std::string who = fmt::format("realization {}: ", realization);
    layout_.mpi().abort(fmt::format("{}{}; {}", message.rfind(who, 0) == 0 ? "" : who, message, where_saved()),
                        kExitRuntimeFailure);
}

int EnsembleStepper::agree(const std::vector<Failure>& failures, bool with_signal) {
    int local[2] = {with_signal ? stop_signal_received() : 0, static_cast<int>(failures.size())};
    int global[2] = {0, 0};
    MPI_Allreduce(local, global, 2, MPI_INT, MPI_MAX, layout_.mpi().comm());
    if (global[1] > 0) fail_agreed(failures);
    return global[0];
}

void EnsembleStepper::fail_agreed(const std::vector<Failure>& failures) {
    // The failing rank says what failed (with its rank in the prefix); the root gets the
    // messages so that the run file can say it too.
    for (const Failure& f : failures) {
        const std::string who = fmt::format("realization {}: ", f.realization);
        const std::string text =
            fmt::format("{}{}; {}", f.message.rfind(who, 0) == 0 ? "" : who, f.message, where_saved());
        std::fprintf(stderr, "efdem: [rank %d of %d] error: %s\n", layout_.mpi().rank(), layout_.mpi().size(),
                     text.c_str());
    }
    std::fflush(stderr);
    std::vector<std::vector<std::uint8_t>> mine(local_.size());
    for (const Failure& f : failures) {
        const std::string text = fmt::format("realization {} at t = {:.6g}: {}", f.realization, time(), f.message);
        mine[static_cast<std::size_t>(f.realization - layout_.first_index())].assign(text.begin(), text.end());
    }
    const auto all = layout_.gather_arrays(mine);
    std::string summary;
    for (const auto& m : all)
        if (!m.empty()) summary += (summary.empty() ? "" : "; ") + std::string(m.begin(), m.end());
    throw RunFailed(summary.empty() ? std::string("a realization failed (see the messages above)") : summary);
}

EnsembleStepper::Message EnsembleStepper::broadcast(Message m) const {
    double buf[3] = {static_cast<double>(static_cast<int>(m.command)), m.value, m.top_half ? 1.0 : 0.0};
    MPI_Bcast(buf, 3, MPI_DOUBLE, 0, layout_.mpi().comm());
    return {static_cast<Command>(static_cast<int>(buf[0])), buf[1], buf[2] != 0.0};
}

void EnsembleStepper::run(double duration, coarse::BurstSamples& out) {
    if (interrupted_) throw RunInterrupted(interrupted_, time());
    const bool top = needs_top_half();
    broadcast({Command::run, duration, top});
    const long wanted = std::lround(duration / settings_.sample_interval);
    if (do_run(wanted, top, &out) < wanted) throw RunInterrupted(interrupted_, time());
}

void EnsembleStepper::lift(const Eigen::VectorXd& target, double new_time) {
    const bool top = observable_->needs_top_half();
    broadcast({Command::lift, new_time, top});
    do_lift(new_time, top, &target);
}

void EnsembleStepper::finish(int exit_code) {
    if (exit_code != kExitInterrupted) flush_since_mark();
    finish_code_ = exit_code;
    broadcast({Command::finish, static_cast<double>(exit_code), false});
}

void EnsembleStepper::record(const SampleRecord& s) {
    if (!recorder_) return;
    if (provisional_) pending_.push_back(s);  // recorded when the jump before it is kept
    else if (has_resume_point_) since_mark_.push_back(s);
    else recorder_->sample(s);
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
    resume_stepper_ = saved_state();
    resume_driver_ = driver;
    flush_since_mark();
}

void EnsembleStepper::do_mark() {
    resume_states_.clear();
    try {
        for (const auto& r : local_) resume_states_.push_back(r->save_state());
    } catch (const std::exception& e) {
        fail(std::string("keeping the state between coarse steps: ") + e.what(), local_.front()->index());
    }
    resume_time_ = time();
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

void EnsembleStepper::confirm_kept_state() {
    broadcast({Command::confirm, 0.0, false});
    do_confirm();
}

void EnsembleStepper::do_keep() {
    kept_.clear();
    try {
        for (const auto& r : local_) kept_.push_back(r->save_state());
    } catch (const std::exception& e) {
        fail(std::string("keeping the state before a projective jump: ") + e.what(), local_.front()->index());
    }
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
        fail(std::string("going back to the state before a rejected jump: ") + e.what(), local_.front()->index());
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
            case Command::run: do_run(std::lround(m.value / settings_.sample_interval), m.top_half, nullptr); break;
            case Command::lift: do_lift(m.value, m.top_half, nullptr); break;
            case Command::checkpoint: do_checkpoint(std::lround(m.value), nullptr, false); break;
            case Command::keep: do_keep(); break;
            case Command::go_back: do_go_back(); break;
            case Command::confirm: do_confirm(); break;
            case Command::mark: do_mark(); break;
            case Command::checkpoint_mark: do_checkpoint(std::lround(m.value), nullptr, true); break;
            case Command::finish: finish_code_ = static_cast<int>(m.value); return;
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
        last_checkpoint_ = writer_->write(sequence, at_resume_point ? resume_states_ : states, header);
        last_checkpoint_time_ = at_resume_point ? resume_time_ : time();
        return last_checkpoint_;
    } catch (const std::exception& e) {
        layout_.mpi().abort(fmt::format("writing checkpoint {}: {}", sequence, e.what()), kExitRuntimeFailure);
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
    return s;
}

void EnsembleStepper::restore_state(const StepperState& s) {
    samples_taken_ = s.samples_taken;
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
            try {
                r->advance(settings_.steps_per_sample);
                if (r->index() == inject.realization && r->time() >= inject.time)
                    throw RuntimeFailure("injected failure (debug.fail_realization)", r->index());
            } catch (const std::exception& e) {
                failures.push_back({r->index(), e.what()});
            }
        }
        const int signal = agree(failures, true);
        micro_time_ += static_cast<double>(settings_.steps_per_sample) * local_.front()->dt();
        particle_steps_ += static_cast<double>(settings_.steps_per_sample) * total_particles_;
        take_sample(top_half, out);
        ++samples_taken_;
        for (auto& r : local_) {
            try {
                r->after_sample(samples_taken_);
            } catch (const std::exception& e) {
                failures.push_back({r->index(), e.what()});
            }
        }
        agree(failures, false);
        if (signal != 0) {
            interrupted_ = signal;
            return s + 1;
        }
    }
    return samples;
}

void EnsembleStepper::take_sample(bool top, coarse::BurstSamples* out) {
    const double start = MPI_Wtime();
    std::vector<Eigen::VectorXd> icdf, top_icdf, scalars;
    for (const auto& r : local_) {
        Observation o = r->observe(grid_, top);
        icdf.push_back(std::move(o.icdf));
        if (top) top_icdf.push_back(std::move(o.top));
        scalars.push_back(Eigen::Vector4d(o.com, o.z_min, o.z_max, o.mean_height));
    }
    const Eigen::MatrixXd all_icdf = layout_.gather_rows(icdf);
    const Eigen::MatrixXd all_top = top ? layout_.gather_rows(top_icdf) : Eigen::MatrixXd();
    const Eigen::MatrixXd all_scalars = layout_.gather_rows(scalars);
    if (!layout_.is_root()) {
        overhead_.restrict_seconds += MPI_Wtime() - start;
        ++overhead_.samples;
        return;
    }

    SampleRecord& rec = last_sample_;
    rec.time = time();
    rec.realizations = all_icdf;
    rec.mean = coarse::ensemble_mean(all_icdf);
    rec.variance = coarse::ensemble_variance(all_icdf, rec.mean);
    rec.com = all_scalars.col(0);
    rec.top_mean = top ? coarse::ensemble_mean(all_top) : Eigen::VectorXd();
    height_range_ = {all_scalars.col(1).minCoeff(), all_scalars.col(2).maxCoeff()};
    const Eigen::VectorXd x = observable_->restrict_ensemble(all_icdf, all_top);
    rec.compact = observable_->needs_top_half() ? x : Eigen::VectorXd();
    rec.compact_status = observable_->status();
    if (!observable_->needs_top_half() && settings_.recorded) {
        rec.compact = settings_.recorded->restrict_ensemble(all_icdf, all_top);
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
            out->members.push_back(observable_->restrict_members(all_icdf, all_top));
    }
    record(rec);
    overhead_.restrict_seconds += MPI_Wtime() - start;
    ++overhead_.samples;
    if (progress_) progress_->update(rec.time, particle_steps_, "");
}

void EnsembleStepper::do_lift(double new_time, bool top, const Eigen::VectorXd* target) {
    const double start = MPI_Wtime();
    std::vector<std::vector<double>> reals;
    std::vector<std::vector<std::uint8_t>> bytes;
    std::vector<Eigen::VectorXd> top_icdf;
    std::vector<std::size_t> out_reals, out_bytes;
    for (const auto& r : local_) {
        LiftPayload in = r->lift_input();
        reals.push_back(std::move(in.reals));
        bytes.push_back(std::move(in.bytes));
        if (top) top_icdf.push_back(r->observe(grid_, true).top);
        const auto [nr, nb] = r->lift_output_sizes();
        out_reals.push_back(nr);
        out_bytes.push_back(nb);
    }
    const auto all_reals = layout_.gather_arrays(reals);
    const auto all_bytes = layout_.gather_arrays(bytes);
    const Eigen::MatrixXd all_top = top ? layout_.gather_rows(top_icdf) : Eigen::MatrixXd();

    std::vector<std::vector<double>> lifted_reals;
    std::vector<std::vector<std::uint8_t>> lifted_bytes;
    if (layout_.is_root()) {
        last_lift_ = LiftRecord{};
        for (int r = 0; r < layout_.size(); ++r) {
            const Eigen::VectorXd goal =
                observable_->lift_target(*target, top ? Eigen::VectorXd(all_top.row(r).transpose()) : Eigen::VectorXd());
            LiftOutcome res = lifter_.lift(goal, {all_reals[r], all_bytes[r]}, grid_, lifting_[r]);
            last_lift_.changed.push_back(res.changed);
            last_lift_.max_deviation.push_back(res.max_deviation);
            last_lift_.messages.push_back(res.message);
            lifted_reals.push_back(std::move(res.payload.reals));
            lifted_bytes.push_back(std::move(res.payload.bytes));
        }
    }
    const auto my_reals = layout_.scatter_arrays(lifted_reals, out_reals);
    const auto my_bytes = layout_.scatter_arrays(lifted_bytes, out_bytes);
    for (std::size_t j = 0; j < local_.size(); ++j) {
        local_[j]->apply_lift({my_reals[j], my_bytes[j]});
        local_[j]->set_time(new_time);
    }
    overhead_.lift_seconds += MPI_Wtime() - start;
    ++overhead_.lifts;
}

}  // namespace efdem::mpi_driver
