// Simulation over a window (simulation.hpp) and the `delayspec simulate` command.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "cli_test_support.hpp"
#include "delayspec/simulation.hpp"
#include "delayspec_test_paths.hpp"
#include "event_fd_support.hpp"

using namespace delayspec;
using namespace delayspec::testing;

namespace {

using delayspec::testing::CliResult;
using delayspec::testing::run;

const std::string kScene = std::string(DELAYSPEC_SOURCE_DIR) + "/data/scenes/default.toml";

}  // namespace

TEST(Simulation, PoincarePointsAreTheStroboscopicMapIterates) {
  // Same steps, same order, same times: bit-identical to iterating StroboscopicMap.
  const ImpactModel model(paper_orbit_parameters());
  const TrapezoidStepper<ImpactModel> stepper(model);
  const HistoryGrid grid = make_grid(model.tau(), model.period(), 60);
  const StroboscopicMap<ImpactModel> map(stepper, grid);
  Eigen::VectorXd U = map.constant_history(model.initial_state());
  SimulationOptions o;
  o.t_end = 5 * model.period();
  const SimulationRecord<2> rec = simulate(stepper, stepper, grid, U, o);
  ASSERT_EQ(rec.poincare_y.size(), 6u);  // t = 0, T, ..., 5 T
  for (size_t i = 0; i < rec.poincare_y.size(); ++i) {
    EXPECT_EQ(rec.poincare_y[i], V2(U.tail<2>())) << "period " << i;
    U = map.apply(U);
  }
  EXPECT_EQ(rec.t.size(), static_cast<size_t>(5 * 60 + 1));
}

TEST(Simulation, OneImpactPerPeriodOnThePeriodOneOrbit) {
  // The period-1 orbit at N = 200 impacts once per period (max x - e ~ 1e-3); in a window of 20
  // periods after settling, 20 impacts, one per period at the same phase (to the orbit's
  // settling accuracy, 1e-6 after 3000 periods with |mu_1| = 0.976). (At N = 100 the default
  // 4 contact sub-steps give |mu_1| = 1.02: the discrete orbit is unstable there.)
  const ImpactModel model(paper_orbit_parameters());
  const TrapezoidStepper<ImpactModel> stepper(model);
  const HistoryGrid grid = make_grid(model.tau(), model.period(), 200);
  const StroboscopicMap<ImpactModel> map(stepper, grid);
  SimulationOptions o;
  o.t_start = 3000 * model.period();
  o.t_end = 3020 * model.period();
  const SimulationRecord<2> rec = simulate(stepper, stepper, grid, map.constant_history(model.initial_state()), o);
  ASSERT_EQ(rec.impact_times.size(), 20u);
  for (size_t i = 1; i < rec.impact_times.size(); ++i)
    EXPECT_NEAR(rec.impact_times[i] - rec.impact_times[i - 1], model.period(), 1e-6);
  EXPECT_GT(rec.max_H, 0);
}

TEST(Simulation, BadWindowIsBadInput) {
  const ImpactModel model;
  const TrapezoidStepper<ImpactModel> stepper(model);
  const HistoryGrid grid = make_grid(model.tau(), model.period(), 20);
  const Eigen::VectorXd U = Eigen::VectorXd::Zero(grid.dimension(2));
  SimulationOptions o;
  o.t_end = -1;
  EXPECT_THROW(simulate(stepper, stepper, grid, U, o), BadInput);
  o.t_end = 10;
  o.t_start = 11;
  EXPECT_THROW(simulate(stepper, stepper, grid, U, o), BadInput);
  o.t_start = 0;
  o.sample_every = 0;
  EXPECT_THROW(simulate(stepper, stepper, grid, U, o), BadInput);
  o.sample_every = 1;
  EXPECT_THROW(simulate(stepper, stepper, grid, Eigen::VectorXd::Zero(3), o), BadInput);
}

TEST(CliSimulate, JsonAndCsvFiles) {
  const std::filesystem::path dir = delayspec::testing::scratch_path("simulate");
  const CliResult r = run({"simulate", kScene, "--set", "N=50", "--set", "t_end=100", "--set", "t_start=50", "--set",
                           "sample_every=5", "--json", "--out", dir.string()});
  ASSERT_EQ(r.status, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  for (const char* key : {"impacts", "impact_times", "poincare", "steps", "t_end", "t_start", "h", "N", "files"})
    EXPECT_TRUE(j.contains(key)) << key;
  EXPECT_EQ(j["impacts"].get<size_t>(), j["impact_times"].size());
  std::ifstream traj(dir / "trajectory.csv");
  std::string header, line;
  while (std::getline(traj, header) && header.rfind("#", 0) == 0) {
  }  // the metadata lines (docs/formats.md)
  EXPECT_EQ(header, "t,x,v");
  long rows = 0;
  double first_t = -1;
  while (std::getline(traj, line)) {
    if (rows == 0) first_t = std::stod(line.substr(0, line.find(',')));
    ++rows;
  }
  EXPECT_EQ(rows, j["samples"].get<long>());
  EXPECT_GE(first_t, 50.0);
  EXPECT_TRUE(std::filesystem::exists(dir / "poincare.csv"));
  EXPECT_TRUE(std::filesystem::exists(dir / "impacts.csv"));
  std::filesystem::remove_all(dir);
}

TEST(CliSimulate, BadKeysExitTwoNamingThem) {
  struct Case {
    std::vector<std::string> sets;
    const char* named;
  };
  for (const Case& c : std::vector<Case>{{{"t_end=-3"}, "t_end"},
                                         {{"t_end=10", "t_start=20"}, "t_start"},
                                         {{"sample_every=0"}, "sample_every"},
                                         {{"control_on_at=-1"}, "control_on_at"},
                                         {{"model=linear", "control_on_at=5"}, "control_on_at"},
                                         {{"contact_substeps=0"}, "contact_substeps"},
                                         {{"events_before_control=maybe", "control_on_at=5"}, "events_before_control"},
                                         {{"events_before_control=off"}, "events_before_control"},
                                         {{"t_ned=5"}, "t_ned"}}) {
    std::vector<std::string> args = {"simulate"};
    for (const auto& s : c.sets) {
      args.push_back("--set");
      args.push_back(s);
    }
    const CliResult r = run(args);
    EXPECT_EQ(r.status, 2) << c.named;
    EXPECT_NE(r.err.find(c.named), std::string::npos) << r.err;
  }
}

// Fig. 6.3's fair comparison: with events_before_control = on, runs that differ only in `events`
// after control_on_at share the trajectory up to the switch bit for bit (same steps, same
// stepper), and differ after it (the orbit impacts, and events off steps across the contacts
// differently). Without the key the chaotic uncontrolled phase already separates them.
TEST(CliSimulate, EventsBeforeControlGivesBothRunsTheSameStateAtTheSwitch) {
  auto poincare = [](const std::vector<std::string>& extra) {
    std::vector<std::string> args = {"simulate", kScene,      "--set", "N=100", "--set", "k=1.4", "--set",
                                     "e=1.2609", "--set",     "x0=0",  "--set", "v0=0",  "--set", "control_on_at=300",
                                     "--set",    "t_end=600", "--json"};
    args.insert(args.end(), extra.begin(), extra.end());
    const CliResult r = run(args);
    EXPECT_EQ(r.status, 0) << r.err;
    return nlohmann::json::parse(r.out)["poincare"];
  };
  const auto on = poincare({"--set", "events=on"});
  const auto off = poincare({"--set", "events=off", "--set", "events_before_control=on"});
  const auto off_throughout = poincare({"--set", "events=off"});
  ASSERT_EQ(on.size(), off.size());
  ASSERT_GT(on.size(), 70u);  // t = m T, T = 2 pi / 0.802 = 7.83
  const double switch_time = 300;
  size_t before = 0, differ_after = 0, differ_throughout = 0;
  for (size_t i = 0; i < on.size(); ++i) {
    const double t = on[i][0].get<double>();
    if (t <= switch_time) {
      ++before;
      EXPECT_EQ(on[i], off[i]) << "t = " << t;  // identical up to and including the switch
      differ_throughout += on[i] != off_throughout[i];
    } else {
      differ_after += on[i] != off[i];
    }
  }
  EXPECT_GE(before, 38u);
  EXPECT_GT(differ_after, 0u);
  EXPECT_GT(differ_throughout, 0u);  // the key is what makes the states equal
}
