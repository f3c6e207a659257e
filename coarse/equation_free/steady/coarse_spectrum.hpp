#pragma once
/// \file
/// Coarse stability at a steady state: the leading eigenvalues mu of the coarse Jacobian
/// dPhi_tau/dX by Arnoldi on the same CRN directional derivatives the Newton steps use
/// (docs/steady_states.md), reported with their rates log|mu|/tau.
///
/// Arnoldi without restarts, one product per step, stopped as soon as the wanted Ritz values'
/// residual estimates are small (or the space is the whole coarse space: then the Ritz values
/// are the eigenvalues of the explicit Jacobian in the Krylov basis, to the accuracy of the
/// products). Why not the explicit Jacobian column by column: Phi_tau damps the fast coarse
/// modes by exp(lambda tau), so the leading few eigenvalues converge in far fewer than n
/// products when the coarse vector is large, and for n = 4 (the compact vector) both cost the
/// same. Why not Spectra's restarted Arnoldi: its restarts discard products (bursts), and it
/// needs ncv < n, which a 4-vector cannot give for more than two eigenvalues.

#include <complex>
#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "coarse/equation_free/krylov/arnoldi_process.hpp"
#include "coarse/equation_free/steady/coarse_map.hpp"

namespace efdem::coarse {

struct SpectrumSettings {
    /// How many leading eigenvalues (largest |mu|) to report, >= 1.
    int eigenvalues = 3;
    /// Most products (0: the coarse dimension).
    int max_products = 0;
    /// Stop when every wanted Ritz value's residual estimate h_{k+1,k} |e_k^T y| is below this.
    double tolerance = 1e-8;
    /// Seed of the start vector (a fixed pseudo-random vector: the same on every rank).
    std::uint64_t seed = 1;
};

struct CoarseEigenvalue {
    std::complex<double> mu;
    /// log|mu|/tau [1/sqrt(d_p/g)]: the decay (< 0) or growth rate of the mode.
    double rate = 0;
    /// Residual estimate |A z - mu z| of the Ritz pair (unit z): an error bound on mu for a
    /// normal Jacobian, an error estimate otherwise; it includes what the products' noise does
    /// to the Arnoldi relation only through the Hessenberg entries.
    double residual = 0;
    /// The products' noise over the Krylov basis, sqrt(sum_j |e_j|^2) with |e_j| the members'
    /// standard error of product j (CoarseMap::derivative_noise): a bound on |V^T E| that
    /// perturbs the Hessenberg matrix, so |mu error| <~ residual + noise for a normal Jacobian.
    /// 0 for a deterministic operator.
    double noise = 0;
};

struct CoarseSpectrum {
    std::vector<CoarseEigenvalue> leading;  ///< by |mu|, largest first
    int products = 0;                       ///< directional derivatives spent
    bool whole_space = false;               ///< the Krylov space became invariant (or all of R^n)
};

/// Leading eigenvalues of the operator `jacobian` (dimension n) over a time tau.
/// \pre n >= 1, tau > 0.
CoarseSpectrum leading_eigenvalues(const LinearOperator& jacobian, Eigen::Index n, double tau,
                                   const SpectrumSettings& settings);

/// The same at the steady state x (parameter: for a map with a parameter hook): begins a base
/// at x on `map`, takes the derivatives from it, and ends it. \pre no base on `map`.
CoarseSpectrum coarse_spectrum(CoarseMap& map, const Eigen::VectorXd& x,
                               const SpectrumSettings& settings, double parameter = 0.0);

}  // namespace efdem::coarse
