#include "mpi_driver/checkpoint_data/checkpoint_format.hpp"

#include <cmath>

#include <cctype>

#include <fmt/format.h>

#include "mpi_driver/checkpoint_data/realization_state.hpp"

namespace efdem::mpi_driver {

namespace {
template <class T>
std::uint64_t hash_value(const T& v, std::uint64_t h) {
    return fnv1a(&v, sizeof v, h);
}
std::uint64_t hash_text(const std::string& s, std::uint64_t h) {
    h = hash_value(static_cast<std::uint64_t>(s.size()), h);
    return fnv1a(s.data(), s.size(), h);
}
std::uint64_t hash_vector(const Eigen::VectorXd& v, std::uint64_t h) {
    h = hash_value(static_cast<std::uint64_t>(v.size()), h);
    return v.size() == 0 ? h
                         : fnv1a(v.data(), static_cast<std::size_t>(v.size()) * sizeof(double), h);
}
/// Format 4: every field of the integrator's state, in the order of coarse::MultistepState.
std::uint64_t hash_integrator(const coarse::IntegratorState& state, std::uint64_t h) {
    h = hash_value(state ? 1L : 0L, h);
    if (!state) return h;
    const coarse::MultistepState& s = *state;
    h = hash_value(s.t_end, h);
    h = hash_vector(s.x_end, h);
    h = hash_value(static_cast<std::uint64_t>(s.history.size()), h);
    for (const auto& n : s.history) {
        h = hash_value(n.tau, h);
        h = hash_vector(n.slope, h);
        h = hash_vector(n.se, h);
    }
    h = hash_value(s.curvature_only_front ? 1L : 0L, h);
    h = hash_value(s.decay.ok ? 1L : 0L, h);
    for (double d : {s.decay.rate, s.decay.ratio, s.decay.delay}) h = hash_value(d, h);
    h = hash_text(s.decay.message, h);
    h = hash_text(std::string(coarse::to_string(s.hold_kind)), h);
    h = hash_text(s.hold, h);
    h = hash_value(s.controller.dt_last, h);
    h = hash_value(s.controller.dt_cap, h);
    h = hash_value(s.controller.consecutive_rejections, h);
    const coarse::MultistepTotals& t = s.totals;
    for (long v : {t.attempts, t.accepted, t.rejected, t.direct}) h = hash_value(v, h);
    for (double d : {t.dt_taken, t.dt_tolerance, t.dt_tolerance_2r, t.dt_tolerance_4r,
                     t.statistical, t.truncation})
        h = hash_value(d, h);
    // Written before cpi.healing_auto / the pool: the checksum such a file was written with.
    if (!std::isnan(s.healing)) h = hash_value(s.healing, h);
    if (!std::isnan(s.lift_reserve)) h = hash_value(s.lift_reserve, h);
    // Files written before it hold none (0) and keep their checksum.
    if (s.realizations > 0) h = hash_value(static_cast<long>(s.realizations), h);
    // cpi.lift = own only (files of other runs keep the checksum they had before it).
    if (s.member_deviation.size() > 0) {
        h = hash_value(static_cast<long>(s.member_deviation.rows()), h);
        h = fnv1a(s.member_deviation.data(),
                  static_cast<std::size_t>(s.member_deviation.size()) * sizeof(double), h);
    }
    // cpi.accuracy only (files of other runs keep the checksum they had before it).
    if (!std::isnan(s.budget.sigma))
        for (double d : {s.budget.variance, s.budget.truncation, s.budget.t_last, s.budget.sigma,
                         s.budget.last_rate, s.budget.rate})
            h = hash_value(d, h);
    if (s.pool.empty()) return h;
    h = hash_value(static_cast<std::uint64_t>(s.pool.size()), h);
    for (const coarse::PooledBurst& b : s.pool) {
        h = hash_value(b.node.tau, h);
        h = hash_vector(b.node.slope, h);
        h = hash_vector(b.node.se, h);
        h = hash_value(b.commitment, h);
    }
    // cpi.window_auto only (files of other runs keep the checksum they had before it).
    if (std::isnan(s.window)) return h;
    h = hash_value(s.window, h);
    h = hash_value(s.window_fast_time2, h);
    return hash_value(static_cast<long>(s.window_measurements), h);
}
}  // namespace

std::uint64_t CheckpointHeader::checksum() const {
    std::uint64_t h = hash_value(format_version, 0xcbf29ce484222325ULL);
    h = hash_text(mode, h);
    h = hash_value(realizations, h);
    h = hash_value(sequence, h);
    h = hash_text(scene_text, h);
    h = hash_text(parameters, h);
    const StepperState& s = stepper;
    for (double d : {s.micro_time, s.particle_steps, s.height_lo, s.height_hi})
        h = hash_value(d, h);
    h = hash_value(s.samples_taken, h);
    h = fnv1a_array(s.lifting, h);
    h = fnv1a_array(s.observable, h);
    h = fnv1a_array(s.recorded, h);
    h = hash_value(driver.t_origin, h);
    h = hash_value(driver.coarse_steps, h);
    h = hash_value(driver.without_progress, h);
    h = hash_value(driver.fell_back ? 1L : 0L, h);
    if (format_version >= 4) {
        h = hash_integrator(driver.integrator, h);
    } else if (format_version >= 2) {
        h = fnv1a_array(integrator_layout, h);
        h = hash_text(integrator_layout_text, h);
    }
    // Only where a piece of the warm-up is done (checkpoints inside it): the checksums of every
    // other checkpoint, and of those written before the field existed, stay as they were.
    if (driver.warmup_done != 0) h = hash_value(driver.warmup_done, h);
    // Likewise the samples a warm-up until steady needs (only at safe points inside one).
    const coarse::BurstSamples& tail = driver.warmup_tail;
    if (!tail.t.empty()) {
        h = hash_value(static_cast<std::uint64_t>(tail.t.size()), h);
        for (double t : tail.t) h = hash_value(t, h);
        for (const auto* series : {&tail.member_phase, &tail.member_expansion}) {
            h = hash_value(static_cast<std::uint64_t>(series->size()), h);
            for (const Eigen::VectorXd& v : *series) h = hash_vector(v, h);
        }
    }
    // Likewise the drift test's pool (cpi.finish = steady, only once it holds a burst).
    if (!driver.drift.empty()) {
        h = hash_value(static_cast<std::uint64_t>(driver.drift.size()), h);
        for (double v : driver.drift) h = hash_value(v, h);
    }
    // Likewise the run loop's wall time (absent where unknown, and before efdem kept it).
    if (std::isfinite(s.wall_seconds)) h = hash_value(s.wall_seconds, h);
    if (format_version >= 3) {
        h = hash_value(driver.warmed_up ? 1L : 0L, h);
        h = fnv1a_array(s.active, h);
        h = hash_value(s.failures, h);
    }
    for (const auto& o : outputs) {
        h = hash_text(o.name, h);
        h = hash_text(o.bytes, h);
    }
    return h;
}

std::string checkpoint_file_name(const std::string& prefix, long sequence) {
    return fmt::format("{}_ckpt_{:08d}.h5", prefix, sequence);
}

bool is_checkpoint_file_name(const std::string& name, const std::string& prefix) {
    const std::string head = prefix + "_ckpt_";
    if (name.size() != head.size() + 8 + 3 || name.rfind(head, 0) != 0 || !name.ends_with(".h5"))
        return false;
    for (std::size_t k = head.size(); k < head.size() + 8; ++k)
        if (!std::isdigit(static_cast<unsigned char>(name[k]))) return false;
    return true;
}

}  // namespace efdem::mpi_driver
