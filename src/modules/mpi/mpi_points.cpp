// The distributed point loop under MPI (distributed_points.hpp describes it): the lead's
// dispatcher and compute threads, the workers' requests.
#include <mpi.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdint>
#include <cstring>
#include <exception>
#include <mutex>
#include <new>
#include <stdexcept>
#include <string>
#include <thread>

#include "delayspec/errors.hpp"
#include "modules/mpi/mpi_parts.hpp"

namespace delayspec::cli::mpi {

namespace {

// Worker -> lead: [int32 points wanted next][int64 n][n x (int64 index, int32 outcome, int64 size,
// bytes)], the points finished since the last request (none in a thread's first request).
constexpr int request_tag = 1801;
// Lead -> worker: int64 indices to compute next; none = no more points.
constexpr int reply_tag = 1802;

// A worker asks for as many points as it computes in about this time (its own mean cost per
// point so far), so that cheap points (a chart point at N = 40: 0.3 ms) do not each pay a round
// trip to the lead; the lead grants at most remaining / (2 * all threads), so that the chunks
// shrink towards the end and the ranks finish together.
constexpr double chunk_seconds = 0.02;
constexpr int max_chunk = 4096;

// What a finished point's request carries: its result, or the exception its compute threw.
enum class Outcome : std::int32_t { result, bad_input, numerical_failure, out_of_memory, other };

struct FinishedPoint {
  std::int64_t index = 0;
  Outcome outcome = Outcome::result;
  std::string bytes;  // the encoded result, or the exception's message
};

struct Request {
  std::int32_t wanted = 1;
  std::vector<FinishedPoint> finished;
};

template <class T>
void put(std::string& out, const T& value) {
  out.append(reinterpret_cast<const char*>(&value), sizeof value);
}

template <class T>
T get(const std::string& in, size_t& at) {
  T value;
  std::memcpy(&value, in.data() + at, sizeof value);
  at += sizeof value;
  return value;
}

std::string pack(const Request& r) {
  std::string message;
  put(message, r.wanted);
  put(message, static_cast<std::int64_t>(r.finished.size()));
  for (const FinishedPoint& p : r.finished) {
    put(message, p.index);
    put(message, p.outcome);
    put(message, static_cast<std::int64_t>(p.bytes.size()));
    message += p.bytes;
  }
  return message;
}

Request unpack(const std::string& message) {
  size_t at = 0;
  Request r;
  r.wanted = get<std::int32_t>(message, at);
  r.finished.resize(static_cast<size_t>(get<std::int64_t>(message, at)));
  for (FinishedPoint& p : r.finished) {
    p.index = get<std::int64_t>(message, at);
    p.outcome = get<Outcome>(message, at);
    const auto size = static_cast<size_t>(get<std::int64_t>(message, at));
    p.bytes = message.substr(at, size);
    at += size;
  }
  return r;
}

// The exception of a point computed on a worker, rethrown on the lead with its type.
std::exception_ptr remote_exception(const FinishedPoint& p) {
  switch (p.outcome) {
    case Outcome::bad_input: return std::make_exception_ptr(BadInput(p.bytes));
    case Outcome::numerical_failure: return std::make_exception_ptr(NumericalFailure(p.bytes));
    case Outcome::out_of_memory: return std::make_exception_ptr(std::bad_alloc());
    default: return std::make_exception_ptr(std::runtime_error(p.bytes));
  }
}

// The first failure of a loop, on any thread or rank.
class FirstFailure {
 public:
  void set(std::exception_ptr e) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!failure_) failure_ = std::move(e);
  }
  void rethrow_if_any() {
    if (failure_) std::rethrow_exception(failure_);
  }

 private:
  std::mutex mutex_;
  std::exception_ptr failure_;
};

// Waits for the next request. MPI_Probe would spin (OpenMPI polls: a core at 100% on rank 0,
// taken from its compute threads), so the dispatcher probes and sleeps, 20 us at first, then
// longer while nothing comes, up to 250 us: a request waits at most about 0.3 ms, small next to
// the chunk_seconds of work a request asks for, and an idle dispatcher wakes 4000 times a
// second, a negligible load.
MPI_Status next_request() {
  using namespace std::chrono_literals;
  auto pause = 20us;
  for (;;) {
    int arrived = 0;
    MPI_Status status;
    MPI_Iprobe(MPI_ANY_SOURCE, request_tag, MPI_COMM_WORLD, &arrived, &status);
    if (arrived) return status;
    std::this_thread::sleep_for(pause);
    pause = std::min<std::chrono::microseconds>(2 * pause, 250us);
  }
}

// The message `status` announces, received.
template <class T>
std::vector<T> receive(const MPI_Status& status, MPI_Datatype type) {
  int count = 0;
  MPI_Get_count(&status, type, &count);
  std::vector<T> data(static_cast<size_t>(count));
  MPI_Recv(data.data(), count, type, status.MPI_SOURCE, status.MPI_TAG, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
  return data;
}

}  // namespace

// The lead: its threads take indices one at a time, and the dispatcher chunks for the workers,
// from one counter.
void lead_points(const std::vector<long>& todo, int threads, long worker_threads, const PointTasks& tasks,
                 const std::function<void()>& point_done) {
  const long count = static_cast<long>(todo.size());
  const long all_threads = threads + worker_threads;
  std::atomic<long> next{0};
  FirstFailure failure;
  auto fail = [&](std::exception_ptr e) {
    failure.set(std::move(e));
    next.store(count);  // stop handing out points, here and to the workers
  };

  std::thread dispatcher([&] {
    for (long requesters = worker_threads; requesters > 0;) {
      const MPI_Status status = next_request();
      const std::vector<char> bytes = receive<char>(status, MPI_BYTE);
      const Request request = unpack(std::string(bytes.begin(), bytes.end()));
      for (const FinishedPoint& p : request.finished) {
        if (p.outcome != Outcome::result) {
          fail(remote_exception(p));
          continue;
        }
        try {
          tasks.decode(p.index, p.bytes);
        } catch (...) {
          fail(std::current_exception());
        }
      }
      const long remaining = std::max(count - next.load(), 0L);
      const long grant = std::clamp<long>(request.wanted, 1, std::max(remaining / (2 * all_threads), 1L));
      const long first = std::min(next.fetch_add(grant), count);
      const long end = std::min(first + grant, count);
      std::vector<std::int64_t> chunk;
      for (long i = first; i < end; ++i) chunk.push_back(todo[static_cast<size_t>(i)]);
      if (chunk.empty()) --requesters;
      MPI_Send(chunk.data(), static_cast<int>(chunk.size()), MPI_INT64_T, status.MPI_SOURCE, reply_tag, MPI_COMM_WORLD);
    }
  });
  auto compute = [&] {
    for (long i = next.fetch_add(1); i < count; i = next.fetch_add(1)) {
      try {
        tasks.compute(todo[static_cast<size_t>(i)]);
      } catch (...) {
        fail(std::current_exception());
      }
      point_done();
    }
  };
  std::vector<std::thread> pool;
  for (int t = 1; t < threads; ++t) pool.emplace_back(compute);
  compute();
  for (auto& t : pool) t.join();
  dispatcher.join();
  failure.rethrow_if_any();
}

// A worker: each thread asks the lead for a chunk of indices, computes it, and sends the results
// with its next request; the threads take turns at the MPI calls (MPI_THREAD_SERIALIZED).
void worker_points(int threads, const PointTasks& tasks, const std::function<void()>& point_done) {
  std::mutex mpi;
  auto compute = [&] {
    Request request;
    for (;;) {
      std::vector<std::int64_t> chunk;
      {
        std::lock_guard<std::mutex> lock(mpi);
        const std::string message = pack(request);
        MPI_Send(message.data(), static_cast<int>(message.size()), MPI_BYTE, 0, request_tag, MPI_COMM_WORLD);
        MPI_Status status;
        MPI_Probe(0, reply_tag, MPI_COMM_WORLD, &status);
        chunk = receive<std::int64_t>(status, MPI_INT64_T);
      }
      if (chunk.empty()) return;
      request.finished.clear();
      const auto start = std::chrono::steady_clock::now();
      for (const std::int64_t index : chunk) {
        FinishedPoint p{index, Outcome::result, ""};
        try {
          tasks.compute(index);
          p.bytes = tasks.encode(index);
        } catch (const BadInput& e) {
          p = {index, Outcome::bad_input, e.what()};
        } catch (const NumericalFailure& e) {
          p = {index, Outcome::numerical_failure, e.what()};
        } catch (const std::bad_alloc&) {
          p = {index, Outcome::out_of_memory, ""};
        } catch (const std::exception& e) {
          p = {index, Outcome::other, e.what()};
        }
        request.finished.push_back(std::move(p));
        point_done();
        if (request.finished.back().outcome != Outcome::result) break;  // the lead stops the loop
      }
      const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      const double per_point = seconds / static_cast<double>(request.finished.size());
      request.wanted = static_cast<std::int32_t>(
          std::clamp(per_point > 0 ? chunk_seconds / per_point : double(max_chunk), 1.0, double(max_chunk)));
    }
  };
  const int n = std::max(threads, 1);
  std::vector<std::thread> pool;
  for (int t = 1; t < n; ++t) pool.emplace_back(compute);
  compute();
  for (auto& t : pool) t.join();
}

}  // namespace delayspec::cli::mpi
