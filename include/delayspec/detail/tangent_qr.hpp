#pragma once
// The QR kernel of the Lyapunov propagation (lyapunov.hpp; implemented in tangent_qr.cpp):
// internal, trusted by lyapunov_exponents, tested on its own (test_lyapunov.cpp, TangentQR).
#include <vector>

namespace delayspec {

// The QR step on an n x k block stored row-major (the interleaved layout: row i = entry i of
// the k vectors), factorised in place by Householder reflections (the LAPACK algorithm,
// re-associated so that each reflector costs one pass over the rows and Q is formed in one more
// pass from the compact WY form; the mathematics and the stability argument are in
// src/engine/tangent_qr.cpp; tests compare with Eigen's HouseholderQR). Binds to the block's memory
// once; no allocation after construction. A block with a column norm beyond 2^+-300 is first
// scaled by an exact power of two, so squares neither overflow nor underflow.
class TangentQR {
 public:
  TangentQR(double* block, long n, int k);

  // Factorises the bound block = Q R in place, writes Q (n x k row-major, columns signed so
  // that R_ii > 0) to q_out and stores log |R_ii| in log_r[0..k). q_out is separate memory, the
  // block itself, or the same buffer starting before the block (the Lyapunov loop writes Q a
  // period's slots ahead of the factorised block): row r of Q is stored after rows >= r of the
  // block were last read, so Q may overwrite it from below; q_out inside (block, block + n k)
  // is not allowed.
  // NumericalFailure when an entry of the block or of R is not finite, or when |R_ii| is below
  // n eps times the norm of column i (that vector is lost in rounding: dependent on the others).
  void factorise(double* q_out, double* log_r);

 private:
  double* block_;
  long n_;
  int k_;
  std::vector<double> scalars_;   // per-reflector scalars and per-column sums (6 k)
  std::vector<double> matrices_;  // the k x k matrices of the Q formation (4 k^2)
};

}  // namespace delayspec
