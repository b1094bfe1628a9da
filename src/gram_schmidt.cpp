// Gram-Schmidt kernels streaming a tall basis once (detail/gram_schmidt.hpp).
#include "delayspec/detail/gram_schmidt.hpp"

#include <algorithm>
#include <cstring>
#include <system_error>
#include <thread>
#include <vector>

namespace delayspec::detail {

namespace {

// Two doubles: one SSE2 register on every x86-64 (NEON on AArch64). Sums kept in packs are lanes of
// their own, so the compiler needs no reassociation to vectorise them (the library is built
// without -ffast-math). Measured on the 2-core VM, 2 x 10^6 rows x 40 columns: ~22 GB/s for both
// kernels on one core, the memory bandwidth of one core.
using Pack = double __attribute__((vector_size(16)));

Pack load(const double* p) {
  Pack v;
  std::memcpy(&v, p, sizeof v);
  return v;
}

double lanes_sum(Pack v) { return v[0] + v[1]; }

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
    for (; i + 2 <= b; i += 2) {
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
  for (; c < j; ++c) {
    const double* q = Q + c * n;
    Pack sv{}, tv{};
    long i = a;
    for (; i + 2 <= b; i += 2) {
      const Pack qv = load(q + i);
      sv += qv * load(x + i);
      if constexpr (kTwo) tv += qv * load(y + i);
    }
    double sc = lanes_sum(sv), tc = lanes_sum(tv);
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
  Pack xx{}, xy{}, yy{};
  long i = a;
  for (; i + 2 <= b; i += 2) {
    const Pack xv = load(x + i);
    xx += xv * xv;
    if constexpr (kTwo) {
      const Pack yv = load(y + i);
      xy += xv * yv;
      yy += yv * yv;
    }
  }
  ProjectedProducts p{lanes_sum(xx), lanes_sum(xy), lanes_sum(yy)};
  for (; i < b; ++i) {
    p.xx += x[i] * x[i];
    if constexpr (kTwo) {
      p.xy += x[i] * y[i];
      p.yy += y[i] * y[i];
    }
  }
  return p;
}

// Runs work(first_chunk, last_chunk) on `threads` contiguous ranges of the chunks, one of them in
// the calling thread. A thread that cannot be started leaves its range to the calling thread.
template <class Work>
void for_chunk_ranges(long chunks, int threads, const Work& work) {
  const long parts = std::clamp<long>(threads, 1, std::max(1L, chunks));
  if (parts == 1) {
    work(0L, chunks);
    return;
  }
  std::vector<std::thread> pool;
  std::vector<long> left_over;
  for (long p = 1; p < parts; ++p) {
    try {
      pool.emplace_back(work, p * chunks / parts, (p + 1) * chunks / parts);
    } catch (const std::system_error&) {
      left_over.push_back(p);
    }
  }
  work(0L, chunks / parts);
  for (long p : left_over) work(p * chunks / parts, (p + 1) * chunks / parts);
  for (auto& thread : pool) thread.join();
}

long chunk_count(long n) { return (n + kGramSchmidtRows - 1) / kGramSchmidtRows; }

}  // namespace

int gram_schmidt_threads(long n) {
  const long hardware = std::max(1u, std::thread::hardware_concurrency());
  return static_cast<int>(std::clamp(n >> 16, 1L, hardware));
}

void basis_coefficients(const double* Q, long n, long j, const double* x, const double* y, double* s, double* t,
                        int threads) {
  const long chunks = chunk_count(n);
  const bool two = y != nullptr;
  // partial[k][0:j] = chunk k's part of s, partial[k][j:2j] of t
  std::vector<double> partial(static_cast<size_t>(chunks * 2 * j));
  for_chunk_ranges(chunks, threads, [&](long first, long last) {
    for (long k = first; k < last; ++k) {
      const long a = k * kGramSchmidtRows, b = std::min(n, a + kGramSchmidtRows);
      double* ps = partial.data() + k * 2 * j;
      if (two) chunk_coefficients<true>(Q, n, j, x, y, a, b, ps, ps + j);
      else chunk_coefficients<false>(Q, n, j, x, y, a, b, ps, ps + j);
    }
  });
  std::fill(s, s + j, 0.0);
  if (two) std::fill(t, t + j, 0.0);
  for (long k = 0; k < chunks; ++k) {
    const double* ps = partial.data() + k * 2 * j;
    for (long c = 0; c < j; ++c) {
      s[c] += ps[c];
      if (two) t[c] += ps[j + c];
    }
  }
}

ProjectedProducts subtract_in_basis(const double* Q, long n, long j, const double* s, const double* t, double* x,
                                    double* y, int threads) {
  const long chunks = chunk_count(n);
  std::vector<ProjectedProducts> partial(static_cast<size_t>(chunks));
  for_chunk_ranges(chunks, threads, [&](long first, long last) {
    for (long k = first; k < last; ++k) {
      const long a = k * kGramSchmidtRows, b = std::min(n, a + kGramSchmidtRows);
      partial[k] =
          y ? chunk_subtract<true>(Q, n, j, s, t, x, y, a, b) : chunk_subtract<false>(Q, n, j, s, t, x, y, a, b);
    }
  });
  ProjectedProducts total;
  for (const auto& p : partial) {
    total.xx += p.xx;
    total.xy += p.xy;
    total.yy += p.yy;
  }
  return total;
}

void divide_and_split(long n, double r, double g, double* u, const double* w, double* z, int threads) {
  const double inverse = 1 / r;
  for_chunk_ranges(chunk_count(n), threads, [&](long first, long last) {
    const long a = first * kGramSchmidtRows, b = std::min(n, last * kGramSchmidtRows);
    for (long i = a; i < b; ++i) {
      u[i] *= inverse;
      z[i] = (w[i] - g * u[i]) * inverse;
    }
  });
}

}  // namespace delayspec::detail
