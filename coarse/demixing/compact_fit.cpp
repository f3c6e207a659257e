#include "coarse/demixing/compact_fit.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

#include <fmt/format.h>
#include <Eigen/QR>
#include <Eigen/SVD>
#include <unsupported/Eigen/NonLinearOptimization>

#include "core/contracts.hpp"

namespace efdem::coarse {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

/// The nodes the fit uses: positive values, and the first node with y <= 0 (Q17).
struct FitData {
    std::vector<double> p;
    std::vector<double> y;
    int zero_row = -1;    ///< row of the first zero node, -1 if y > 0 everywhere
    double centre = 0.0;  ///< p0 of the internal parameterization below

    int size() const { return static_cast<int>(p.size()); }
};

// Internally the model is written about the centre p0 of the fitted nodes,
//   f = a (p - p0) + b' + c' e^(d (p - p0)),  b' = b + a p0,  c' = c e^(d p0),
// the same function with decorrelated parameters: d/dd of c e^(dp) is c p e^(dp), nearly p
// times d/dc over p in [0.05, 0.95], which makes a long curved valley that LM crawls along
// (30-200 iterations from a start 1 % off); about p0 the columns are far less collinear.
Eigen::Vector4d to_internal(const Eigen::Vector4d& q, double p0) {
    return {q[0], q[1] + q[0] * p0, q[2] * std::exp(q[3] * p0), q[3]};
}
Eigen::Vector4d to_external(const Eigen::Vector4d& q, double p0) {
    return {q[0], q[1] - q[0] * p0, q[2] * std::exp(-q[3] * p0), q[3]};
}

FitData select_nodes(const Eigen::VectorXd& y, const ProbabilityGrid& grid) {
    FitData data;
    for (int i = 0; i < grid.size(); ++i) {
        if (y[i] > 0.0 || data.zero_row < 0) {
            if (!(y[i] > 0.0)) data.zero_row = data.size();
            data.p.push_back(grid.p(i));
            data.y.push_back(std::max(y[i], 0.0));
        }
    }
    if (!data.p.empty()) data.centre = 0.5 * (data.p.front() + data.p.back());
    return data;
}

/// Which of (a, b, c, d) are fitted; the others keep their values in `full`.
struct ParameterMask {
    std::array<bool, 4> free{true, true, true, true};
    Eigen::Vector4d full = Eigen::Vector4d::Zero();

    int n_free() const { return free[0] + free[1] + free[2] + free[3]; }
    Eigen::VectorXd pack(const Eigen::Vector4d& all) const {
        Eigen::VectorXd v(n_free());
        for (int j = 0, k = 0; j < 4; ++j)
            if (free[j]) v[k++] = all[j];
        return v;
    }
    Eigen::Vector4d unpack(const Eigen::VectorXd& v) const {
        Eigen::Vector4d all = full;
        for (int j = 0, k = 0; j < 4; ++j)
            if (free[j]) all[j] = v[k++];
        return all;
    }
};

/// Residuals and analytic Jacobian for Eigen's LevenbergMarquardt, in internal parameters.
struct Residuals {
    const FitData& data;
    const ParameterMask& mask;
    double d_limit;

    int values() const { return data.size(); }

    int operator()(const Eigen::VectorXd& x, Eigen::VectorXd& r) const {
        const Eigen::Vector4d q = mask.unpack(x);
        if (!(std::abs(q[3]) <= d_limit)) {
            // Outside the supported range: a large, finite residual that LM rejects by
            // shrinking its trust region (no e^(d p) overflow).
            r.setConstant(1e10);
            return 0;
        }
        for (int i = 0; i < data.size(); ++i) {
            const double u = data.p[i] - data.centre;
            const double f = q[0] * u + q[1] + q[2] * std::exp(q[3] * u);
            r[i] = (i == data.zero_row ? std::max(f, 0.0) : f) - data.y[i];
        }
        return 0;
    }

    int df(const Eigen::VectorXd& x, Eigen::MatrixXd& jac) const {
        const Eigen::Vector4d q = mask.unpack(x);
        for (int i = 0; i < data.size(); ++i) {
            const double u = data.p[i] - data.centre, e = std::exp(q[3] * u);
            const bool clamped = i == data.zero_row && q[0] * u + q[1] + q[2] * e <= 0.0;
            const Eigen::Vector4d row =
                clamped ? Eigen::Vector4d::Zero() : Eigen::Vector4d(u, 1.0, e, q[2] * u * e);
            jac.row(i) = mask.pack(row).transpose();
        }
        return 0;
    }
};

struct LmOutcome {
    Eigen::Vector4d params;
    bool converged = false;
    int status = 0;
    int iterations = 0;
    int evaluations = 0;
};

LmOutcome run_lm(const FitData& data, const ParameterMask& mask, const Eigen::Vector4d& start,
                 const CompactFitSettings& settings) {
    Residuals residuals{data, mask, settings.d_limit};
    Eigen::LevenbergMarquardt<Residuals> lm(residuals);
    lm.parameters.maxfev = settings.max_evaluations;
    lm.parameters.ftol = settings.tolerance;
    lm.parameters.xtol = settings.tolerance;
    Eigen::VectorXd x = mask.pack(start);
    // MINPACK's tests are relative; at a residual of round-off size they cannot tell progress
    // from noise and the search crawls. Stop at 1e-13 of the data norm (an exact fit).
    const double exact =
        1e-13 * Eigen::Map<const Eigen::VectorXd>(data.y.data(), data.size()).norm();
    using namespace Eigen::LevenbergMarquardtSpace;
    Status status = lm.minimizeInit(x);
    if (status != ImproperInputParameters && lm.fnorm > exact) {
        do status = lm.minimizeOneStep(x);
        while (status == Running && lm.fnorm > exact);
    }
    LmOutcome out;
    out.params = mask.unpack(x);
    out.status = static_cast<int>(status);
    // 1-4: converged by a tolerance or a zero gradient; 6-8: no further reduction is possible
    // at machine precision, i.e. at a minimum; Running/NotStarted here: stopped at an exact
    // fit. 0 and 5 (evaluation budget) are failures.
    out.converged = status != ImproperInputParameters && status != TooManyFunctionEvaluation &&
                    status != UserAsked && out.params.allFinite();
    out.iterations = static_cast<int>(lm.njev);
    out.evaluations = static_cast<int>(lm.nfev);
    return out;
}

/// The nodes a linear least-squares fit uses: the positive ones (the first zero only asks for
/// f <= 0, which a linear fit cannot express), and the zero too if fewer than 3 remain.
std::vector<int> linear_rows(const FitData& data) {
    std::vector<int> rows;
    for (int i = 0; i < data.size(); ++i)
        if (i != data.zero_row) rows.push_back(i);
    if (rows.size() < 3 && data.zero_row >= 0) rows.push_back(data.zero_row);
    return rows;
}

/// (a, b', c', d) with d given and (a, b', c') by linear least squares on `rows` (internal
/// parameters; column-pivoting QR, so a nearly collinear e^(d u) still gives the minimum-norm
/// solution of the dependent part). Non-finite entries if it cannot be solved.
Eigen::Vector4d linear_fit(const FitData& data, const std::vector<int>& rows, double d) {
    const auto n = static_cast<Eigen::Index>(rows.size());
    Eigen::MatrixXd basis(n, 3);
    Eigen::VectorXd target(n);
    for (Eigen::Index j = 0; j < n; ++j) {
        const auto row = static_cast<std::size_t>(rows[static_cast<std::size_t>(j)]);
        const double u = data.p[row] - data.centre;
        basis.row(j) << u, 1.0, std::exp(d * u);
        target[j] = data.y[row];
    }
    Eigen::Vector4d q;
    q << basis.colPivHouseholderQr().solve(target), d;
    return q;
}

/// Cold start (internal parameters): for each d on a grid, (a, b', c') by linear least squares,
/// ranked by the true objective on all fitted nodes. \pre data.size() >= 3.
Eigen::Vector4d cold_start(const FitData& data, double d_limit, int& evaluations) {
    const std::vector<int> rows = linear_rows(data);
    const ParameterMask all;
    const Residuals objective{data, all, d_limit};
    Eigen::VectorXd r(data.size());
    Eigen::Vector4d best = Eigen::Vector4d::Zero();
    double best_ssr = std::numeric_limits<double>::infinity();
    for (int k = -80; k <= 80; ++k) {
        const double d = std::clamp(0.25 * k, -d_limit, d_limit);
        if (k == 0) continue;  // e^(0 p) = 1 duplicates the constant b
        const Eigen::Vector4d q = linear_fit(data, rows, d);
        if (!q.allFinite()) continue;
        objective(q, r);
        ++evaluations;
        if (r.squaredNorm() < best_ssr) {
            best_ssr = r.squaredNorm();
            best = q;
        }
    }
    return best;
}

/// Condition number of the Jacobian in natural scales at the internal q (all four parameters
/// free): the derivatives of f/Y with respect to (a/Y, b'/Y, c'/Y, d), Y = max y, i.e. the
/// columns u, 1, e^(du) and (c'/Y) u e^(du), u = p - p0. Unlike column normalization this
/// keeps the information that d stops mattering as c -> 0.
double condition_number(const FitData& data, const Eigen::Vector4d& q, double y_scale,
                        double d_limit) {
    const ParameterMask all;
    Eigen::MatrixXd jac(data.size(), 4);
    Residuals{data, all, d_limit}.df(q, jac);
    jac.col(3) /= y_scale;
    const Eigen::VectorXd sv = Eigen::JacobiSVD<Eigen::MatrixXd>(jac).singularValues();
    return sv[3] == 0.0 ? std::numeric_limits<double>::infinity() : sv[0] / sv[3];
}

/// Standard errors of the external (a, b, c, d) at the internal solution q: s^2 (J^T J)^-1 on
/// the free internal parameters, mapped by the Jacobian M of to_external(); NaN for held
/// parameters, or without degrees of freedom, or for a rank-deficient J.
Eigen::Vector4d standard_errors(const FitData& data, const ParameterMask& mask,
                                const Eigen::Vector4d& q, double d_limit) {
    Eigen::Vector4d se = Eigen::Vector4d::Constant(kNaN);
    const int n_free = mask.n_free(), dof = data.size() - n_free;
    if (dof <= 0) return se;
    const Residuals res{data, mask, d_limit};
    const Eigen::VectorXd x = mask.pack(q);
    Eigen::VectorXd r(data.size());
    Eigen::MatrixXd jac(data.size(), n_free);
    res(x, r);
    res.df(x, jac);
    const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(jac);
    if (qr.rank() < n_free) return se;
    const Eigen::MatrixXd pinv = qr.solve(Eigen::MatrixXd::Identity(data.size(), data.size()));
    const Eigen::MatrixXd cov_free = (r.squaredNorm() / dof) * pinv * pinv.transpose();
    Eigen::Matrix4d cov = Eigen::Matrix4d::Zero();
    for (int i = 0, ki = 0; i < 4; ++i) {
        if (!mask.free[i]) continue;
        for (int j = 0, kj = 0; j < 4; ++j)
            if (mask.free[j]) cov(i, j) = cov_free(ki, kj++);
        ++ki;
    }
    const double p0 = data.centre, e = std::exp(-q[3] * p0);
    Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
    m(1, 0) = -p0;
    m(2, 2) = e;
    m(2, 3) = -p0 * q[2] * e;
    const Eigen::Matrix4d cov_external = m * cov * m.transpose();
    for (int j = 0; j < 4; ++j)
        if (mask.free[j]) se[j] = std::sqrt(cov_external(j, j));
    return se;
}

}  // namespace

Eigen::VectorXd y_of_p(const CompactParameters& q, const ProbabilityGrid& grid) {
    EFDEM_EXPECTS(std::abs(q.d) <= 700.0);
    Eigen::VectorXd y(grid.size());
    for (int i = 0; i < grid.size(); ++i) {
        const double p = grid.p(i);
        y[i] = std::max(q.a * p + q.b + q.c * std::exp(q.d * p), 0.0);
    }
    return y;
}

Eigen::VectorXd light_icdf_from_compact(const Eigen::VectorXd& top_icdf,
                                        const CompactParameters& params,
                                        const ProbabilityGrid& grid) {
    EFDEM_EXPECTS(top_icdf.size() == grid.size());
    return top_icdf - y_of_p(params, grid);
}

CompactFit fit_compact(const Eigen::VectorXd& y, const ProbabilityGrid& grid,
                       const std::optional<CompactParameters>& previous,
                       const CompactFitSettings& settings) {
    EFDEM_EXPECTS(grid.size() >= 4 && y.size() == grid.size());
    EFDEM_EXPECTS(y.allFinite());
    EFDEM_EXPECTS(settings.max_evaluations > 0 && settings.tolerance > 0.0 &&
                  settings.d_limit > 0.0 && settings.max_condition > 1.0 &&
                  settings.max_d_error > 0.0);
    CompactFit fit;
    const FitData data = select_nodes(y, grid);
    fit.n_fitted = data.size();
    const int n_positive = data.zero_row < 0 ? data.size() : data.size() - 1;
    if (n_positive == 0) {
        fit.status = CompactFitStatus::full_demixing;
        fit.message = "y(p) = 0 at every node: demixing is complete; (a, b, c, d) = 0";
        return fit;
    }

    Eigen::Vector4d start;  // internal parameters
    if (previous) {
        Eigen::Vector4d q = previous->vector();
        q[3] = std::clamp(q[3], -settings.d_limit, settings.d_limit);
        start = to_internal(q, data.centre);
    } else if (data.size() >= 3) {
        start = cold_start(data, settings.d_limit, fit.evaluations);
    } else {
        start = Eigen::Vector4d::Zero();
    }

    ParameterMask mask;
    LmOutcome outcome;
    auto run = [&](const Eigen::Vector4d& from) {
        outcome = run_lm(data, mask, from, settings);
        fit.iterations += outcome.iterations;
        fit.evaluations += outcome.evaluations;
    };
    const double y_scale = y.maxCoeff();
    std::string why;  // why the 4-parameter fit is not trusted
    bool fit4_failed = false;
    if (data.size() >= 4) {
        run(start);
        fit.condition_number = condition_number(data, outcome.params, y_scale, settings.d_limit);
        // NaN with degrees of freedom left means a rank-deficient Jacobian: not determined.
        // With none left (4 nodes) there is no error estimate; the condition number decides.
        const double se_d = standard_errors(data, mask, outcome.params, settings.d_limit)[3];
        const bool d_undetermined =
            data.size() > 4 && (std::isnan(se_d) || se_d > settings.max_d_error);
        if (!outcome.converged) {
            fit4_failed = true;
            why = fmt::format("the 4-parameter fit did not converge (MINPACK status {})",
                              outcome.status);
        } else if (fit.condition_number > settings.max_condition) {
            why = fmt::format(
                "the four parameters are not identifiable (condition number "
                "{:.3g} > {:.3g})",
                fit.condition_number, settings.max_condition);
        } else if (d_undetermined) {
            why = fmt::format("d is not determined by the data (standard error {:.3g} > {:.3g})",
                              se_d, settings.max_d_error);
        }
    } else {
        why = fmt::format(
            "only {} node(s) with y > 0 (plus the first zero): four parameters "
            "are not determined",
            n_positive);
    }
    std::string fallback;
    if (!why.empty() && previous && data.size() >= 3) {
        mask.free = {true, true, true, false};
        mask.full[3] = start[3];
        run(start);
        fit.d_held = true;
        fallback = fmt::format("d held at the previous fit's value {:.6g} (Q17)", start[3]);
        if (!outcome.converged) {
            // With d held the model is linear in (a, b, c) but for the clamp at the first zero
            // node: its linear least-squares solution is the fit, whatever stopped LM (seen
            // on nearly straight y(p), where b and c e^(dp) are almost the same column).
            const Eigen::Vector4d q = linear_fit(data, linear_rows(data), start[3]);
            if (q.allFinite()) {
                fallback += fmt::format(
                    "; with d held Levenberg-Marquardt did not converge either (MINPACK status "
                    "{}): (a, b, c) by linear least squares",
                    outcome.status);
                outcome.params = q;
                outcome.converged = true;
            }
        }
    } else if (!why.empty() && data.size() < 4) {
        mask.free = {true, true, false, false};
        mask.full << 0.0, 0.0, 0.0, previous ? start[3] : 0.0;
        run(start);
        fallback = "fitted the line a p + b (c = 0)";
    } else if (fit4_failed) {
        why.clear();  // no fallback: the not_converged message below says it all
    }

    fit.parameters = CompactParameters::from_vector(to_external(outcome.params, data.centre));
    fit.rms = std::sqrt((y_of_p(fit.parameters, grid) - y).squaredNorm() / grid.size());
    fit.standard_errors = standard_errors(data, mask, outcome.params, settings.d_limit);
    const double relative_rms = fit.rms / y_scale;
    std::string verdict;
    if (!outcome.converged) {
        fit.status = CompactFitStatus::not_converged;
        verdict = fmt::format(
            "Levenberg-Marquardt did not converge (MINPACK status {}, {} "
            "evaluations); the parameters are unusable",
            outcome.status, fit.evaluations);
    } else if (relative_rms > settings.max_relative_rms) {
        fit.status = CompactFitStatus::poor_fit;
        verdict = fmt::format(
            "residual RMS {:.3g} is {:.1f} % of max y (limit {:.1f} %): y(p) is "
            "not of the form max[a p + b + c e^(d p), 0]",
            fit.rms, 100 * relative_rms, 100 * settings.max_relative_rms);
    } else {
        fit.status = why.empty() ? CompactFitStatus::ok : CompactFitStatus::ill_conditioned;
    }
    for (const std::string* part : {&verdict, &why, &fallback})
        if (!part->empty()) fit.message += (fit.message.empty() ? "" : "; ") + *part;
    return fit;
}

}  // namespace efdem::coarse
