#include "mpi_driver/ensemble/ensemble_stepper.hpp"

#include <cmath>
#include <limits>

#include <fmt/format.h>
#include <mpi.h>

#include "core/contracts.hpp"
#include "core/error.hpp"
#include "core/log.hpp"
#include "mpi_driver/parallel/mpi_broadcast.hpp"
#include "mpi_driver/parallel/stop_signal.hpp"

namespace efdem::mpi_driver {

namespace {
using Use = EnsembleSnapshots::Use;

/// "realization R: MESSAGE", unless the message names it already.
std::string naming(long realization, const std::string& message) {
    const std::string who = fmt::format("realization {}: ", realization);
    return message.rfind(who, 0) == 0 ? message : who + message;
}

SamplingSettings sampling(const StepperSettings& s) {
    SamplingSettings out;
    out.quantiles = s.quantiles;
    out.bed = s.bed;
    out.recorded = s.recorded;
    return out;
}

/// The one reference ICDF a lift command asked for (it asks for its observable's only).
coarse::ReferenceIcdf lift_reference(ReferenceNeeds needs) {
    EFDEM_ASSERT(!(needs.top_half && needs.whole_bed));
    if (needs.top_half) return coarse::ReferenceIcdf::top_half;
    return needs.whole_bed ? coarse::ReferenceIcdf::whole_bed : coarse::ReferenceIcdf::none;
}
}  // namespace

EnsembleStepper::EnsembleStepper(const EnsembleLayout& layout, Realizations local,
                                 const StepperSettings& settings,
                                 coarse::EnsembleObservable& observable, const Lifter& lifter,
                                 SampleSink* sink, Progress* progress)
    : layout_(layout),
      local_(std::move(local)),
      settings_(settings),
      sink_(sink),
      progress_(progress),
      sampler_(layout, sampling(settings), observable),
      lifting_(layout, settings.quantiles, settings.seed, lifter),
      snapshots_(sink),
      failures_(layout, settings.on_failure, [this] { return where_saved(); }) {
    EFDEM_EXPECTS(static_cast<int>(local_.size()) == layout.per_rank());
    long n = 0;
    for (const auto& r : local_) n += r->particles();
    total_particles_ = static_cast<double>(layout_.sum(n));
}

double EnsembleStepper::time() const {
    // The clock of one in the ensemble where there is one (a dropped realization's clock is
    // moved on with the ensemble's, but by sums of its own).
    return failures_.time(local_);
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

void EnsembleStepper::agree_on_stage(const std::string& local_failure, long realization) const {
    const std::string mine =
        local_failure.empty()
            ? std::string()
            : fmt::format("{}; {}", naming(realization, local_failure), where_saved());
    const Agreement agreed =
        agree_on_failure(layout_.mpi().comm(), mine.empty() ? kExitOk : kExitRuntimeFailure, mine);
    if (agreed.exit_code == kExitOk) return;
    if (layout_.is_root()) log::error("{}", agreed.message);
    throw RunFailed(agreed.message);
}

EnsembleStepper::Message EnsembleStepper::broadcast(Message m) const {
    double buf[4] = {static_cast<double>(static_cast<int>(m.command)), m.value, m.needs.code(),
                     m.hold_at_rest ? 1.0 : 0.0};
    MPI_Bcast(buf, 4, MPI_DOUBLE, 0, layout_.mpi().comm());
    return {static_cast<Command>(static_cast<int>(buf[0])), buf[1],
            ReferenceNeeds::from_code(buf[2]), buf[3] != 0.0};
}

// --- the root's side of the commands --------------------------------------------------------

void EnsembleStepper::run(double duration, coarse::BurstSamples& out) {
    if (interrupted_) throw RunInterrupted(interrupted_, time());
    const ReferenceNeeds wanted_icdfs = needs();
    broadcast({Command::run, duration, wanted_icdfs});
    const long wanted = std::lround(duration / settings_.sample_interval);
    const long got = do_run(wanted, wanted_icdfs, &out);
    if (failures_.pending()) throw EnsembleChanged();
    if (got < wanted) throw RunInterrupted(interrupted_, time());
}

void EnsembleStepper::lift(const Eigen::VectorXd& target, double new_time) {
    root_lift(target, nullptr, new_time);
}

bool EnsembleStepper::lifts_apart() const {
    return settings_.lift_members && observable().restricts_members();
}

void EnsembleStepper::lift_apart(const Eigen::VectorXd& target, const Eigen::MatrixXd& member_steps,
                                 double new_time) {
    EFDEM_EXPECTS(lifts_apart());
    root_lift(target, &member_steps, new_time);
}

void EnsembleStepper::root_lift(const Eigen::VectorXd& target, const Eigen::MatrixXd* member_steps,
                                double new_time) {
    const ReferenceNeeds lift_icdfs = ReferenceNeeds::of(observable().reference());
    const bool members =
        lifts_apart();  // cpi.lift = members or own, and an observable with members
    // Holding needs each realization's own coarse vector: only with an observable that has them.
    const bool hold = settings_.hold_at_rest && observable().restricts_members();
    broadcast({members ? Command::lift_members : Command::lift, new_time, lift_icdfs, hold});
    do_lift(new_time, lift_icdfs, &target, members, hold, member_steps);
}

void EnsembleStepper::finish(int exit_code) {
    if (exit_code != kExitInterrupted) snapshots_.release();
    finish_code_ = exit_code;
    broadcast({Command::finish, static_cast<double>(exit_code), false});
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

void EnsembleStepper::begin_steady_solve() {
    settings_.lift_members = false;
    settings_.hold_at_rest = false;
    progress_ = nullptr;
}

void EnsembleStepper::set_parameter(double value) {
    broadcast({Command::set_parameter, value, false});
    do_set_parameter(value);
}

void EnsembleStepper::mark_resume_point(const DriverState& driver) {
    EFDEM_EXPECTS(!snapshots_.has(Use::kept));
    broadcast({Command::resume_point, 0.0, false});
    do_mark_resume_point(driver);
}

std::filesystem::path EnsembleStepper::checkpoint(long sequence, const DriverState& driver) {
    EFDEM_EXPECTS(writer_ != nullptr && !snapshots_.has(Use::kept));
    snapshots_.release();  // the checkpoint stores the output files with every sample so far
    broadcast({Command::checkpoint, static_cast<double>(sequence), false});
    CheckpointHeader header;
    header.stepper = saved_state();
    header.driver = driver;
    return do_checkpoint(sequence, &header, false);
}

std::filesystem::path EnsembleStepper::checkpoint_resume_point() {
    EFDEM_EXPECTS(writer_ != nullptr && has_resume_point());
    const EnsembleSnapshot& resume = snapshots_.get(Use::resume);
    const long sequence = resume.driver.coarse_steps;
    broadcast({Command::checkpoint_resume_point, static_cast<double>(sequence), false});
    CheckpointHeader header;
    header.stepper = resume.stepper;
    header.driver = resume.driver;
    return do_checkpoint(sequence, &header, true);
}

void EnsembleStepper::rebuild_after_failure() {
    EFDEM_EXPECTS(failures_.pending() && has_resume_point());
    const ReferenceNeeds lift_icdfs = ReferenceNeeds::of(observable().reference());
    broadcast({Command::rebuild, 0.0, lift_icdfs});
    do_rebuild(lift_icdfs);
}

// --- the other ranks: the command loop ------------------------------------------------------

void EnsembleStepper::serve() {
    while (true) {
        const Message m = broadcast({Command::finish, 0.0, {}});
        switch (m.command) {
            case Command::run:
                do_run(std::lround(m.value / settings_.sample_interval), m.needs, nullptr);
                break;
            case Command::lift:
                do_lift(m.value, m.needs, nullptr, false, m.hold_at_rest);
                break;
            case Command::lift_members:
                do_lift(m.value, m.needs, nullptr, true, m.hold_at_rest);
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
            case Command::resume_point:
                do_mark_resume_point(DriverState{});
                break;
            case Command::checkpoint_resume_point:
                do_checkpoint(std::lround(m.value), nullptr, true);
                break;
            case Command::rebuild:
                do_rebuild(m.needs);
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

// --- what every rank does for a command -----------------------------------------------------

long EnsembleStepper::do_run(long samples, ReferenceNeeds needs, coarse::BurstSamples* out) {
    const InjectedFailure& inject = settings_.failure;
    const bool can_redo = has_resume_point();
    // A stop signal need not wait for the end of a sample (a paper-size bed's takes seconds,
    // more than mpirun's grace between its SIGTERM and SIGKILL) where there is a state to go back
    // to: the resume point (cpi), or, when a checkpoint can be written (direct), the sample's
    // start kept here.
    const bool keep_sample_start = !can_redo && can_checkpoint();
    Realization::StopCheck stop;
    if (can_redo || keep_sample_start) stop = [] { return stop_signal_received() != 0; };
    std::vector<RealizationState> sample_start;
    std::vector<RealizationFailure> failed;
    for (long s = 0; s < samples; ++s) {
        // (A copy that fails here, out of memory, ends the job as a failed lift's apply does.)
        if (keep_sample_start) sample_start = EnsembleSnapshots::save_realizations(local_);
        long paused = 0;   // particles of this rank's realizations at rest, not advanced
        bool cut = false;  // this rank stopped inside the sample on a stop signal
        for (auto& r : local_) {
            if (!failures_.is_active(r->index())) {
                // Dropped after a failure: not advanced, but its clock keeps time.
                r->set_time(r->time() + static_cast<double>(settings_.steps_per_sample) * r->dt());
                continue;
            }
            if (settings_.pause_at_rest && r->at_rest()) {
                // At rest for good: only its clock moves on.
                r->set_time(r->time() + static_cast<double>(settings_.steps_per_sample) * r->dt());
                paused += r->particles();
                continue;
            }
            if (cut) continue;  // the sample is given up: its state is not used
            try {
                if (!r->advance_unless_stopped(settings_.steps_per_sample, stop)) {
                    cut = true;
                    continue;
                }
                if (!injected_fired_ && !inject.keep_stage && r->index() == inject.realization &&
                    r->time() >= inject.time) {
                    injected_fired_ = true;
                    throw RuntimeFailure("injected failure (debug.fail_realization)", r->index());
                }
            } catch (const std::exception& e) {
                failed.push_back({r->index(), e.what()});
            }
        }
        const FailureAgreement::Agreed agreed =
            failures_.agree(local_, failed, stop_signal_received(), cut, can_redo, sink_);
        const int signal = agreed.signal;
        failed.clear();
        if (agreed.cut && !failures_.pending()) {
            // Stopped inside the sample somewhere: no rank uses it, and the counters stay those
            // of its start. Direct: back to that start (the checkpoint's state); cpi: the
            // checkpoint is the resume point's.
            if (keep_sample_start)
                restore_agreed(sample_start, "the start of a sample cut by a stop signal");
            interrupted_ = signal;
            return s;
        }
        micro_time_ += static_cast<double>(settings_.steps_per_sample) * local_.front()->dt();
        if (settings_.pause_at_rest)  // what was computed: the paused particles left out
            MPI_Allreduce(MPI_IN_PLACE, &paused, 1, MPI_LONG, MPI_SUM, layout_.mpi().comm());
        particle_steps_ += static_cast<double>(settings_.steps_per_sample) *
                           (total_particles_ - static_cast<double>(paused));
        if (failures_.pending()) return s;  // cpi: the step is redone from its resume point
        if (const SampleRecord* rec =
                sampler_.take(local_, failures_.active(), time(), needs, out)) {
            const double start = MPI_Wtime();
            note_rest(*rec);
            snapshots_.record(*rec);
            record_seconds_ += MPI_Wtime() - start;  // recording counts as restriction
            if (progress_) progress_->update(rec->time, particle_steps_, "");
        }
        ++samples_taken_;
        for (auto& r : local_) {
            if (!failures_.is_active(r->index())) continue;
            try {
                r->after_sample(samples_taken_);
            } catch (const std::exception& e) {
                failed.push_back({r->index(), e.what()});
            }
        }
        failures_.agree(local_, failed, 0, false, can_redo, sink_);
        failed.clear();
        if (failures_.pending()) return s + 1;
        if (signal != 0) {
            interrupted_ = signal;
            return s + 1;
        }
    }
    return samples;
}

void EnsembleStepper::restore_agreed(const std::vector<RealizationState>& states,
                                     const char* where) {
    std::string failure;
    try {
        EnsembleSnapshots::restore_realizations(local_, states);
    } catch (const std::exception& e) {
        failure = std::string("going back to ") + where + ": " + e.what();
    }
    agree_on_stage(failure, local_.front()->index());
}

void EnsembleStepper::note_rest(const SampleRecord& rec) {
    bool all = rec.realizations_used > 0;
    any_at_rest_ = false;
    for (Eigen::Index r = 0; r < rec.at_rest.size(); ++r) {
        if (!std::isnan(rec.at_rest[r]) && rec.at_rest[r] != 1.0) all = false;
        if (rec.at_rest[r] == 1.0) any_at_rest_ = true;
    }
    if (!all)
        at_rest_since_ = std::numeric_limits<double>::quiet_NaN();
    else if (std::isnan(at_rest_since_))
        at_rest_since_ = rec.time;
}

void EnsembleStepper::do_lift(double new_time, ReferenceNeeds needs, const Eigen::VectorXd* target,
                              bool members, bool hold, const Eigen::MatrixXd* member_steps) {
    EnsembleLifting::Request request;
    request.hold_at_rest = hold;
    request.new_time = new_time;
    request.reference = lift_reference(needs);
    request.members = members;
    request.target = target;
    request.member_steps = member_steps;
    lifting_.lift(local_, failures_.active(), observable(), request);
}

std::filesystem::path EnsembleStepper::do_checkpoint(long sequence, const CheckpointHeader* header,
                                                     bool at_resume_point) {
    const double start = MPI_Wtime();
    try {
        if (at_resume_point) {
            const EnsembleSnapshot& resume = snapshots_.get(Use::resume);
            last_checkpoint_ = writer_->write(sequence, resume.realizations, header);
            last_checkpoint_time_ = resume.time;
        } else {
            std::vector<RealizationState> states = EnsembleSnapshots::save_realizations(local_);
            last_checkpoint_ = writer_->write(sequence, states, header);
            last_checkpoint_time_ = time();
        }
        last_checkpoint_seconds_ = MPI_Wtime() - start;
        return last_checkpoint_;
    } catch (const CheckpointWriteError& e) {
        // Every rank knows it at once: they end together, and the root marks the run file.
        if (layout_.is_root()) log::error("{}", e.what());
        throw RunFailed(e.what());
    } catch (const std::exception& e) {
        layout_.mpi().abort(fmt::format("writing checkpoint {}: {}", sequence, e.what()),
                            kExitRuntimeFailure);
    }
}

EnsembleSnapshot EnsembleStepper::snapshot(const char* when) const {
    EnsembleSnapshot s;
    std::string failure;
    try {
        const InjectedFailure& inject = settings_.failure;
        if (inject.keep_stage)
            for (const auto& r : local_)
                if (r->index() == inject.realization && r->time() >= inject.time)
                    throw std::runtime_error("injected failure (debug.fail_stage = keep)");
        s.realizations = EnsembleSnapshots::save_realizations(local_);
    } catch (const std::exception& e) {
        failure = std::string("keeping the state ") + when + ": " + e.what();
    }
    agree_on_stage(failure, local_.front()->index());
    s.time = time();
    s.stepper = saved_state();
    s.last_sample = sampler_.last();
    s.coarse = sampler_.last_coarse();
    return s;
}

void EnsembleStepper::return_to(const EnsembleSnapshot& s, const char* when, bool keep_membership) {
    at_rest_since_ = std::numeric_limits<double>::quiet_NaN();
    restore_agreed(s.realizations, when);
    // The discarded work was done: it stays in the cost.
    const double micro = micro_time_, steps = particle_steps_;
    StepperState now;
    failures_.save(now);
    restore_state(s.stepper);
    micro_time_ = micro;
    particle_steps_ = steps;
    if (keep_membership) failures_.restore(now);
}

void EnsembleStepper::do_keep() {
    snapshots_.keep(snapshot("before a projective jump"));
}

void EnsembleStepper::do_go_back() {
    const EnsembleSnapshot kept = snapshots_.go_back();
    return_to(kept, "the state before a rejected jump", false);
    // The last sample is the kept one again; its coarse vector stays the rejected burst's last
    // (as before the re-cut: a resume point marked right after a rejection keeps that one).
    sampler_.set_last(kept.last_sample);
}

void EnsembleStepper::do_confirm() {
    snapshots_.confirm();
}

void EnsembleStepper::do_mark_resume_point(const DriverState& driver) {
    EnsembleSnapshot s = snapshot("between coarse steps");
    s.driver = driver;
    snapshots_.set_resume_point(std::move(s));
}

void EnsembleStepper::do_set_parameter(double value) {
    EFDEM_EXPECTS(!settings_.parameter.empty());
    for (auto& r : local_) r->set_parameter(settings_.parameter, value);
}

void EnsembleStepper::do_rebuild(ReferenceNeeds needs) {
    EFDEM_EXPECTS(failures_.pending() && has_resume_point());
    // 1. Every realization back to where the interrupted coarse step began; the samples since
    //    then are dropped.
    const EnsembleSnapshot& resume = snapshots_.get(Use::resume);
    snapshots_.back_to_resume_point();
    return_to(resume, "the resume point after a failure", true);
    sampler_.set_last(resume.last_sample, resume.coarse);
    // 2. Drop, or rebuild from the next healthy realization (before the first coarse step, at
    //    the run's start, from its own initial state: there is no ensemble state to lift to).
    int lift_flag = layout_.is_root() ? (resume.coarse.size() > 0 ? 1 : 0) : 1;
    MPI_Bcast(&lift_flag, 1, MPI_INT, 0, layout_.mpi().comm());
    const FailureAgreement::Rebuild plan = failures_.plan_rebuild(lift_flag != 0);
    if (plan.replace) {
        failures_.send_donor_states(plan, resume.realizations, local_);
        if (layout_.is_root())
            for (long f : plan.failed)  // a fresh lifting stream of its own, never used before
                lifting_.renew_stream(f, failures_.failures());
    }
    // 3. Lifted at once to the ensemble's coarse state at the resume point, so that the copy
    //    leaves its donor's trajectory from the first step on.
    if (plan.replace && lift_flag) {
        EnsembleLifting::Request request;
        request.new_time = resume.time;
        request.reference = lift_reference(needs);
        request.target = layout_.is_root() ? &resume.coarse : nullptr;
        request.only = &plan.rebuilt;
        lifting_.lift(local_, failures_.active(), observable(), request);
    }
    failures_.finish_rebuild(plan, resume.time, sink_);
    // 4. The rebuilt ensemble is the new resume point (a stop now checkpoints it), with the
    //    loop's state of the old one.
    const DriverState driver = resume.driver;
    do_mark_resume_point(driver);
}

StepperState EnsembleStepper::saved_state() const {
    StepperState s;
    s.samples_taken = samples_taken_;
    s.micro_time = micro_time_;
    s.particle_steps = particle_steps_;
    s.wall_seconds = progress_ ? wall_before_ + progress_->elapsed_seconds()
                               : std::numeric_limits<double>::quiet_NaN();
    sampler_.save(s);
    lifting_.save(s);
    failures_.save(s);
    return s;
}

void EnsembleStepper::restore_state(const StepperState& s) {
    samples_taken_ = s.samples_taken;
    micro_time_ = s.micro_time;
    particle_steps_ = s.particle_steps;
    failures_.restore(s);
    sampler_.restore(s);
    lifting_.restore(s);
    // The test-only injected failure happens once per run: a state that has survived a failure
    // (a restart after a replace, say) must not see it again. Never reset: going back to a state
    // kept before it does not undo it.
    injected_fired_ = injected_fired_ || (settings_.failure.realization >= 0 && s.failures > 0);
}

}  // namespace efdem::mpi_driver
