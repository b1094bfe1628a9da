#pragma once
// Classical Gram-Schmidt against a tall orthonormal basis Q (n x j, column-major, leading
// dimension n: the first j columns of an Eigen::MatrixXd), for the Krylov-Schur backend
// (src/engine/eigen/krylov_block.cpp) and GMRES (gmres.hpp). Compiled in the library (src/engine/kernels/gram_schmidt.cpp).
//
// At large n the Krylov solve is bound by reading Q (2 x 10^6 rows x 41 columns = 656 MB), not by
// the operator (one application of the monodromy at N = 10^6 is ~2 ms, one read of Q ~30 ms). So
// each kernel reads Q exactly once and does all of its work for two vectors in that pass:
//     basis_coefficients:  s = Q^T x,  t = Q^T y
//     subtract_in_basis:   x <- x - Q s,  y <- y - Q t,  and then x^T x, x^T y, y^T y
// (y may be null: x alone). Rows go in chunks of kGramSchmidtRows (x's and y's pieces stay in the
// cache while the j columns stream past), four columns at a time (x and y are loaded once per
// four columns). Sums are formed per chunk and added in chunk order, so the result does not
// depend on `threads`: the chunks are split between threads, not the sums. The chunk bodies run
// the portable code or, where the CPU has them, AVX2 + FMA (src/engine/kernels/gram_schmidt_chunks.hpp;
// DELAYSPEC_KERNEL=baseline forces the portable path): the two round differently, each the same
// for any thread count.
namespace delayspec::detail {

inline constexpr long kGramSchmidtRows = 8192;

// Threads worth using for vectors of n entries: one per 2^16 rows (a thread's start-up, ~50 us,
// against ~1 ms of streaming 2^16 rows of 20 columns), at most the hardware's, at least 1.
int gram_schmidt_threads(long n);

// s[0:j] = Q^T x and, when y is not null, t[0:j] = Q^T y.
void basis_coefficients(const double* Q, long n, long j, const double* x, const double* y, double* s, double* t,
                        int threads);

struct ProjectedProducts {
  double xx = 0, xy = 0, yy = 0;  // of the updated vectors (xy, yy zero when y is null)
};

// x -= Q s and, when y is not null, y -= Q t; returns the products of the results.
ProjectedProducts subtract_in_basis(const double* Q, long n, long j, const double* s, const double* t, double* x,
                                    double* y, int threads);

// q = u / r in place of u, and z = (w - g q) / r: the end of an Arnoldi step with delayed
// reorthogonalisation (the new basis vector and the next candidate), on the same threads.
void divide_and_split(long n, double r, double g, double* u, const double* w, double* z, int threads);

}  // namespace delayspec::detail
