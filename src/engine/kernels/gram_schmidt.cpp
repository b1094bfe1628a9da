// Gram-Schmidt kernels streaming a tall basis once (detail/gram_schmidt.hpp): the threaded
// drivers; the row-chunk bodies are in gram_schmidt_chunks.hpp, portable here.
#include "delayspec/detail/gram_schmidt.hpp"

#include <algorithm>
#include <system_error>
#include <thread>
#include <vector>

#include "delayspec/detail/kernel_dispatch.hpp"
#include "engine/kernels/gram_schmidt_chunks.hpp"

namespace delayspec::detail {

namespace {

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

// The chunk kernels of the path choose_kernel_path picks (DELAYSPEC_KERNEL, the CPU).
const GramSchmidtChunkKernels& chunk_kernels() {
  return runs_avx2_code(choose_kernel_path(KernelPath::avx2)) ? gram_schmidt_chunks_avx2() : kChunkKernels;
}

}  // namespace

int gram_schmidt_threads(long n) {
  // Read once: hardware_concurrency() reads /sys on every call (measured 6 % of GMRES at n = 4002,
  // which asks once per Newton step).
  static const long hardware = std::max(1u, std::thread::hardware_concurrency());
  return static_cast<int>(std::clamp(n >> 16, 1L, hardware));
}

void basis_coefficients(const double* Q, long n, long j, const double* x, const double* y, double* s, double* t,
                        int threads) {
  const long chunks = chunk_count(n);
  const bool two = y != nullptr;
  const GramSchmidtChunkKernels& kernels = chunk_kernels();
  // partial[k][0:j] = chunk k's part of s, partial[k][j:2j] of t
  std::vector<double> partial(static_cast<size_t>(chunks * 2 * j));
  for_chunk_ranges(chunks, threads, [&](long first, long last) {
    for (long k = first; k < last; ++k) {
      const long a = k * kGramSchmidtRows, b = std::min(n, a + kGramSchmidtRows);
      double* ps = partial.data() + k * 2 * j;
      kernels.coefficients(Q, n, j, x, y, a, b, ps, ps + j);
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
  const GramSchmidtChunkKernels& kernels = chunk_kernels();
  std::vector<ProjectedProducts> partial(static_cast<size_t>(chunks));
  for_chunk_ranges(chunks, threads, [&](long first, long last) {
    for (long k = first; k < last; ++k) {
      const long a = k * kGramSchmidtRows, b = std::min(n, a + kGramSchmidtRows);
      partial[k] = kernels.subtract(Q, n, j, s, t, x, y, a, b);
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
