// `delayspec plot`: renders PNG and SVG (gnuplot) from result files, atomically, and rejects
// bad directories and settings with exit 2.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "cli_test_support.hpp"

namespace fs = std::filesystem;

namespace {

using delayspec::testing::CliResult;
using delayspec::testing::run;

std::string head(const fs::path& p, size_t n) {
  std::ifstream in(p, std::ios::binary);
  std::string s(n, '\0');
  in.read(s.data(), static_cast<std::streamsize>(n));
  s.resize(static_cast<size_t>(in.gcount()));
  return s;
}

fs::path fresh_dir(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("delayspec_test_plot_" + name);
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

}  // namespace

TEST(PlotCli, RendersMultipliersAndChartAsPngAndSvg) {
  const fs::path dir = fresh_dir("render");
  // Inputs written by the commands themselves.
  CliResult f = run({"floquet", "--json", "--set", "model=linear", "--set", "N=20", "--set", "solver=dense",
                     "--set", "nev=4"});
  ASSERT_EQ(f.status, 0) << f.err;
  std::ofstream(dir / "floquet.json") << f.out;
  CliResult c = run({"chart", "--out", dir.string(), "--set", "model=mathieu", "--set", "N=10", "--set",
                     "solver=dense", "--set", "chart_x_points=3", "--set", "chart_y_points=3"});
  ASSERT_EQ(c.status, 0) << c.err;

  CliResult p = run({"plot", dir.string(), "--json", "--set", "plot_width=300", "--set", "plot_height=200"});
  ASSERT_EQ(p.status, 0) << p.err;
  auto j = nlohmann::json::parse(p.out);
  EXPECT_EQ(j["files"].size(), 4u);
  for (const char* name : {"multipliers", "chart"}) {
    EXPECT_EQ(head(dir / "plots" / (std::string(name) + ".png"), 8), std::string("\x89PNG\r\n\x1a\n", 8)) << name;
    EXPECT_NE(head(dir / "plots" / (std::string(name) + ".svg"), 400).find("<svg"), std::string::npos) << name;
    EXPECT_TRUE(fs::exists(dir / "plots" / (std::string(name) + ".gp"))) << name;
  }
  for (const auto& entry : fs::directory_iterator(dir / "plots"))
    EXPECT_NE(entry.path().filename().string()[0], '.') << "temporary left behind: " << entry.path();
}

TEST(PlotCli, BadInputPaths) {
  CliResult missing = run({"plot", "/nonexistent/results"});
  EXPECT_EQ(missing.status, 2);
  EXPECT_NE(missing.err.find("not a directory"), std::string::npos) << missing.err;

  CliResult none = run({"plot"});
  EXPECT_EQ(none.status, 2);
  EXPECT_NE(none.err.find("needs a results directory"), std::string::npos) << none.err;

  const fs::path empty = fresh_dir("empty");
  CliResult nothing = run({"plot", empty.string()});
  EXPECT_EQ(nothing.status, 2);
  EXPECT_NE(nothing.err.find("nothing to plot"), std::string::npos) << nothing.err;

  CliResult width = run({"plot", empty.string(), "--set", "plot_width=5"});
  EXPECT_EQ(width.status, 2);
  EXPECT_NE(width.err.find("`plot_width = 5`"), std::string::npos) << width.err;

  const fs::path dir = fresh_dir("nognuplot");
  std::ofstream(dir / "floquet.json") << R"({"model": "linear", "N": 4, "solver": "dense",
      "multipliers": [{"re": 0.5, "im": 0, "abs": 0.5}]})";
  CliResult no_gnuplot = run({"plot", dir.string(), "--set", "plot_gnuplot=/nonexistent/gnuplot"});
  EXPECT_EQ(no_gnuplot.status, 2);
  EXPECT_NE(no_gnuplot.err.find("cannot run gnuplot"), std::string::npos) << no_gnuplot.err;
  EXPECT_FALSE(fs::exists(dir / "plots" / "multipliers.png"));

  std::ofstream(dir / "floquet.json") << "{ not json";
  CliResult broken = run({"plot", dir.string()});
  EXPECT_EQ(broken.status, 2);
  EXPECT_NE(broken.err.find("not JSON"), std::string::npos) << broken.err;
}

TEST(PlotCli, RendersSweepSimulateConvergeAndBenchFiles) {
  // Synthetic inputs in the formats the sweep, simulate, converge and bench commands write
  // (docs/formats.md): every figure is produced as a PNG and an SVG.
  const fs::path dir = fresh_dir("formats");
  std::ofstream(dir / "exponents.csv") << "parameter,lambda1,lambda2,se1,se2,lambda1_per_time,lambda2_per_time,seconds\n"
                                          "0,0.1,-0.2,0.01,0.01,0.0127,-0.025,1\n0.5,-0.1,-0.3,0.01,0.02,-0.0127,-0.038,1\n";
  std::ofstream(dir / "section.csv") << "parameter,x\n0,0.1\n0,0.2\n0.5,-0.05\n";
  std::ofstream(dir / "sweep.json") << R"({"sweep_key": "k"})";
  std::ofstream(dir / "trajectory.csv") << "t,x,v\n0,0,1\n0.1,0.1,0.99\n0.2,0.2,0.96\n0.3,0.29,0.9\n";
  std::ofstream(dir / "poincare.csv") << "t,x,v\n0,0,1\n";
  std::ofstream(dir / "impacts.csv") << "t,count\n0,0\n5,1\n9,2\n";
  std::ofstream(dir / "converge.json") << R"({"reference": "exact", "by_events": [
      {"events": "on", "rows": [{"N": 100, "error": 1e-3, "seconds": 0.1}, {"N": 200, "error": 2.5e-4, "seconds": 0.2}]},
      {"events": "off", "rows": [{"N": 100, "error": 1e-2, "seconds": 0.1}, {"N": 200, "error": 5e-3, "seconds": 0.2}]}]})";
  std::ofstream(dir / "bench.json") << R"({"rows": [{"N": 100, "solver": "spectra", "seconds": 0.01, "error": 1e-3},
      {"N": 200, "solver": "spectra", "seconds": 0.02, "error": 2e-4}]})";
  CliResult p = run({"plot", dir.string(), "--set", "plot_width=300", "--set", "plot_height=200"});
  ASSERT_EQ(p.status, 0) << p.err;
  for (const char* name : {"exponents", "bifurcation", "phase", "impacts", "convergence", "speed_error"}) {
    EXPECT_EQ(head(dir / "plots" / (std::string(name) + ".png"), 8), std::string("\x89PNG\r\n\x1a\n", 8)) << name;
    EXPECT_NE(head(dir / "plots" / (std::string(name) + ".svg"), 400).find("<svg"), std::string::npos) << name;
  }
}
