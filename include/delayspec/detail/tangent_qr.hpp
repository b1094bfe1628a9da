#pragma once
// The QR kernel of the Lyapunov propagation (lyapunov.hpp; implemented in lyapunov.cpp):
// internal, trusted by lyapunov_exponents, tested on its own (test_lyapunov.cpp, TangentQR).
#include <vector>

namespace delayspec {

// The QR step on an n x k block stored row-major (the interleaved layout: row i = entry i of
// the k vectors), factorised in place by Householder reflections (the LAPACK/Eigen algorithm,
// written for this layout: Eigen's HouseholderQR on a row-major Ref measured 4x slower;
// tests compare the two). Binds to the block's memory once; no allocation after construction.
// A block whose largest entry is beyond 2^+-300 is first scaled by an exact power of two, so
// squares neither overflow nor underflow.
class TangentQR {
 public:
  TangentQR(double* block, long n, int k);

  // Factorises the bound block = Q R in place, writes Q (n x k row-major, columns signed so
  // that R_ii > 0) to q_out (must not overlap the block) and stores log |R_ii| in log_r[0..k).
  // NumericalFailure when an entry of the block or of R is not finite, or when |R_ii| is below
  // n eps times the norm of column i (that vector is lost in rounding: dependent on the others).
  void factorise(double* q_out, double* log_r);

 private:
  double* block_;
  long n_;
  int k_;
  std::vector<double> tau_, r_, norm_;
};

}  // namespace delayspec
