// `floquet` with `period_guess`: a periodic orbit of unknown period (autonomous_orbit.hpp; the
// engine's own tests check it against closed forms). Here: the command's fields, its period's
// error bar against a much finer solve (N = 1600, whose own error is (100 / 1600)^2 = 1/256 of the
// default's), and bad input.
#include <gtest/gtest.h>

#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <csignal>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <thread>
#include <vector>

#include "cli_test_support.hpp"

namespace {

using delayspec::testing::CliResult;
using delayspec::testing::run;

const std::vector<std::string> kMackeyGlass8 = {"floquet", "--json", "--set", "model=mackey-glass", "--set", "tau=8",
                                                "--set",   "x0=1.1", "--set",  "period_guess=20"};

nlohmann::json floquet_json(std::vector<std::string> args) {
  const CliResult r = run(args);
  EXPECT_EQ(r.status, 0) << r.err;
  return nlohmann::json::parse(r.out);
}

TEST(AutonomousOrbitCli, MackeyGlassOrbitItsPeriodErrorBarAndTrivialMultiplier) {
  const nlohmann::json j = floquet_json(kMackeyGlass8);
  std::vector<std::string> fine = kMackeyGlass8;
  fine.insert(fine.end(), {"--set", "N=1600", "--set", "error_bars=off"});
  const double reference = floquet_json(fine)["period"].get<double>();
  const double T = j["period"].get<double>();
  EXPECT_GT(T, 20);
  // the extrapolated period within its error estimate of the much finer solve (whose own error,
  // 1/256 of N = 100's, is covered by 1e-6 relative); the bar printed at N, |T - extrapolated| +
  // error, then covers T's error too (triangle inequality)
  const auto& bars = j["period_error_bars"];
  const double extrapolated = bars["extrapolated"].get<double>(), error = bars["error_estimate"].get<double>();
  EXPECT_LE(std::abs(extrapolated - reference), error + std::abs(reference) * 1e-6) << bars.dump();
  EXPECT_GT(std::abs(T - reference), 1e-6);  // N = 100 is not N = 1600: the bar has something to cover
  // the trivial multiplier apart, at rounding; the orbit is stable
  EXPECT_LT(j["trivial_multiplier"]["distance_from_1"].get<double>(), 1e-10);
  EXPECT_EQ(j["multipliers"].size(), 6u);
  EXPECT_LT(j["multipliers"][0]["abs"].get<double>(), 1);
  EXPECT_EQ(j["verdict"], "stable");
  EXPECT_EQ(j["steps_per_period"].get<int>(), 250);  // round(N T_guess / tau) = round(100 * 20 / 8)
}

TEST(AutonomousOrbitCli, ConvergeExtrapolatesThePeriod) {
  const nlohmann::json j = floquet_json({"converge", "--json", "--set", "model=mackey-glass", "--set", "tau=8", "--set",
                                         "x0=1.1", "--set", "period_guess=20", "--set", "Ns=50,100,200,400"});
  const auto& p = j["period"];
  ASSERT_EQ(p["periods"].size(), 4u);
  std::vector<std::string> fine = kMackeyGlass8;
  fine.insert(fine.end(), {"--set", "N=1600", "--set", "error_bars=off"});
  const double reference = floquet_json(fine)["period"].get<double>();
  // the extrapolation over N = 50 .. 400 within its error estimate of the N = 1600 solve (whose
  // own error is (400 / 1600)^2 = 1/16 of N = 400's, which is itself inside the estimate's scale)
  EXPECT_LE(std::abs(p["extrapolated"].get<double>() - reference),
            p["error_estimate"].get<double>() + std::abs(p["periods"][3].get<double>() - reference) / 16)
      << p.dump();
  EXPECT_EQ(j["rows"].size(), 4u);  // the other multipliers' study, as for any orbit
}

// At N = 3200 `orbit = auto` (the default) solves by nested shooting (autonomous_shooting.hpp),
// `orbit = newton` by sparse LU on the whole period, on the same K: the same period. Newton's
// per-step residual test (1e-12 (1 + |x|) per step) adds up over K = 8000 steps: 1e-8 allows
// for it (at N = 800 it was 7e-10, test_autonomous_orbit.cpp), the multipliers to the
// eigensolver's 1e-8.
TEST(AutonomousOrbitCli, AutoShootsAndAgreesWithNewton) {
  std::vector<std::string> args = kMackeyGlass8;
  args.insert(args.end(), {"--set", "N=3200", "--set", "error_bars=off"});
  const CliResult shooting = run(args);
  ASSERT_EQ(shooting.status, 0) << shooting.err;
  args.insert(args.end(), {"--set", "orbit=newton"});
  const CliResult newton = run(args);
  ASSERT_EQ(newton.status, 0) << newton.err;
  const auto a = nlohmann::json::parse(shooting.out), b = nlohmann::json::parse(newton.out);
  EXPECT_EQ(a["orbit"]["method"].get<std::string>().rfind("shooting", 0), 0u) << a["orbit"];
  EXPECT_EQ(b["orbit"]["method"].get<std::string>().rfind("newton", 0), 0u) << b["orbit"];
  EXPECT_EQ(a["steps_per_period"], b["steps_per_period"]);
  EXPECT_NEAR(a["period"].get<double>(), b["period"].get<double>(), 1e-8);
  EXPECT_NEAR(a["multipliers"][0]["re"].get<double>(), b["multipliers"][0]["re"].get<double>(), 1e-8);
}

TEST(AutonomousOrbitCli, BadInputAndNoOrbit) {
  for (const auto& [sets, says] : std::vector<std::pair<std::vector<std::string>, std::string>>{
           {{"model=impact", "period_guess=6"}, "`period_guess` with `model = impact`"},
           {{"model=linear", "period_guess=2"}, "a linear model has no isolated periodic orbits"},
           {{"model=mackey-glass", "period_guess=-1"}, "`period_guess = -1`"},
           {{"model=mackey-glass", "period_guess=abc"}, "`period_guess = abc`"},
           {{"model=mackey-glass", "period_guess=20", "orbit=simulate"}, "`orbit = simulate` with `period_guess`"}}) {
    std::vector<std::string> args = {"floquet"};
    for (const std::string& s : sets) args.insert(args.end(), {"--set", s});
    const CliResult r = run(args);
    EXPECT_EQ(r.status, 2) << says << ": " << r.err;
    EXPECT_NE(r.err.find(says), std::string::npos) << r.err;
  }
  // the history at the equilibrium x* = 1: the guess is that equilibrium, no orbit (exit 3)
  const CliResult r = run({"floquet", "--set", "model=mackey-glass", "--set", "tau=8", "--set", "x0=1", "--set",
                           "period_guess=20"});
  EXPECT_EQ(r.status, 3) << r.err;
  EXPECT_NE(r.err.find("no periodic orbit near the guess"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("residual"), std::string::npos) << r.err;
}

}  // namespace

// Issue 61 item 3: sizes bounded before allocation. A period_guess far beyond the orbit's asks for
// an orbit system the machine cannot hold (Mackey-Glass, N = 200, tau = 17: 1.2e7 steps per
// period, a sparse LU whose factors fill the delay's band, >= 19 GB); it used to grow until the
// kernel killed it (exit 137, no message). Run in a forked child whose address space is limited
// to what it has mapped plus 1.5 GB (`ulimit -v`; "plus" so that a sanitizer's reserved shadow
// does not count): exit 2 naming the key, in milliseconds, before anything large is allocated.
TEST(AutonomousOrbitCli, AnOrbitSystemBeyondTheMemoryIsRefusedNamingTheKey) {
  int pipe_fds[2];
  ASSERT_EQ(::pipe(pipe_fds), 0);
  const pid_t pid = ::fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) {
    ::close(pipe_fds[0]);
    double mapped = 0;
    std::ifstream status("/proc/self/status");
    for (std::string line; std::getline(status, line);)
      if (line.rfind("VmSize:", 0) == 0) mapped = 1024.0 * std::strtod(line.c_str() + 7, nullptr);
    rlimit limit{};
    ::getrlimit(RLIMIT_AS, &limit);
    limit.rlim_cur = static_cast<rlim_t>(mapped + 1.5e9);
    if (::setrlimit(RLIMIT_AS, &limit) != 0) ::_exit(120);
    const CliResult r = run({"floquet", "--set", "model=mackey-glass", "--set", "N=200", "--set", "period_guess=1e6"});
    const std::string message = std::to_string(r.status) + "\n" + r.err;
    if (::write(pipe_fds[1], message.data(), message.size()) < 0) ::_exit(121);
    ::_exit(0);
  }
  ::close(pipe_fds[1]);
  // The child runs in a copy of this (threaded) process without exec: should it ever hang, it is
  // killed after a minute and the test fails, rather than CI hanging.
  int child = 0;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  pid_t done = 0;
  while ((done = ::waitpid(pid, &child, WNOHANG)) == 0 && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  if (done == 0) {
    ::kill(pid, SIGKILL);
    ::waitpid(pid, &child, 0);
    ::close(pipe_fds[0]);
    FAIL() << "the child did not finish within 60 s";
  }
  ASSERT_EQ(done, pid);
  std::string message;
  char buffer[4096];
  for (ssize_t got; (got = ::read(pipe_fds[0], buffer, sizeof buffer)) > 0;) message.append(buffer, got);
  ::close(pipe_fds[0]);
  ASSERT_TRUE(WIFEXITED(child) && WEXITSTATUS(child) == 0) << "child status " << child << ": " << message;
  EXPECT_EQ(message.substr(0, 2), "2\n") << message;
  EXPECT_NE(message.find("`period_guess = 1e+06` (11764706 steps per period at N = 200) needs at least"), std::string::npos) << message;
  EXPECT_NE(message.find("this process may use"), std::string::npos) << message;
}
