#include "coarse/equation_free/steady/coarse_spectrum.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

#include <Eigen/Eigenvalues>

#include "core/contracts.hpp"

namespace efdem::coarse {

namespace {

/// Ritz values of the process so far, largest |mu| first, with their residual estimates.
std::vector<CoarseEigenvalue> ritz_values(const ArnoldiProcess& arnoldi, double tau) {
    const Eigen::MatrixXd h = arnoldi.square_hessenberg();
    Eigen::EigenSolver<Eigen::MatrixXd> es(h, true);
    const Eigen::Index k = h.rows();
    std::vector<CoarseEigenvalue> out(static_cast<std::size_t>(k));
    for (Eigen::Index i = 0; i < k; ++i) {
        CoarseEigenvalue& e = out[static_cast<std::size_t>(i)];
        e.mu = es.eigenvalues()[i];
        const double modulus = std::abs(e.mu);
        e.rate = modulus > 0 ? std::log(modulus) / tau : -std::numeric_limits<double>::infinity();
        const Eigen::VectorXcd y = es.eigenvectors().col(i).normalized();
        e.residual = arnoldi.next_coupling() * std::abs(y[k - 1]);
    }
    std::stable_sort(out.begin(), out.end(),
                     [](const CoarseEigenvalue& a, const CoarseEigenvalue& b) {
                         return std::abs(a.mu) > std::abs(b.mu);
                     });
    return out;
}

}  // namespace

CoarseSpectrum leading_eigenvalues(const LinearOperator& jacobian, Eigen::Index n, double tau,
                                   const SpectrumSettings& settings) {
    EFDEM_EXPECTS(n >= 1 && tau > 0.0 && settings.eigenvalues >= 1);
    const int limit = settings.max_products > 0
                          ? std::min<int>(settings.max_products, static_cast<int>(n))
                          : static_cast<int>(n);
    std::mt19937_64 rng(settings.seed);
    std::uniform_real_distribution<double> uniform(0.5, 1.5);  // every mode present in the start
    Eigen::VectorXd start(n);
    for (Eigen::Index i = 0; i < n; ++i) start[i] = uniform(rng);
    ArnoldiProcess arnoldi(jacobian, start, limit);
    CoarseSpectrum out;
    const auto wanted = static_cast<std::size_t>(settings.eigenvalues);
    while (arnoldi.extend()) {
        out.leading = ritz_values(arnoldi, tau);
        if (arnoldi.invariant()) break;
        if (out.leading.size() < wanted) continue;
        const bool settled = std::all_of(
            out.leading.begin(), out.leading.begin() + static_cast<long>(wanted),
            [&](const CoarseEigenvalue& e) { return e.residual <= settings.tolerance; });
        if (settled) break;
    }
    out.products = arnoldi.steps();
    out.whole_space = arnoldi.invariant();
    if (out.leading.size() > wanted) out.leading.resize(wanted);
    return out;
}

CoarseSpectrum coarse_spectrum(CoarseMap& map, const Eigen::VectorXd& x,
                               const SpectrumSettings& settings, double parameter) {
    map.begin(x, parameter);
    double noise2 = 0.0;  // Arnoldi's basis vectors are unit vectors: |e_j| is the product's noise
    CoarseSpectrum out = leading_eigenvalues(
        [&map, &noise2](const Eigen::VectorXd& v) {
            Eigen::VectorXd jv = map.derivative(v);
            noise2 +=
                map.derivative_noise() * map.derivative_noise() / std::max(v.squaredNorm(), 1e-300);
            return jv;
        },
        x.size(), map.settings().tau, settings);
    map.end();
    for (CoarseEigenvalue& e : out.leading) e.noise = std::sqrt(noise2);
    return out;
}

}  // namespace efdem::coarse
