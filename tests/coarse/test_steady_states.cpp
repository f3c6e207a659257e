// Coarse steady states on toy steppers, without DEM or MPI (docs/steady_states.md): Newton-
// GMRES and the coarse spectrum on a linear stepper with known fixed point and eigenvalues,
// pseudo-arclength continuation round a fold, the stop at the noise level of an ensemble,
// common random numbers in the directional derivatives, and Anderson/damped fixed-point
// iteration against Newton.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>
#include <Eigen/LU>
#include <Eigen/SVD>

#include "coarse/equation_free/krylov/gmres.hpp"
#include "coarse/equation_free/steady/arclength_system.hpp"
#include "coarse/equation_free/steady/coarse_map.hpp"
#include "coarse/equation_free/steady/coarse_spectrum.hpp"
#include "coarse/equation_free/steady/continuation.hpp"
#include "coarse/equation_free/steady/fixed_point_iteration.hpp"
#include "coarse/equation_free/steady/fixed_point_system.hpp"
#include "coarse/equation_free/steady/newton_krylov.hpp"
#include "tests/coarse/steady_toy_steppers.hpp"

using namespace efdem;
using namespace efdem::coarse;

namespace {

constexpr double kTau = 2.0;
constexpr double kH = 0.1;  // sampling interval of the linear toy

/// A non-normal x' = A (x - x*), A = V diag(lambda) V^-1: four decaying modes, the slowest
/// exp(-0.05 tau) = 0.905 (slow enough that plain iteration needs hundreds of bursts).
struct LinearCase {
    Eigen::Vector4d lambda{-0.05, -0.2, -1.0, -3.0};
    Eigen::Vector4d x_star{1.0, -2.0, 0.5, 3.0};
    Eigen::Matrix4d v;
    LinearCase() {
        v << 1.0, 0.3, 0.3, 0.3,  //
            0.0, 1.0, 0.3, 0.3,   //
            0.0, 0.0, 1.0, 0.3,   //
            0.2, 0.0, 0.0, 1.0;
    }
    Eigen::MatrixXd propagator(double t) const {
        return v * (lambda * t).array().exp().matrix().asDiagonal() * v.inverse();
    }
    test::AffineToyStepper stepper() const { return {propagator(kH), x_star, kH}; }
    /// |J_F^-1| = |(P^K - I)^-1|: how far a residual r can leave the answer from x*.
    double inverse_jacobian_norm() const {
        const Eigen::MatrixXd j = propagator(kTau) - Eigen::MatrixXd::Identity(4, 4);
        const Eigen::MatrixXd inv = j.inverse();
        return Eigen::JacobiSVD<Eigen::MatrixXd>(inv).singularValues()[0];
    }
};

CoarseMapSettings deterministic_map() {
    CoarseMapSettings s;
    s.tau = kTau;
    s.difference_step = 1e-6;
    return s;
}

}  // namespace

TEST_CASE(
    "Newton-GMRES finds the fixed point of a linear stepper; Arnoldi recovers exp(lambda tau)",
    "[unit][steady]") {
    const LinearCase c;
    test::AffineToyStepper toy = c.stepper();
    CoarseMap map(toy, deterministic_map());
    NewtonKrylovSettings ns;
    ns.stop.tolerance = 1e-10;
    FixedPointSystem system(map, 4);
    const SteadySolveRecord rec = NewtonKrylov(ns).solve(system, Eigen::Vector4d::Zero());
    REQUIRE(rec.reason == SteadyStopReason::converged);
    // F is affine: one Newton step with a 4-dimensional Krylov space is exact up to the
    // differences' round-off (eps |X| / h ~ 1e-9 relative), so a second step meets 1e-10.
    CHECK(rec.iterations <= 2);
    CHECK(rec.krylov_iterations.front() == 4);
    // |x - x*| <= |J_F^-1| |F| with |F| <= 1e-10 (|J_F^-1| = 17.4 for this A and tau).
    const double bound = c.inverse_jacobian_norm() * ns.stop.tolerance;
    CHECK((rec.x - c.x_star).norm() <= bound);
    // Each evaluation is one burst of tau: the record's micro time is exact.
    CHECK(rec.micro_time == Approx(kTau * static_cast<double>(rec.evaluations)).epsilon(1e-14));
    WARN("linear toy, Newton-GMRES: " << rec.iterations << " Newton steps, " << rec.evaluations
                                      << " evaluations (" << rec.micro_time
                                      << " micro time), |x - x*| = " << (rec.x - c.x_star).norm()
                                      << " (bound " << bound << ")");

    SpectrumSettings ss;
    ss.eigenvalues = 3;
    const CoarseSpectrum spec = coarse_spectrum(map, rec.x, ss);
    REQUIRE(spec.leading.size() == 3);
    CHECK(spec.products <= 4);  // never more than the coarse dimension
    for (int k = 0; k < 3; ++k) {
        const CoarseEigenvalue& e = spec.leading[static_cast<std::size_t>(k)];
        const double exact = std::exp(c.lambda[k] * kTau);
        // The products are exact up to the differences' round-off and truncation: eps |X| / h
        // ~ 1e-9 times |P^K| (the affine map has no curvature), so 1e-7 leaves two decades.
        CHECK(std::abs(e.mu - exact) <= 1e-7);
        // rate = log|mu| / tau: an error 1e-7 in mu is 1e-7 / (mu tau) <= 4e-7 in the rate.
        CHECK(e.rate == Approx(c.lambda[k]).margin(1e-6));
    }
    WARN("linear toy spectrum: mu = "
         << spec.leading[0].mu.real() << ", " << spec.leading[1].mu.real() << ", "
         << spec.leading[2].mu.real() << " (exact " << std::exp(c.lambda[0] * kTau) << ", "
         << std::exp(c.lambda[1] * kTau) << ", " << std::exp(c.lambda[2] * kTau) << ") from "
         << spec.products << " products");
}

TEST_CASE("GMRES solves a small nonsymmetric system and records a decreasing residual per product",
          "[unit][steady]") {
    Eigen::Matrix3d a;
    a << 4, 1, 0, -1, 3, 2, 0.5, 0, 2;
    const Eigen::Vector3d b(1, 2, 3);
    GmresSettings gs;
    gs.relative_tolerance = 1e-12;
    const GmresResult r =
        gmres([&a](const Eigen::VectorXd& x) -> Eigen::VectorXd { return a * x; }, b, gs);
    // In exact arithmetic GMRES is exact after n = 3 products; double round-off with a
    // condition number ~5 leaves ~1e-15 relative.
    CHECK(r.iterations == 3);
    CHECK((a * r.x - b).norm() <= 1e-12 * b.norm());
    REQUIRE(r.residuals.size() == 4);
    for (std::size_t k = 1; k < r.residuals.size(); ++k)
        CHECK(r.residuals[k] <= r.residuals[k - 1]);
}

TEST_CASE(
    "fixed-point iteration converges on the linear toy; Anderson beats damped; compared with "
    "Newton",
    "[unit][steady]") {
    const LinearCase c;
    auto solve = [&](int depth) {
        test::AffineToyStepper toy = c.stepper();
        CoarseMap map(toy, deterministic_map());
        FixedPointSettings fs;
        fs.stop.tolerance = 1e-10;
        fs.max_iterations = 1000;
        fs.depth = depth;
        return FixedPointIteration(fs).solve(map, Eigen::Vector4d::Zero());
    };
    const SteadySolveRecord damped = solve(0), anderson = solve(3);
    REQUIRE(damped.reason == SteadyStopReason::converged);
    REQUIRE(anderson.reason == SteadyStopReason::converged);
    const double bound = c.inverse_jacobian_norm() * 1e-10;
    CHECK((damped.x - c.x_star).norm() <= bound);
    CHECK((anderson.x - c.x_star).norm() <= bound);
    // Plain iteration (beta = 1) is the power method on P^K: the residual ratio tends to the
    // slowest mode's mu = exp(-0.05 tau) = 0.9048, with an error (0.67/0.905)^k < 1e-6 after
    // the ~230 iterations it needs.
    const std::size_t n = damped.residuals.size();
    CHECK(damped.residuals[n - 1] / damped.residuals[n - 2] ==
          Approx(std::exp(c.lambda[0] * kTau)).margin(1e-6));
    // Anderson(3) on a 4-dimensional affine map is a Krylov method (GMRES-equivalent for
    // depth >= n; Walker & Ni 2011): it needs a few dozen evaluations against ~230.
    CHECK(anderson.evaluations * 4 < damped.evaluations);

    test::AffineToyStepper toy = c.stepper();
    CoarseMap map(toy, deterministic_map());
    NewtonKrylovSettings ns;
    ns.stop.tolerance = 1e-10;
    FixedPointSystem system(map, 4);
    const SteadySolveRecord newton = NewtonKrylov(ns).solve(system, Eigen::Vector4d::Zero());
    WARN("linear toy to |F| <= 1e-10 from 0: Newton-GMRES "
         << newton.iterations << " steps, " << newton.evaluations << " bursts, micro time "
         << newton.micro_time << "; Anderson(3) " << anderson.iterations << " iterations, "
         << anderson.micro_time << "; damped (beta = 1) " << damped.iterations << " iterations, "
         << damped.micro_time);
}

namespace {

/// x' = lambda + x^2 + 0.3 y, y' = x - y: steady states y = x, lambda = -x^2 - 0.3 x, a
/// saddle-node at x = -0.15, lambda = 0.0225 (where det Df = -2x - 0.3 vanishes). Stable for
/// x < -0.15, a saddle beyond; the eigenvalues of Df are the roots of
/// s^2 - (2x - 1) s + (-2x - 0.3).
Eigen::VectorXd fold_drift(const Eigen::VectorXd& y, double lambda) {
    Eigen::VectorXd f(2);
    f << lambda + y[0] * y[0] + 0.3 * y[1], y[0] - y[1];
    return f;
}
constexpr double kFoldLambda = 0.0225;
/// Leading (largest real part) eigenvalue of Df at the steady state with first component x.
double fold_leading_rate(double x) {
    const double tr = 2 * x - 1, det = -2 * x - 0.3;
    return 0.5 * (tr + std::sqrt(tr * tr - 4 * det));
}

}  // namespace

TEST_CASE(
    "pseudo-arclength continuation turns round a fold, where the leading eigenvalue crosses 1",
    "[unit][steady]") {
    // Deterministic: one member, RK4 with dt = 0.01 (the eigenvalues of the map are
    // exp(s tau) to ~1e-10).
    test::SdeEnsembleStepper toy(fold_drift, 0.0, 1, 0.01, 10, Eigen::Vector2d(-1, -1), 1);
    CoarseMapSettings ms = deterministic_map();
    ms.common_random_numbers = true;
    CoarseMap map(toy, ms, [&toy](double lambda) { toy.set_parameter(lambda); });
    ContinuationSettings cs;
    cs.corrector.stop.tolerance = 1e-9;
    cs.step = 0.1;
    cs.max_step = 0.2;
    cs.parameter_min = -0.7;
    cs.max_points = 60;
    // From near the stable state at lambda = -0.7 (x = -1), lambda increasing.
    const Branch b =
        PseudoArclengthContinuation(map, cs).run(Eigen::Vector2d(-1.05, -0.95), -0.7, +1.0);
    INFO(b.end_reason);
    REQUIRE(b.points.size() >= 8);
    // Back on the stable side, the predictor heading below -0.7 is shortened to land there,
    // and the last corrector holds lambda = -0.7 (to its tolerance 1e-9).
    CHECK(b.end_reason.find("reached the end of the parameter range") != std::string::npos);
    CHECK(b.points.back().parameter == Approx(-0.7).margin(1e-8));
    // Every point is a steady state: lambda = -x^2 - 0.3 x and y = x. The corrector stops at
    // |G| <= 1e-9 and the extended Jacobian stays regular through the fold (that is what the
    // arclength row is for), so a condition number up to ~100 leaves errors below 1e-7.
    for (const BranchPoint& p : b.points) {
        CHECK(p.parameter == Approx(-p.x[0] * p.x[0] - 0.3 * p.x[0]).margin(1e-7));
        CHECK(p.x[1] == Approx(p.x[0]).margin(1e-7));
    }
    const std::vector<FoldEstimate> folds = b.folds();
    REQUIRE(folds.size() == 1);
    const std::size_t at = folds.front().at;
    // lambda increases up to the fold, then decreases.
    for (std::size_t k = 1; k <= at; ++k) CHECK(b.points[k].parameter > b.points[k - 1].parameter);
    for (std::size_t k = at + 1; k < b.points.size(); ++k)
        CHECK(b.points[k].parameter < b.points[k - 1].parameter);
    // The vertex of the parabola through three points at most 0.2 apart in s: lambda(s) is a
    // parabola in x, and x(s) is straight up to O(s^2) near the fold (y = x there), so the
    // cubic error term is small against ds^3 = 8e-3 (measured 3.5e-6); 1e-4 is 0.4% of lambda.
    CHECK(folds.front().parameter == Approx(kFoldLambda).margin(1e-4));
    // The leading eigenvalue is exp(s_max tau) at every point, below 1 on the stable side of
    // the fold and above 1 past it. RK4 with dt = 0.01 is exact to ~1e-10; the one-sided
    // difference of step h = 1e-6 is off by h/2 |d2 Phi|, and the x^2 term amplified over tau
    // makes d2 Phi ~ mu^2 on the unstable side (measured: 0.4-0.6 h mu^2, up to 2e-4 at
    // mu = 22): allow 1e-6 + h mu^2.
    for (const BranchPoint& p : b.points) {
        REQUIRE(p.has_leading);
        const double exact = std::exp(fold_leading_rate(p.x[0]) * kTau);
        CHECK(std::abs(p.leading.mu - exact) <= 1e-6 + 1e-6 * exact * exact);
        if (p.x[0] < -0.15 - 1e-3) CHECK(std::abs(p.leading.mu) < 1.0);
        if (p.x[0] > -0.15 + 1e-3) CHECK(std::abs(p.leading.mu) > 1.0);
    }
    CHECK(std::abs(b.points[at - 1].leading.mu) < 1.0);
    CHECK(std::abs(b.points[at + 1].leading.mu) > 1.0);
    WARN("fold continuation: " << b.points.size() << " points, fold at lambda = "
                               << folds.front().parameter << " (exact " << kFoldLambda << "), "
                               << b.evaluations << " evaluations, micro time " << b.micro_time
                               << "; " << b.end_reason);
}

namespace {

/// Each member: dY_i = [-k_i (Y_i - c_i) - (Y_i - c_i)^3] dt + sigma dW_i. The drift is odd
/// about c and the noise symmetric, so the ensemble mean of the map lifted at c stays at c:
/// the mean fixed point is c exactly. The cubic makes the paths' derivatives depend on the
/// noise (CRN is not exact), and only contracts more than the linear part: every coarse
/// eigenvalue is <= exp(-k_min tau).
struct NoisyCase {
    Eigen::Vector3d k{0.5, 1.0, 2.0};
    Eigen::Vector3d c{0.5, -1.0, 2.0};
    double sigma = 0.1;
    int members = 64;
    test::SdeEnsembleStepper stepper(std::uint64_t seed) const {
        const Eigen::Vector3d kk = k, cc = c;
        auto drift = [kk, cc](const Eigen::VectorXd& y, double) -> Eigen::VectorXd {
            const Eigen::ArrayXd d = (y - cc).array();
            return (-kk.array() * d - d.cube()).matrix();
        };
        return {drift, sigma, members, 0.05, 10, cc, seed};
    }
};

/// Passes a FixedPointSystem through and writes down the calls that cost a burst or change the
/// kept micro state: 'b' begin, 'e' end, 'j' a derivative, 't' a trial.
class CallLog final : public NewtonSystem {
  public:
    explicit CallLog(NewtonSystem& inner) : inner_(inner) {}
    Eigen::Index dimension() const override { return inner_.dimension(); }
    SystemEvaluation begin(const Eigen::VectorXd& y) override {
        calls += 'b';
        begun.push_back(y);
        return inner_.begin(y);
    }
    Eigen::VectorXd jacobian_times(const Eigen::VectorXd& v) override {
        calls += 'j';
        return inner_.jacobian_times(v);
    }
    SystemEvaluation trial(const Eigen::VectorXd& y) override {
        calls += 't';
        return inner_.trial(y);
    }
    void end() override {
        calls += 'e';
        inner_.end();
    }
    long evaluations() const override { return inner_.evaluations(); }
    double micro_time() const override { return inner_.micro_time(); }

    std::string calls;
    std::vector<Eigen::VectorXd> begun;

  private:
    NewtonSystem& inner_;
};

CoarseMapSettings noisy_map(bool crn, double h) {
    CoarseMapSettings s;
    s.tau = kTau;
    s.difference_step = h;
    s.common_random_numbers = crn;
    return s;
}

}  // namespace

TEST_CASE(
    "on a noisy ensemble Newton-GMRES stops at the noise level, within the noise band of the fixed "
    "point",
    "[unit][steady]") {
    const NoisyCase c;
    test::SdeEnsembleStepper toy = c.stepper(7);
    CoarseMap map(toy, noisy_map(true, 1e-2));
    NewtonKrylovSettings ns;  // tolerance 1e-10 is far below the noise: only the noise can stop it
    FixedPointSystem system(map, 3);
    const Eigen::Vector3d x0 = c.c + Eigen::Vector3d(0.8, -0.6, 0.5);
    const SteadySolveRecord rec = NewtonKrylov(ns).solve(system, x0);
    INFO(rec.message);
    REQUIRE(rec.reason == SteadyStopReason::noise_level);
    CHECK(rec.message.find("noise level") != std::string::npos);
    const double noise = rec.noise.back();
    CHECK(rec.residuals.back() <= ns.stop.noise_factor * noise);
    // F(x) = J_F (x - c) + e with |e| <= 2 noise (the same chi-squared argument as the stop)
    // and |F| <= 2 noise at the stop, so |x - c| <= |J_F^-1| 4 noise, |J_F^-1| <=
    // 1 / (1 - exp(-k_min tau)) = 1.58 since every eigenvalue is real in [0, exp(-k_min tau)].
    const double band = 4.0 * noise / (1.0 - std::exp(-c.k.minCoeff() * kTau));
    CHECK((rec.x - c.c).norm() <= band);
    // The band is narrow against where the solve started, so landing in it is the solver's
    // doing (|x0 - c| = 1.12; the band is ~0.11 for 64 members).
    CHECK(band < 0.2 * (x0 - c.c).norm());
    WARN("noisy toy: " << rec.iterations << " Newton steps, " << rec.evaluations
                       << " bursts, |F| = " << rec.residuals.back() << ", noise " << noise
                       << ", |x - c| = " << (rec.x - c.c).norm() << " within the band " << band);
}

TEST_CASE("common random numbers make the ensemble's directional derivatives accurate",
          "[unit][steady]") {
    const NoisyCase c;
    const Eigen::Vector3d x = c.c + Eigen::Vector3d(0.3, -0.2, 0.1);
    const Eigen::Vector3d v = Eigen::Vector3d(1.0, 1.0, 1.0).normalized();
    // The spread of J v over independent micro states (the noise part of its error; the O(h)
    // bias is the same either way).
    auto spread = [&](bool crn) {
        test::SdeEnsembleStepper toy = c.stepper(11);
        CoarseMap map(toy, noisy_map(crn, 1e-2));
        constexpr int kTrials = 12;
        std::vector<Eigen::VectorXd> jv;
        double reported2 = 0;  // mean square of the noise each product reports from its members
        for (int t = 0; t < kTrials; ++t) {
            map.begin(x);
            jv.push_back(map.derivative(v));
            reported2 += map.derivative_noise() * map.derivative_noise() / kTrials;
            map.end();
        }
        Eigen::VectorXd mean = Eigen::VectorXd::Zero(3);
        for (const auto& j : jv) mean += j / kTrials;
        double ss = 0;
        for (const auto& j : jv) ss += (j - mean).squaredNorm();
        return std::make_pair(std::sqrt(ss / (kTrials - 1)), std::sqrt(reported2));
    };
    const auto [with, with_reported] = spread(true);
    const auto [without, without_reported] = spread(false);
    // What each product reports as its noise (the members' standard error of their own
    // differences) is the spread over independent micro states, with CRN and without: the
    // spread of 12 trials of a 3-vector is itself uncertain by ~15% (33 degrees of freedom),
    // the members' SE from 64 by ~10%; a factor 1.5 either way leaves room for both.
    CHECK(with_reported == Approx(with).epsilon(0.5));
    CHECK(without_reported == Approx(without).epsilon(0.5));
    // Without CRN the difference of two independent means has noise sqrt(2) SE / h per
    // component: SE = 0.1 sqrt((1 - e^(-2 k tau))/2k)/sqrt(64) ~ 0.01, h = 0.01, so ~2 in |J v|.
    // With CRN only the noise in the paths' derivatives is left (the cubic's 3 (Y - c)^2 term,
    // ~10% of k per member, averaged over 64): ~0.01. A ratio above 20 leaves a factor ~10.
    CHECK(without > 0.5);
    CHECK(without > 20.0 * with);
    WARN("spread of J v over 12 micro states: with CRN "
         << with << " (reported " << with_reported << "), without " << without << " (reported "
         << without_reported << "; ratio " << without / with << ")");
}

TEST_CASE(
    "a fallback first guess is tried only when the first guess is noisy and far, and the closer "
    "one starts",
    "[unit][steady]") {
    const NoisyCase c;
    test::SdeEnsembleStepper toy = c.stepper(5);
    CoarseMap map(toy, noisy_map(true, 1e-2));
    FixedPointSystem fixed(map, 3);
    CallLog system(fixed);
    const NewtonKrylov newton{NewtonKrylovSettings{}};
    // The noise norm of F is ~0.01 (64 members, sigma = 0.1), the threshold 2 x that; F at an
    // offset d is ~(1 - e^(-k tau)) d, so an offset of 1 is ~30 x the threshold, 0.002 below it.
    const Eigen::Vector3d far = c.c + Eigen::Vector3d::Constant(1.0);
    const Eigen::Vector3d near = c.c + Eigen::Vector3d::Constant(0.3);
    const Eigen::Vector3d steady = c.c + Eigen::Vector3d::Constant(0.002);

    SECTION("far first guess, closer fallback: the solve starts from the fallback's kept state") {
        const FallbackGuess fallback{near, 2.0};
        const SteadySolveRecord rec = newton.solve(system, far, &fallback);
        INFO(rec.message << "; calls " << system.calls);
        CHECK(rec.from_fallback);
        CHECK(rec.first_guess_residual > rec.fallback_residual);
        // Iterate 0 is the fallback's evaluation itself (no burst in between), and the first
        // Newton step's derivatives are taken from its kept micro state: b e b j...
        CHECK(rec.residuals.front() == rec.fallback_residual);
        CHECK(system.calls.substr(0, 4) == "bebj");
        CHECK(system.begun[1] == Eigen::VectorXd(near));
        CHECK(rec.converged());
    }
    SECTION("the first guess closer after all: it is evaluated afresh and its state kept") {
        const FallbackGuess fallback{far, 2.0};
        const SteadySolveRecord rec = newton.solve(system, near, &fallback);
        INFO(rec.message << "; calls " << system.calls);
        CHECK_FALSE(rec.from_fallback);
        CHECK(rec.first_guess_residual < rec.fallback_residual);
        CHECK(system.calls.substr(0, 6) == "bebebj");
        CHECK(system.begun[2] == Eigen::VectorXd(near));
        // A fresh evaluation at the same point: the same |F| up to the noise (4 x its norm
        // bounds the difference of two independent errors, as in the stopping rule).
        CHECK(rec.residuals.front() ==
              Approx(rec.first_guess_residual).margin(4.0 * rec.noise.front()));
        CHECK(rec.converged());
    }
    SECTION("a first guess within the ratio: the fallback is never evaluated") {
        const FallbackGuess fallback{far, 2.0};
        const SteadySolveRecord rec = newton.solve(system, steady, &fallback);
        INFO(rec.message << "; calls " << system.calls);
        CHECK(std::isnan(rec.fallback_residual));
        CHECK_FALSE(rec.from_fallback);
        // One evaluation per iterate, none for the fallback (here: at the noise level at once).
        CHECK(system.begun.size() == rec.residuals.size());
        CHECK(system.begun.front() == Eigen::VectorXd(steady));
    }
}

TEST_CASE(
    "a noise-free map never evaluates the fallback: its predictor is as good as the branch is "
    "smooth",
    "[unit][steady]") {
    const LinearCase c;
    test::AffineToyStepper toy = c.stepper();
    CoarseMap map(toy, deterministic_map());
    FixedPointSystem fixed(map, 4);
    CallLog system(fixed);
    const FallbackGuess fallback{c.x_star, 0.0};  // even with ratio 0 and the exact answer
    const SteadySolveRecord rec =
        NewtonKrylov{NewtonKrylovSettings{}}.solve(system, Eigen::Vector4d::Zero(), &fallback);
    CHECK(std::isnan(rec.fallback_residual));
    CHECK(system.calls.substr(0, 2) == "bj");
}

TEST_CASE(
    "a predictor that overshoots a sharp turn of the branch hands over to the last point held at "
    "the new parameter",
    "[unit][steady]") {
    // x' = -2 (x - tanh((lambda - 0.15)/0.03)) in two components: the steady state jumps from
    // -1 to +1 within ~0.1 of lambda. Past the jump the secant through the two points on its
    // flanks extrapolates the jump (|F| ~ 2 at the predictor) while the last point is already
    // on the upper plateau: the corrector starts from it, with lambda held.
    auto drift = [](const Eigen::VectorXd& y, double lambda) -> Eigen::VectorXd {
        return -2.0 * (y.array() - std::tanh((lambda - 0.15) / 0.03)).matrix();
    };
    test::SdeEnsembleStepper toy(drift, 1e-3, 16, 0.01, 10, Eigen::Vector2d(-1, -1), 9);
    CoarseMap map(toy, noisy_map(true, 1e-2), [&toy](double lambda) { toy.set_parameter(lambda); });
    ContinuationSettings cs;
    cs.parameter_step = 0.1;
    cs.max_parameter_step = 0.1;
    cs.step = 0.1;
    cs.max_step = 10.0;
    cs.min_step = 1e-3;
    cs.parameter_min = 0.0;
    cs.parameter_max = 0.6;
    cs.stability = false;
    const Branch b = PseudoArclengthContinuation(map, cs).run(Eigen::Vector2d(-1, -1), 0.0, +1.0);
    INFO(b.end_reason);
    REQUIRE(b.points.size() >= 5);
    CHECK(b.end_reason.find("reached the end of the parameter range") != std::string::npos);
    int held = 0;
    for (std::size_t k = 0; k < b.points.size(); ++k) {
        const BranchPoint& p = b.points[k];
        INFO("point " << k << " at lambda = " << p.parameter
                      << (p.from_fallback ? " (from the last point)" : ""));
        // Every point is steady to its noise band: F = (e^{-2 tau} - 1)(x - x*) + noise, |F| <=
        // 2 noise at the stop and |noise| <= 2 noise, so |x - x*| <= 4 noise / (1 - e^{-4})
        // (noise ~ 1e-4 for sigma = 1e-3 over 16 members).
        const double x_star = std::tanh((p.parameter - 0.15) / 0.03);
        CHECK((p.x.array() - x_star).abs().maxCoeff() <= 4.0 * p.noise / (1.0 - std::exp(-4.0)));
        if (p.from_fallback && k >= 2) {
            ++held;
            // Held at the predicted parameter: lambda_{k-1} + ds t_lambda with t the secant
            // through the two points before, or the end of the range the predictor landed on
            // (GMRES meets the linear constraint row to its forcing x |G|: 1e-6 is ample).
            const BranchPoint& q = b.points[k - 1];
            const BranchPoint& o = b.points[k - 2];
            const double chord =
                std::sqrt((q.x - o.x).squaredNorm() + std::pow(q.parameter - o.parameter, 2));
            const double predicted =
                std::min(q.parameter + p.step * (q.parameter - o.parameter) / chord, 0.6);
            CHECK(p.parameter == Approx(predicted).margin(1e-6));
        }
    }
    // At least the first point past the jump: its predictor lands ~2 off, the last point ~0.04.
    CHECK(held >= 1);
    // The same branch without the fallback (same seed) ran through the turn in more, shorter
    // steps after failed correctors: measured 373 evaluations against 285.
    test::SdeEnsembleStepper again(drift, 1e-3, 16, 0.01, 10, Eigen::Vector2d(-1, -1), 9);
    CoarseMap map_again(again, noisy_map(true, 1e-2),
                        [&again](double lambda) { again.set_parameter(lambda); });
    cs.fallback_ratio = 1e6;
    const Branch without =
        PseudoArclengthContinuation(map_again, cs).run(Eigen::Vector2d(-1, -1), 0.0, +1.0);
    CHECK(b.evaluations < without.evaluations);
    WARN("sharp turn: " << b.points.size() << " points, " << held << " from the last point, "
                        << b.evaluations
                        << " evaluations (without the fallback: " << without.points.size()
                        << " points, " << without.evaluations << " evaluations); " << b.end_reason);
}

TEST_CASE("a fallback with its own system: the solve goes on in it from the fallback's kept state",
          "[unit][steady]") {
    const NoisyCase c;
    test::SdeEnsembleStepper toy = c.stepper(5);
    CoarseMap map(toy, noisy_map(true, 1e-2));
    FixedPointSystem fixed(map, 3);
    CallLog first(fixed), second(fixed);
    FallbackGuess fallback{c.c + Eigen::Vector3d::Constant(0.3), 2.0, &second};
    const SteadySolveRecord rec = NewtonKrylov{NewtonKrylovSettings{}}.solve(
        first, c.c + Eigen::Vector3d::Constant(1.0), &fallback);
    INFO(rec.message);
    CHECK(rec.from_fallback);
    CHECK(first.calls == "be");                // evaluated once, then left
    CHECK(second.calls.substr(0, 2) == "bj");  // the fallback's state serves the first products
    CHECK(rec.converged());
}

namespace {
/// The deterministic fold toy behind a map whose hook remembers the highest parameter it was
/// asked to run at.
struct WatchedFold {
    test::SdeEnsembleStepper toy{fold_drift, 0.0, 1, 0.01, 10, Eigen::Vector2d(-1, -1), 1};
    double highest = -std::numeric_limits<double>::infinity();
    CoarseMap map{toy, deterministic_map(), [this](double lambda) {
                      highest = std::max(highest, lambda);
                      toy.set_parameter(lambda);
                  }};
};
}  // namespace

TEST_CASE("an arclength corrector never runs the micro model at a parameter outside its bounds",
          "[unit][steady]") {
    WatchedFold fold;
    CoarseMap& map = fold.map;
    double& highest = fold.highest;
    const Eigen::Vector3d predicted(-1.0, -1.0, -0.5);
    map.set_parameter_bounds(-0.7, -0.3);
    ArclengthSystem system(map, Eigen::Vector3d(0.0, 0.0, 1.0), predicted);
    system.begin(predicted);
    const long before = map.evaluations();
    // A Newton step from a noisy tangent asking for lambda = 5: no decrease, and no burst.
    const SystemEvaluation out = system.trial(Eigen::Vector3d(-1.0, -1.0, 5.0));
    CHECK(std::isinf(out.g.norm()));
    CHECK(map.evaluations() == before);
    CHECK(highest <= -0.3);
    // Inside the bounds a trial runs as always.
    const SystemEvaluation in = system.trial(Eigen::Vector3d(-1.0, -1.0, -0.4));
    CHECK(std::isfinite(in.g.norm()));
    CHECK(map.evaluations() == before + 1);
    system.end();
}

TEST_CASE("a difference whose forward point leaves the parameter bounds is taken backwards",
          "[unit][steady]") {
    WatchedFold fold;
    CoarseMap& map = fold.map;
    double& highest = fold.highest;
    const Eigen::Vector2d x(-1.0, -1.0);
    const Eigen::Vector2d v = Eigen::Vector2d::Zero();
    map.begin(x, -0.5);
    const Eigen::VectorXd forward = map.derivative(v, 1.0);  // d Phi / d lambda
    map.end();
    map.set_parameter_bounds(-0.7, -0.5);  // the base on the upper bound
    highest = -std::numeric_limits<double>::infinity();
    map.begin(x, -0.5);
    const Eigen::VectorXd backward = map.derivative(v, 1.0);
    map.end();
    CHECK(highest <= -0.5);
    // One-sided differences of step h = 1e-6 either way: they differ by h |d2 Phi / d lambda2|,
    // O(1e-6) for this smooth map (tau = 2), and by round-off eps |Phi| / h ~ 1e-10.
    CHECK((forward - backward).norm() <= 1e-5 * (1.0 + forward.norm()));
    CHECK(forward.norm() > 0.1);  // a real derivative, not two zeros
}
