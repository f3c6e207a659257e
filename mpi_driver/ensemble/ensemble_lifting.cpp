#include "mpi_driver/ensemble/ensemble_lifting.hpp"

#include <limits>
#include <string>

#include <fmt/format.h>
#include <mpi.h>

#include "core/contracts.hpp"

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
/// The member steps of a lift apart, their mean over the finite rows taken out (a non-finite row
/// becomes zero: the common increment alone); empty when there are none or their rows do not
/// match the n lifted realizations (the ensemble changed since the burst).
Eigen::MatrixXd centred_steps(const Eigen::MatrixXd* steps, long n, Eigen::Index m) {
    if (!steps || steps->rows() != n || steps->cols() != m) return {};
    Eigen::MatrixXd out = *steps;
    Eigen::VectorXd sum = Eigen::VectorXd::Zero(m);
    long finite = 0;
    for (Eigen::Index k = 0; k < out.rows(); ++k) {
        if (!out.row(k).allFinite()) {
            out.row(k).setZero();
            continue;
        }
        sum += out.row(k).transpose();
        ++finite;
    }
    if (finite == 0) return {};
    const Eigen::VectorXd mean = sum / static_cast<double>(finite);
    for (Eigen::Index k = 0; k < out.rows(); ++k)
        if (steps->row(k).allFinite()) out.row(k) -= mean.transpose();
    return out;
}
}  // namespace

void EnsembleLifting::lift(Realizations& local, const std::vector<char>& active,
                           coarse::EnsembleObservable& observable, const Request& request) {
    const double start = MPI_Wtime();
    const bool top = request.top_half, members = request.members;
    const std::vector<char>* only = request.only;
    const Eigen::VectorXd* target = request.target;
    auto lifted_here = [&](long index) {
        return active[static_cast<std::size_t>(index)] != 0 &&
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
    for (const auto& r : local) {
        if (!lifted_here(r->index())) {
            // Dropped, or not among `only`: nothing sent, nothing changed.
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
        EFDEM_EXPECTS(target != nullptr);
        last_ = LiftRecord{};
        // Each lifted realization's own X and their mean, in realization order (the same sum on
        // any layout); the increment target - mean moves every one of them alike.
        Eigen::MatrixXd own, steps;
        Eigen::VectorXd increment;
        if (members) {
            own = observable.restrict_members(all_own, all_top);
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
            steps = centred_steps(request.member_steps, n, target->size());
        }
        long k = 0;  // the lifted realizations so far: row k of the steps
        for (int r = 0; r < layout_.size(); ++r) {
            if (!lifted_here(r)) {
                last_.changed.push_back(0);
                last_.max_deviation.push_back(std::numeric_limits<double>::quiet_NaN());
                last_.messages.emplace_back(active[static_cast<std::size_t>(r)] ? "" : "dropped");
                lifted_reals.emplace_back();
                lifted_bytes.emplace_back();
                continue;
            }
            Eigen::VectorXd x = *target;
            std::string repaired;
            if (members) {
                x = own.row(r).transpose() + increment;
                if (steps.rows() > 0) x += steps.row(k).transpose();
                ++k;
                if (member_repair_) {
                    const coarse::RepairReport report = member_repair_(x);
                    if (report.changed())
                        repaired = fmt::format(
                            "its own target (X_r + increment) repaired by up to {:.3g} d_p",
                            report.max_adjustment);
                }
            }
            const Eigen::VectorXd goal = observable.lift_target(
                x, top ? Eigen::VectorXd(all_top.row(r).transpose()) : Eigen::VectorXd());
            LiftOutcome res = lifter_.lift(goal, {all_reals[r], all_bytes[r]}, grid_,
                                           streams_[static_cast<std::size_t>(r)]);
            last_.changed.push_back(res.changed);
            last_.max_deviation.push_back(res.max_deviation);
            last_.messages.push_back(repaired.empty() || res.message.empty()
                                         ? repaired + res.message
                                         : repaired + "; " + res.message);
            lifted_reals.push_back(std::move(res.payload.reals));
            lifted_bytes.push_back(std::move(res.payload.bytes));
        }
    }
    const auto my_reals = layout_.scatter_arrays(lifted_reals, out_reals);
    const auto my_bytes = layout_.scatter_arrays(lifted_bytes, out_bytes);
    for (std::size_t j = 0; j < local.size(); ++j) {
        if (lifted_here(local[j]->index())) {
            local[j]->apply_lift({my_reals[j], my_bytes[j]});
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
