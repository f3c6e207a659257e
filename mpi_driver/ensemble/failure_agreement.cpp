#include "mpi_driver/ensemble/failure_agreement.hpp"

#include <algorithm>
#include <utility>

#include <fmt/format.h>
#include <mpi.h>

#include "core/contracts.hpp"
#include "core/log.hpp"

namespace efdem::mpi_driver {

namespace {
/// "realization R: MESSAGE", unless the message names it already.
std::string naming(long realization, const std::string& message) {
    const std::string who = fmt::format("realization {}: ", realization);
    return message.rfind(who, 0) == 0 ? message : who + message;
}
}  // namespace

FailureAgreement::FailureAgreement(const EnsembleLayout& layout, const FailurePolicy& policy,
                                   std::function<std::string()> where_saved)
    : layout_(layout),
      policy_(policy),
      where_saved_(std::move(where_saved)),
      active_(static_cast<std::size_t>(layout.size()), 1) {}

int FailureAgreement::active_count() const {
    return static_cast<int>(std::count(active_.begin(), active_.end(), char{1}));
}

double FailureAgreement::time(const Realizations& local) const {
    for (const auto& r : local)
        if (is_active(r->index())) return r->time();
    return local.front()->time();
}

void FailureAgreement::save(StepperState& s) const {
    s.active.assign(active_.begin(), active_.end());
    s.failures = failures_;
}

void FailureAgreement::restore(const StepperState& s) {
    if (!s.active.empty()) {
        EFDEM_EXPECTS(s.active.size() == active_.size());
        for (std::size_t r = 0; r < active_.size(); ++r) active_[r] = s.active[r] != 0 ? 1 : 0;
    }
    failures_ = s.failures;
}

FailureAgreement::Agreed FailureAgreement::agree(const Realizations& local,
                                                 const std::vector<RealizationFailure>& mine,
                                                 int signal, bool cut, bool can_redo,
                                                 SampleSink* sink) {
    int here[3] = {signal, static_cast<int>(mine.size()), cut ? 1 : 0};
    int global[3] = {0, 0, 0};
    MPI_Allreduce(here, global, 3, MPI_INT, MPI_MAX, layout_.mpi().comm());
    if (global[1] > 0) on_failures(local, mine, can_redo, sink);
    return {global[0], global[2] != 0};
}

std::vector<std::string> FailureAgreement::gather_messages(
    const Realizations& local, const std::vector<RealizationFailure>& failures) const {
    std::vector<std::vector<std::uint8_t>> mine(local.size());
    for (const RealizationFailure& f : failures)
        mine[static_cast<std::size_t>(f.realization - layout_.first_index())].assign(
            f.message.begin(), f.message.end());
    std::vector<std::string> out;
    for (const auto& m : layout_.gather_arrays(mine)) out.emplace_back(m.begin(), m.end());
    return out;
}

void FailureAgreement::on_failures(const Realizations& local,
                                   const std::vector<RealizationFailure>& failures, bool can_redo,
                                   SampleSink* sink) {
    // Which realizations failed: every rank learns the same set.
    const auto R = static_cast<std::size_t>(layout_.size());
    std::vector<int> mine(R, 0), all(R, 0);
    for (const RealizationFailure& f : failures) mine[static_cast<std::size_t>(f.realization)] = 1;
    MPI_Allreduce(mine.data(), all.data(), static_cast<int>(R), MPI_INT, MPI_MAX,
                  layout_.mpi().comm());
    std::vector<long> failed;
    for (std::size_t r = 0; r < R; ++r)
        if (all[r]) failed.push_back(static_cast<long>(r));
    const long total = failures_ + static_cast<long>(failed.size());
    const int healthy = active_count() - static_cast<int>(failed.size());
    const bool drop = policy_.action == FailurePolicy::Action::drop;
    // Why the run cannot survive these failures (empty: it can; abort needs no reason).
    std::string fatal;
    if (total > policy_.max_failures)
        fatal = fmt::format("{} realization failures, more than ensemble.max_failures = {}", total,
                            policy_.max_failures);
    else if ((drop ? healthy : healthy + static_cast<int>(failed.size())) < policy_.min_active ||
             healthy < 1)
        fatal = fmt::format("only {} healthy realization(s) would remain; the run needs {}",
                            healthy, policy_.min_active);
    if (policy_.action == FailurePolicy::Action::abort) fail_agreed(local, failures);
    if (!fatal.empty()) {
        std::vector<RealizationFailure> told = failures;
        for (RealizationFailure& f : told) f.message += "; the run ends: " + fatal;
        fail_agreed(local, told);
    }
    for (const RealizationFailure& f : failures)
        log::rank_warn(
            "realization {} at t = {:.6g}: {}; {} (ensemble.on_failure)", f.realization,
            time(local), f.message,
            drop ? "dropped from the ensemble" : "to be rebuilt from a healthy realization");
    const std::vector<std::string> reasons = gather_messages(local, failures);
    failures_ = total;
    if (!can_redo) {
        // Direct: every whole sample is a safe point; the realization leaves the ensemble here.
        EFDEM_EXPECTS(drop);
        for (long f : failed) active_[static_cast<std::size_t>(f)] = 0;
        if (layout_.is_root() && sink)
            for (long f : failed)
                sink->failure({time(local), f, reasons[static_cast<std::size_t>(f)], "dropped", -1,
                               time(local), active_count()});
        return;
    }
    // cpi: the coarse step is redone from its resume point with the changed ensemble.
    pending_ = failed;
    pending_reasons_ = reasons;
    pending_time_ = time(local);
}

void FailureAgreement::fail_agreed(const Realizations& local,
                                   const std::vector<RealizationFailure>& failures) const {
    // The failing rank says what failed (with its rank in the prefix); the root gets the
    // messages so that the run file can say it too.
    for (const RealizationFailure& f : failures) {
        const std::string text =
            fmt::format("{}; {}", naming(f.realization, f.message), where_saved_());
        log::rank_error("{}", text);
    }
    const std::vector<std::string> all = gather_messages(local, failures);
    std::string summary;
    for (std::size_t r = 0; r < all.size(); ++r)
        if (!all[r].empty())
            summary += fmt::format("{}realization {} at t = {:.6g}: {}",
                                   summary.empty() ? "" : "; ", r, time(local), all[r]);
    throw RunFailed(summary.empty() ? std::string("a realization failed (see the messages above)")
                                    : summary);
}

FailureAgreement::Rebuild FailureAgreement::plan_rebuild(bool can_lift) {
    EFDEM_EXPECTS(pending());
    Rebuild plan;
    plan.replace = policy_.action == FailurePolicy::Action::replace;
    plan.failed = pending_;
    plan.donors.assign(plan.failed.size(), -1);
    plan.rebuilt.assign(active_.size(), 0);
    const auto R = static_cast<long>(active_.size());
    for (std::size_t i = 0; i < plan.failed.size(); ++i) {
        const long f = plan.failed[i];
        if (!plan.replace) {
            active_[static_cast<std::size_t>(f)] = 0;
            continue;
        }
        for (long step = 1; step < R && can_lift; ++step) {
            const long d = (f + step) % R;
            if (active_[static_cast<std::size_t>(d)] &&
                std::find(plan.failed.begin(), plan.failed.end(), d) == plan.failed.end()) {
                plan.donors[i] = d;
                break;
            }
        }
        plan.rebuilt[static_cast<std::size_t>(f)] = 1;
    }
    return plan;
}

void FailureAgreement::send_donor_states(const Rebuild& plan,
                                         const std::vector<RealizationState>& at_resume,
                                         Realizations& local) const {
    // The donor's state at the resume point goes to the failed realization's rank.
    const long k = layout_.per_rank();
    const int me = layout_.mpi().rank();
    for (std::size_t i = 0; i < plan.failed.size(); ++i) {
        if (plan.donors[i] < 0) continue;
        const long failed = plan.failed[i], donor = plan.donors[i];
        const int from = static_cast<int>(donor / k), to = static_cast<int>(failed / k);
        RealizationState state;
        if (from == me) state = at_resume[static_cast<std::size_t>(donor % k)];
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
            state.index = failed;
            local[static_cast<std::size_t>(failed % k)]->restore_state(state);
        }
    }
}

void FailureAgreement::finish_rebuild(const Rebuild& plan, double resumed_at, SampleSink* sink) {
    if (layout_.is_root() && sink)
        for (std::size_t i = 0; i < plan.failed.size(); ++i)
            sink->failure({pending_time_, plan.failed[i],
                           pending_reasons_[static_cast<std::size_t>(plan.failed[i])],
                           plan.replace ? "replaced" : "dropped", plan.donors[i], resumed_at,
                           active_count()});
    pending_.clear();
    pending_reasons_.clear();
}

}  // namespace efdem::mpi_driver
