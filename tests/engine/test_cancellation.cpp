// The cooperative cancellation hook (cancellation.hpp), which the Python module uses for Ctrl-C:
// a check installed for a thread stops each Krylov backend between two applications of the
// monodromy operator, the stroboscopic map and the exponent run between periods, and reaches the
// workers of parallel_points; the check is asked once per period, so the run stops at the first
// period after the request. Without a check nothing changes.
#include <gtest/gtest.h>

#include <atomic>
#include <mutex>
#include <set>
#include <thread>

#include "delayspec/cancellation.hpp"
#include "delayspec/floquet.hpp"
#include "delayspec/lyapunov.hpp"
#include "delayspec/model_linear.hpp"
#include "delayspec/stroboscopic_map.hpp"
#include "delayspec/parallel_points.hpp"

using namespace delayspec;

namespace {

// Requests cancellation from its (limit + 1)-th question on.
class AfterQuestions final : public CancellationCheck {
 public:
  explicit AfterQuestions(long limit) : limit_(limit) {}
  bool requested() override { return ++questions_ > limit_; }
  long questions() const { return questions_.load(); }

 private:
  const long limit_;
  std::atomic<long> questions_{0};
};

StroboscopicMap<LinearModel> linear_map(int N) {
  const LinearModel model({.a = -1, .b = 0.5, .tau = 1, .period = 1});
  return StroboscopicMap<LinearModel>(TrapezoidStepper<LinearModel>(model), make_grid(model.tau(), model.period(), N));
}

}  // namespace

TEST(Cancellation, EveryKrylovBackendStopsBetweenOperatorApplications) {
  const auto map = linear_map(300);
  const auto op = map.monodromy(Eigen::VectorXd::Zero(map.dimension()));
  for (FloquetSolver solver : {FloquetSolver::spectra, FloquetSolver::arpack, FloquetSolver::block}) {
    FloquetOptions o;
    o.nev = 4;
    o.solver = solver;
    AfterQuestions check(5);
    {
      const CancellationScope scope(&check);
      EXPECT_THROW(floquet_multipliers(op, o), Cancelled);
    }
    // Asked before each application: the 6th application stops, none follows.
    EXPECT_EQ(check.questions(), 6);
    EXPECT_EQ(current_cancellation_check(), nullptr);  // the scope is gone
    // The same solve without a check completes (far more than 6 applications).
    const FloquetResult r = floquet_multipliers(op, o);
    EXPECT_GT(r.operator_applications, 6);
  }
}

TEST(Cancellation, StroboscopicMapStopsAtTheNextPeriod) {
  const auto map = linear_map(50);
  Eigen::VectorXd U = map.constant_history(Vec<1>(1));
  AfterQuestions check(3);
  const CancellationScope scope(&check);
  for (int period = 0; period < 3; ++period) U = map.apply(U);
  EXPECT_THROW(map.apply(U), Cancelled);
}

TEST(Cancellation, LyapunovRunStopsAtTheNextPeriod) {
  const auto map = linear_map(50);
  LyapunovOptions o;
  o.transient = 10;
  o.periods = 1000;
  long periods_done = 0;
  o.progress = [&](long done, long) { periods_done = done; };
  AfterQuestions check(25);
  const CancellationScope scope(&check);
  EXPECT_THROW(lyapunov_exponents(map, map.constant_history(Vec<1>(1)), o), Cancelled);
  // Asked once after each period (lyapunov.hpp): the 26th question ends the run after period 26.
  EXPECT_EQ(periods_done, 26);
  EXPECT_EQ(check.questions(), 26);
}

TEST(Cancellation, ParallelPointsWorkersRunUnderTheCallersCheck) {
  AfterQuestions check(1000000);  // never requests: only who sees it matters
  std::mutex mutex;
  std::set<std::thread::id> threads;
  bool all_saw_it = true;
  {
    const CancellationScope scope(&check);
    parallel_points(64, 4, [&](long) {
      std::lock_guard<std::mutex> lock(mutex);
      threads.insert(std::this_thread::get_id());
      all_saw_it = all_saw_it && current_cancellation_check() == &check;
      std::this_thread::sleep_for(std::chrono::milliseconds(1));  // let the pool's threads take points
    });
  }
  EXPECT_TRUE(all_saw_it);
  EXPECT_GT(threads.size(), 1u);
}

TEST(Cancellation, ParallelPointsRethrowsCancelledOnTheCallingThread) {
  AfterQuestions check(0);  // requests at once
  const CancellationScope scope(&check);
  std::atomic<long> finished{0};
  EXPECT_THROW(parallel_points(100, 3,
                                    [&](long) {
                                      throw_if_cancelled();
                                      ++finished;
                                    }),
               Cancelled);
  EXPECT_EQ(finished.load(), 0);
}

TEST(Cancellation, ScopesNestAndRestore) {
  AfterQuestions outer(1000), inner(1000);
  EXPECT_EQ(current_cancellation_check(), nullptr);
  {
    const CancellationScope a(&outer);
    {
      const CancellationScope b(&inner);
      EXPECT_EQ(current_cancellation_check(), &inner);
    }
    EXPECT_EQ(current_cancellation_check(), &outer);
  }
  EXPECT_EQ(current_cancellation_check(), nullptr);
  EXPECT_NO_THROW(throw_if_cancelled());
}
