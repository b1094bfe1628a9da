#pragma once
// The row-chunk bodies of the Gram-Schmidt kernels (detail/gram_schmidt.hpp), compiled twice:
// in src/engine/kernels/gram_schmidt.cpp for the portable build and in src/engine/kernels/gram_schmidt_avx2.cpp with -mavx2
// -mfma, chosen at run time like the step-map kernels (kernel_dispatch.hpp: DELAYSPEC_KERNEL =
// baseline forces the portable one). The passes stream the basis from memory, but the portable
// code also spends an instruction per double per column on two-lane packs without FMA: the
// AVX2 file, four lanes and fused multiply-adds, measured the eigensolve at N = 10^6 7-9 % faster
// (2.75-2.81 -> 2.55-2.66 s, docs/benchmarks.md). Everything but the table type is in an unnamed
// namespace, so each file has its own copies: the linker can never put one file's machine code
// in place of the other's.
#include <cstring>

#include "delayspec/detail/gram_schmidt.hpp"

namespace delayspec::detail {

// One path's chunk kernels, over rows [a, b) (y null: x alone).
//   coefficients: s = Q(a:b, 0:j)^T x(a:b), t likewise for y (the chunk's part of the sums)
//   subtract:     x(a:b) -= Q(a:b, 0:j) s, y(a:b) -= Q(a:b, 0:j) t; the chunk's part of the products
struct GramSchmidtChunkKernels {
  void (*coefficients)(const double* Q, long n, long j, const double* x, const double* y, long a, long b, double* s,
                       double* t);
  ProjectedProducts (*subtract)(const double* Q, long n, long j, const double* s, const double* t, double* x, double* y,
                                long a, long b);
};

// The AVX2 + FMA table (src/engine/kernels/gram_schmidt_avx2.cpp); call only where runs_avx2_code(choose_kernel_path(..)).
const GramSchmidtChunkKernels& gram_schmidt_chunks_avx2();

namespace {

// A pack: one SSE2 register of two doubles in the portable build (NEON on AArch64), one AVX2
// register of four in the AVX2 + FMA file. Sums kept in packs are lanes of their own, so the
// compiler needs no reassociation to vectorise them (the library is built without -ffast-math).
#ifdef __AVX2__
using Pack = double __attribute__((vector_size(32)));
#else
using Pack = double __attribute__((vector_size(16)));
#endif
constexpr long kLanes = sizeof(Pack) / sizeof(double);

Pack load(const double* p) {
  Pack v;
  std::memcpy(&v, p, sizeof v);
  return v;
}

double lanes_sum(Pack v) {
  double sum = 0;
  for (long l = 0; l < kLanes; ++l) sum += v[l];
  return sum;
}

// A sum over rows of one column (a dot product, a squared norm) kept in kChains packs: each pack's
// multiply-adds form a chain that waits for the previous one (4 cycles an FMA), so one pack
// bounds the loop at a pack per 4 cycles; four independent ones let it run at the loads' rate
// (perf, GMRES at n = 4002: the one-pack loops were half of the coefficient pass and a third of
// the subtraction, whose 4-column loops already keep 4 sums).
constexpr long kChains = 4;

Pack chains_sum(const Pack (&chains)[kChains]) { return (chains[0] + chains[1]) + (chains[2] + chains[3]); }

// Partial s = Q^T x, t = Q^T y over rows [a, b), four columns per sweep of x and y.
template <bool kTwo>
void chunk_coefficients(const double* __restrict Q, long n, long j, const double* __restrict x,
                        const double* __restrict y, long a, long b, double* s, double* t) {
  long c = 0;
  for (; c + 4 <= j; c += 4) {
    const double* q0 = Q + c * n;
    const double* q1 = q0 + n;
    const double* q2 = q1 + n;
    const double* q3 = q2 + n;
    Pack s0{}, s1{}, s2{}, s3{}, t0{}, t1{}, t2{}, t3{};
    long i = a;
    for (; i + kLanes <= b; i += kLanes) {
      const Pack xv = load(x + i), a0 = load(q0 + i), a1 = load(q1 + i), a2 = load(q2 + i), a3 = load(q3 + i);
      s0 += a0 * xv;
      s1 += a1 * xv;
      s2 += a2 * xv;
      s3 += a3 * xv;
      if constexpr (kTwo) {
        const Pack yv = load(y + i);
        t0 += a0 * yv;
        t1 += a1 * yv;
        t2 += a2 * yv;
        t3 += a3 * yv;
      }
    }
    double sc[4] = {lanes_sum(s0), lanes_sum(s1), lanes_sum(s2), lanes_sum(s3)};
    double tc[4] = {lanes_sum(t0), lanes_sum(t1), lanes_sum(t2), lanes_sum(t3)};
    for (; i < b; ++i) {
      const double qi[4] = {q0[i], q1[i], q2[i], q3[i]};
      for (int l = 0; l < 4; ++l) {
        sc[l] += qi[l] * x[i];
        if constexpr (kTwo) tc[l] += qi[l] * y[i];
      }
    }
    for (int l = 0; l < 4; ++l) {
      s[c + l] = sc[l];
      if constexpr (kTwo) t[c + l] = tc[l];
    }
  }
  for (; c < j; ++c) {  // the last j mod 4 columns, one at a time: kChains sums each
    const double* q = Q + c * n;
    Pack sv[kChains]{}, tv[kChains]{};
    long i = a;
    for (; i + kChains * kLanes <= b; i += kChains * kLanes)
      for (long u = 0; u < kChains; ++u) {
        const Pack qv = load(q + i + u * kLanes);
        sv[u] += qv * load(x + i + u * kLanes);
        if constexpr (kTwo) tv[u] += qv * load(y + i + u * kLanes);
      }
    for (; i + kLanes <= b; i += kLanes) {
      const Pack qv = load(q + i);
      sv[0] += qv * load(x + i);
      if constexpr (kTwo) tv[0] += qv * load(y + i);
    }
    double sc = lanes_sum(chains_sum(sv)), tc = lanes_sum(chains_sum(tv));
    for (; i < b; ++i) {
      sc += q[i] * x[i];
      if constexpr (kTwo) tc += q[i] * y[i];
    }
    s[c] = sc;
    if constexpr (kTwo) t[c] = tc;
  }
}

// x -= Q s, y -= Q t over rows [a, b), then the partial products of the results there.
template <bool kTwo>
ProjectedProducts chunk_subtract(const double* __restrict Q, long n, long j, const double* s, const double* t,
                                 double* __restrict x, double* __restrict y, long a, long b) {
  long c = 0;
  for (; c + 4 <= j; c += 4) {
    const double* q0 = Q + c * n;
    const double* q1 = q0 + n;
    const double* q2 = q1 + n;
    const double* q3 = q2 + n;
    for (long i = a; i < b; ++i) {
      x[i] -= s[c] * q0[i] + s[c + 1] * q1[i] + s[c + 2] * q2[i] + s[c + 3] * q3[i];
      if constexpr (kTwo) y[i] -= t[c] * q0[i] + t[c + 1] * q1[i] + t[c + 2] * q2[i] + t[c + 3] * q3[i];
    }
  }
  for (; c < j; ++c) {
    const double* q = Q + c * n;
    for (long i = a; i < b; ++i) {
      x[i] -= s[c] * q[i];
      if constexpr (kTwo) y[i] -= t[c] * q[i];
    }
  }
  Pack xx[kChains]{}, xy[kChains]{}, yy[kChains]{};
  long i = a;
  for (; i + kChains * kLanes <= b; i += kChains * kLanes)
    for (long u = 0; u < kChains; ++u) {
      const Pack xv = load(x + i + u * kLanes);
      xx[u] += xv * xv;
      if constexpr (kTwo) {
        const Pack yv = load(y + i + u * kLanes);
        xy[u] += xv * yv;
        yy[u] += yv * yv;
      }
    }
  for (; i + kLanes <= b; i += kLanes) {
    const Pack xv = load(x + i);
    xx[0] += xv * xv;
    if constexpr (kTwo) {
      const Pack yv = load(y + i);
      xy[0] += xv * yv;
      yy[0] += yv * yv;
    }
  }
  ProjectedProducts p{lanes_sum(chains_sum(xx)), lanes_sum(chains_sum(xy)), lanes_sum(chains_sum(yy))};
  for (; i < b; ++i) {
    p.xx += x[i] * x[i];
    if constexpr (kTwo) {
      p.xy += x[i] * y[i];
      p.yy += y[i] * y[i];
    }
  }
  return p;
}

void chunk_coefficients_either(const double* Q, long n, long j, const double* x, const double* y, long a, long b,
                               double* s, double* t) {
  if (y) chunk_coefficients<true>(Q, n, j, x, y, a, b, s, t);
  else chunk_coefficients<false>(Q, n, j, x, y, a, b, s, t);
}

ProjectedProducts chunk_subtract_either(const double* Q, long n, long j, const double* s, const double* t, double* x,
                                        double* y, long a, long b) {
  return y ? chunk_subtract<true>(Q, n, j, s, t, x, y, a, b) : chunk_subtract<false>(Q, n, j, s, t, x, y, a, b);
}

// This file's table.
constexpr GramSchmidtChunkKernels kChunkKernels{&chunk_coefficients_either, &chunk_subtract_either};

}  // namespace
}  // namespace delayspec::detail
