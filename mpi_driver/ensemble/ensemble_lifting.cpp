#include "mpi_driver/ensemble/ensemble_lifting.hpp"

#include <limits>
#include <string>

#include <fmt/format.h>
#include <mpi.h>

#include "coarse/equation_free/projective/multistep_projection.hpp"  // rms
#include "core/contracts.hpp"
#include "mpi_driver/ensemble/reference_rows.hpp"

namespace efdem::mpi_driver {

EnsembleLifting::EnsembleLifting(const EnsembleLayout& layout, int quantiles, std::uint64_t seed,
                                 const Lifter& lifter)
    : layout_(layout), grid_(quantiles), seed_(seed), lifter_(lifter) {
    if (layout_.is_root())
        for (int r = 0; r < layout_.size(); ++r)
            streams_.emplace_back(seed, static_cast<std::uint64_t>(r), "lifting");
}

void EnsembleLifting::renew_stream(long realization, long failures) {
    EFDEM_EXPECTS(layout_.is_root());
    const auto R = static_cast<long>(layout_.size());
    streams_[static_cast<std::size_t>(realization)] =
        RandomStream(seed_, static_cast<std::uint64_t>(realization + R * failures), "lifting");
}

void EnsembleLifting::save(StepperState& s) const {
    for (const auto& l : streams_) s.lifting.push_back(l.state());
}

void EnsembleLifting::restore(const StepperState& s) {
    if (!layout_.is_root()) return;
    EFDEM_EXPECTS(s.lifting.size() == streams_.size());
    for (std::size_t r = 0; r < streams_.size(); ++r) streams_[r].set_state(s.lifting[r]);
}

namespace {
/// The member steps of a lift apart, their mean over the finite rows of the moving realizations
/// (`moving`, one flag per row) taken out; a non-finite row, or the row of a realization held at
/// rest, becomes zero (the common increment alone). Empty when there are none or their rows do not
/// match the n lifted realizations (the ensemble changed since the burst).
Eigen::MatrixXd centred_steps(const Eigen::MatrixXd* steps, const std::vector<char>& moving,
                              Eigen::Index m) {
    const auto n = static_cast<Eigen::Index>(moving.size());
    if (!steps || steps->rows() != n || steps->cols() != m) return {};
    Eigen::MatrixXd out = *steps;
    Eigen::VectorXd sum = Eigen::VectorXd::Zero(m);
    std::vector<char> kept(static_cast<std::size_t>(n), 0);
    long finite = 0;
    for (Eigen::Index k = 0; k < n; ++k) {
        if (!moving[static_cast<std::size_t>(k)] || !out.row(k).allFinite()) {
            out.row(k).setZero();
            continue;
        }
        kept[static_cast<std::size_t>(k)] = 1;
        sum += out.row(k).transpose();
        ++finite;
    }
    if (finite == 0) return {};
    const Eigen::VectorXd mean = sum / static_cast<double>(finite);
    for (Eigen::Index k = 0; k < n; ++k)
        if (kept[static_cast<std::size_t>(k)]) out.row(k) -= mean.transpose();
    return out;
}

constexpr const char* kHeld = "at rest: left where it is";
}  // namespace

void EnsembleLifting::lift(Realizations& local, const std::vector<char>& active,
                           coarse::EnsembleObservable& observable, const Request& request) {
    const double start = MPI_Wtime();
    const bool members = request.members;
    const coarse::ReferenceIcdf kind = request.reference;
    const bool reference = kind != coarse::ReferenceIcdf::none;
    const std::vector<char>* only = request.only;
    const Eigen::VectorXd* target = request.target;
    const bool hold = request.hold_at_rest && !only;
    auto lifted_here = [&](long index) {
        return active[static_cast<std::size_t>(index)] != 0 &&
               (!only || (*only)[static_cast<std::size_t>(index)] != 0);
    };
    const auto m = static_cast<Eigen::Index>(grid_.values().size());
    const double nan = std::numeric_limits<double>::quiet_NaN();
    // cpi.lift = members (and any lift that holds realizations at rest): every realization's own
    // X now, to move the others by the ensemble's increment (a rebuild after a failure lifts to
    // the target itself).
    EFDEM_EXPECTS(!members || !only);
    const bool own_needed = members || hold;
    std::vector<std::vector<double>> reals;
    std::vector<std::vector<std::uint8_t>> bytes, rest_flag;
    std::vector<Eigen::VectorXd> own_icdf;
    ReferenceRows references(ReferenceNeeds::of(kind), m);
    std::vector<std::size_t> out_reals, out_bytes;
    for (const auto& r : local) {
        const bool lifted = lifted_here(r->index());
        const bool held = lifted && hold && r->at_rest();
        rest_flag.push_back({static_cast<std::uint8_t>(held ? 1 : 0)});
        if (!lifted) {
            // Dropped, or not among `only`: nothing sent, nothing changed.
            reals.emplace_back();
            bytes.emplace_back();
            references.add_missing();
            if (own_needed) own_icdf.push_back(Eigen::VectorXd::Constant(m, nan));
            out_reals.push_back(0);
            out_bytes.push_back(0);
            continue;
        }
        if (held) {  // its own X only: it is not lifted
            reals.emplace_back();
            bytes.emplace_back();
        } else {
            LiftPayload in = r->lift_input();
            reals.push_back(std::move(in.reals));
            bytes.push_back(std::move(in.bytes));
        }
        if (reference || own_needed) {
            Observation o = r->observe(grid_, ReferenceNeeds::of(kind));
            references.add(o);
            if (own_needed) own_icdf.push_back(std::move(o.icdf));
        }
        const auto [nr, nb] =
            held ? std::pair<std::size_t, std::size_t>{0, 0} : r->lift_output_sizes();
        out_reals.push_back(nr);
        out_bytes.push_back(nb);
    }
    const auto all_reals = layout_.gather_arrays(reals);
    const auto all_bytes = layout_.gather_arrays(bytes);
    const auto all_rest = layout_.gather_arrays(rest_flag);
    references.gather(layout_);
    const Eigen::MatrixXd& all_reference = references.rows(kind);
    const Eigen::MatrixXd all_own = own_needed ? layout_.gather_rows(own_icdf) : Eigen::MatrixXd();

    std::vector<std::vector<double>> lifted_reals;
    std::vector<std::vector<std::uint8_t>> lifted_bytes;
    if (layout_.is_root()) {
        EFDEM_EXPECTS(target != nullptr);
        last_ = LiftRecord{};
        last_.changed_what = lifter_.changed_what();
        failure_.clear();
        auto is_held = [&](int r) {
            return !all_rest[static_cast<std::size_t>(r)].empty() &&
                   all_rest[static_cast<std::size_t>(r)][0] != 0;
        };
        // Each lifted realization's own X, the sum over them and over those held, in realization
        // order (the same sums on any layout). The moving ones carry the whole increment.
        Eigen::MatrixXd own, steps;
        Eigen::VectorXd moving_target, increment;
        std::vector<char> moving;  // per lifted realization, in order
        long held_count = 0;
        if (own_needed) {
            own = observable.restrict_members(all_own, all_reference);
            EFDEM_ASSERT(own.rows() == layout_.size() && own.cols() == target->size());
            Eigen::VectorXd sum = Eigen::VectorXd::Zero(target->size());
            Eigen::VectorXd sum_held = sum;
            for (int r = 0; r < layout_.size(); ++r)
                if (lifted_here(r)) {
                    sum += own.row(r).transpose();
                    moving.push_back(is_held(r) ? 0 : 1);
                    if (is_held(r)) {
                        sum_held += own.row(r).transpose();
                        ++held_count;
                    }
                }
            const auto n = static_cast<double>(moving.size());
            const auto n_moving = n - static_cast<double>(held_count);
            EFDEM_ASSERT(n > 0);
            if (n_moving > 0) {
                increment = (n * *target - sum) / n_moving;
                moving_target = (n * *target - sum_held) / n_moving;
            }
            if (members) steps = centred_steps(request.member_steps, moving, target->size());
        }
        long k = 0;  // the lifted realizations so far: row k of the steps
        // The lift's error in the ensemble mean over the k lifted: those held at rest are at
        // their own X_r (0).
        Eigen::VectorXd deviation_sum = Eigen::VectorXd::Zero(target->size());
        for (int r = 0; r < layout_.size(); ++r) {
            if (!lifted_here(r) || is_held(r)) {
                last_.changed.push_back(0);
                last_.max_deviation.push_back(std::numeric_limits<double>::quiet_NaN());
                last_.at_rest.push_back(lifted_here(r) ? 1 : 0);
                last_.messages.emplace_back(
                    !lifted_here(r) ? (active[static_cast<std::size_t>(r)] ? "" : "dropped")
                                    : kHeld);
                lifted_reals.emplace_back();
                lifted_bytes.emplace_back();
                if (lifted_here(r)) ++k;
                continue;
            }
            Eigen::VectorXd x = *target;
            std::string repaired;
            if (members || held_count > 0) {
                x = members ? Eigen::VectorXd(own.row(r).transpose() + increment) : moving_target;
                if (steps.rows() > 0) x += steps.row(k).transpose();
                if (member_repair_) {
                    const coarse::RepairReport report = member_repair_(x);
                    if (report.changed())
                        repaired = fmt::format(
                            "its own target ({}) repaired by up to {:.3g} d_p",
                            members ? "X_r + increment" : "the moving realizations' mean",
                            report.max_adjustment);
                }
            }
            ++k;
            const Eigen::VectorXd goal = observable.lift_target(
                x,
                reference ? Eigen::VectorXd(all_reference.row(r).transpose()) : Eigen::VectorXd());
            LiftOutcome res = lifter_.lift(goal, {all_reals[r], all_bytes[r]}, grid_,
                                           streams_[static_cast<std::size_t>(r)]);
            last_.changed.push_back(res.changed);
            last_.max_deviation.push_back(res.max_deviation);
            if (res.failure.empty() && res.deviation.size() == target->size())
                deviation_sum += res.deviation;
            last_.at_rest.push_back(0);
            last_.messages.push_back(repaired.empty() || res.message.empty()
                                         ? repaired + res.message
                                         : repaired + "; " + res.message);
            if (!res.failure.empty()) {
                failure_ += fmt::format("{}realization {}: {}", failure_.empty() ? "" : "; ", r,
                                        res.failure);
                last_.messages.back() +=
                    (last_.messages.back().empty() ? "" : "; ") + ("not lifted: " + res.failure);
            }
            lifted_reals.push_back(std::move(res.payload.reals));
            lifted_bytes.push_back(std::move(res.payload.bytes));
        }
        if (k > 0 && target->size() > 0)
            last_.error = coarse::rms(deviation_sum / static_cast<double>(k));
    }
    const auto my_reals = layout_.scatter_arrays(lifted_reals, out_reals);
    const auto my_bytes = layout_.scatter_arrays(lifted_bytes, out_bytes);
    for (std::size_t j = 0; j < local.size(); ++j) {
        if (lifted_here(local[j]->index())) {
            if (rest_flag[j][0] == 0) local[j]->apply_lift({my_reals[j], my_bytes[j]});
            local[j]->set_time(request.new_time);
        } else if (!only) {
            // A dropped realization's clock follows the jump too: a rank whose realizations were
            // all dropped still knows the ensemble's time.
            local[j]->set_time(request.new_time);
        }
    }
    seconds_ += MPI_Wtime() - start;
    ++count_;
}

}  // namespace efdem::mpi_driver
