#pragma once
// Complex Lambert W, all branches: W_k(z) solves w e^w = z on branch k (Corless et al. 1996
// branch conventions, as in scipy.special.lambertw). Used for the exact characteristic roots
// of the scalar linear DDE x' = a x + b x(t - tau):  lambda_k = a + W_k(b tau e^{-a tau}) / tau.
#include <complex>
#include <vector>

namespace delayspec {

// W_k(z) to about machine precision (Halley's iteration). Throws BadInput for z = 0 on a
// branch k != 0 (where W is -infinity) or a non-finite z.
std::complex<double> lambert_w(std::complex<double> z, int branch);

// The characteristic roots of x' = a x + b x(t - tau) from branches -branches..branches
// (b != 0), sorted by real part, largest first. The principal branch gives the rightmost root.
std::vector<std::complex<double>> linear_dde_roots(double a, double b, double tau, int branches);

// The exact Floquet multipliers exp(lambda T) of the linear DDE over a period T, the `count`
// largest in modulus (sorted as dense_spectrum.hpp sorts).
std::vector<std::complex<double>> linear_dde_multipliers(double a, double b, double tau, double period, int count);

}  // namespace delayspec
