#include "distributed_points.hpp"

#include <algorithm>
#include <atomic>
#include <csignal>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <new>
#include <stdexcept>
#include <string>

#include "delayspec/errors.hpp"
#include "parallel_points.hpp"
#include "ranks.hpp"

#ifdef DELAYSPEC_MPI
#include <mpi.h>

#include <chrono>
#include <mutex>
#include <thread>
#endif

namespace delayspec::cli {

namespace {

// DELAYSPEC_TEST_KILL_RANK=R:K (see the header): the number of points after which this rank
// kills itself, 0 = never.
long kill_after_points() {
  const char* hook = std::getenv("DELAYSPEC_TEST_KILL_RANK");
  if (!hook) return 0;
  char* end = nullptr;
  const long r = std::strtol(hook, &end, 10);
  if (*end != ':' || r != this_rank()) return 0;
  return std::strtol(end + 1, nullptr, 10);
}

// Counts this rank's finished points for the test hook (thread-safe).
class KillHook {
 public:
  KillHook() : after_(kill_after_points()) {}
  void point_done() {
    if (after_ > 0 && done_.fetch_add(1) + 1 == after_) std::raise(SIGKILL);
  }

 private:
  long after_;
  std::atomic<long> done_{0};
};

}  // namespace

bool distributes_points(const std::string& command) {
  return command == "sweep" || command == "chart" || command == "basin" || command == "run";
}

#ifdef DELAYSPEC_MPI

namespace {

constexpr int request_tag = 1801;  // worker -> lead: [index of the finished point][kind][bytes]
constexpr int reply_tag = 1802;    // lead -> worker: the next index, or -1 = no more points

// What a finished point's request carries: its result, or the exception its compute threw.
enum class Outcome : std::int32_t { result, bad_input, numerical_failure, out_of_memory, other };

struct Request {
  std::int64_t index = -1;  // -1: the thread's first request (nothing finished yet)
  Outcome outcome = Outcome::result;
  std::string bytes;  // the encoded result, or the exception's message
};

std::string pack(const Request& r) {
  std::string message(sizeof r.index + sizeof r.outcome, '\0');
  std::memcpy(message.data(), &r.index, sizeof r.index);
  std::memcpy(message.data() + sizeof r.index, &r.outcome, sizeof r.outcome);
  return message + r.bytes;
}

Request unpack(const std::string& message) {
  Request r;
  std::memcpy(&r.index, message.data(), sizeof r.index);
  std::memcpy(&r.outcome, message.data() + sizeof r.index, sizeof r.outcome);
  r.bytes = message.substr(sizeof r.index + sizeof r.outcome);
  return r;
}

// The exception of a point computed on a worker, rethrown on the lead with its type.
std::exception_ptr remote_exception(const Request& r) {
  switch (r.outcome) {
    case Outcome::bad_input: return std::make_exception_ptr(BadInput(r.bytes));
    case Outcome::numerical_failure: return std::make_exception_ptr(NumericalFailure(r.bytes));
    case Outcome::out_of_memory: return std::make_exception_ptr(std::bad_alloc());
    default: return std::make_exception_ptr(std::runtime_error(r.bytes));
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
// longer while nothing comes, up to 1 ms: a request waits at most about 1 ms, small next to a
// point (docs/parallel.md), and an idle dispatcher costs no noticeable CPU.
MPI_Status next_request() {
  using namespace std::chrono_literals;
  auto pause = 20us;
  for (;;) {
    int arrived = 0;
    MPI_Status status;
    MPI_Iprobe(MPI_ANY_SOURCE, request_tag, MPI_COMM_WORLD, &arrived, &status);
    if (arrived) return status;
    std::this_thread::sleep_for(pause);
    pause = std::min<std::chrono::microseconds>(2 * pause, 1000us);
  }
}

// The lead: its threads and the dispatcher take indices from one counter.
void lead_points(const std::vector<long>& todo, int threads, long worker_threads, const PointTasks& tasks,
                 KillHook& hook) {
  const long count = static_cast<long>(todo.size());
  std::atomic<long> next{0};
  FirstFailure failure;
  auto take = [&]() -> long {
    const long i = next.fetch_add(1);
    return i < count ? todo[static_cast<size_t>(i)] : -1;
  };
  auto fail = [&](std::exception_ptr e) {
    failure.set(std::move(e));
    next.store(count);  // stop handing out points, here and to the workers
  };

  std::thread dispatcher([&] {
    for (long requesters = worker_threads; requesters > 0;) {
      const MPI_Status status = next_request();
      int size = 0;
      MPI_Get_count(&status, MPI_BYTE, &size);
      std::string message(static_cast<size_t>(size), '\0');
      MPI_Recv(message.data(), size, MPI_BYTE, status.MPI_SOURCE, request_tag, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
      const Request request = unpack(message);
      if (request.index >= 0 && request.outcome != Outcome::result) fail(remote_exception(request));
      if (request.index >= 0 && request.outcome == Outcome::result) {
        try {
          tasks.decode(request.index, request.bytes);
        } catch (...) {
          fail(std::current_exception());
        }
      }
      const std::int64_t reply = take();
      if (reply < 0) --requesters;
      MPI_Send(&reply, 1, MPI_INT64_T, status.MPI_SOURCE, reply_tag, MPI_COMM_WORLD);
    }
  });
  auto compute = [&] {
    for (long index = take(); index >= 0; index = take()) {
      try {
        tasks.compute(index);
      } catch (...) {
        fail(std::current_exception());
      }
      hook.point_done();
    }
  };
  const int n = std::max(threads, 1);
  std::vector<std::thread> pool;
  for (int t = 1; t < n; ++t) pool.emplace_back(compute);
  compute();
  for (auto& t : pool) t.join();
  dispatcher.join();
  failure.rethrow_if_any();
}

// A worker: each thread asks the lead for an index, computes it, and sends its result with the
// next request; the threads take turns at the MPI calls (MPI_THREAD_SERIALIZED).
void worker_points(int threads, const PointTasks& tasks, KillHook& hook) {
  std::mutex mpi;
  auto compute = [&] {
    Request finished;
    for (;;) {
      std::int64_t index = -1;
      {
        std::lock_guard<std::mutex> lock(mpi);
        const std::string message = pack(finished);
        MPI_Send(message.data(), static_cast<int>(message.size()), MPI_BYTE, 0, request_tag, MPI_COMM_WORLD);
        MPI_Recv(&index, 1, MPI_INT64_T, 0, reply_tag, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
      }
      if (index < 0) return;
      finished.index = index;
      try {
        tasks.compute(index);
        finished.outcome = Outcome::result;
        finished.bytes = tasks.encode(index);
      } catch (const BadInput& e) {
        finished = {index, Outcome::bad_input, e.what()};
      } catch (const NumericalFailure& e) {
        finished = {index, Outcome::numerical_failure, e.what()};
      } catch (const std::bad_alloc&) {
        finished = {index, Outcome::out_of_memory, ""};
      } catch (const std::exception& e) {
        finished = {index, Outcome::other, e.what()};
      }
      hook.point_done();
    }
  };
  const int n = std::max(threads, 1);
  std::vector<std::thread> pool;
  for (int t = 1; t < n; ++t) pool.emplace_back(compute);
  compute();
  for (auto& t : pool) t.join();
}

}  // namespace

#endif

void distributed_points(const std::vector<long>& todo, int threads, const PointTasks& tasks) {
  KillHook hook;
#ifdef DELAYSPEC_MPI
  if (rank_count() > 1) {
    const long worker_threads = enter_point_loop(threads);
    if (!is_lead_rank()) {
      worker_points(threads, tasks, hook);
      throw WorkerPointsDone{};
    }
    // As parallel_points: no more threads than points.
    const long local = std::clamp<long>(threads, 1, std::max<long>(static_cast<long>(todo.size()), 1));
    lead_points(todo, static_cast<int>(local), worker_threads, tasks, hook);
    return;
  }
#endif
  parallel_points(static_cast<long>(todo.size()), threads, [&](long i) {
    tasks.compute(todo[static_cast<size_t>(i)]);
    hook.point_done();
  });
}

}  // namespace delayspec::cli
