// `delayspec boundary` (boundary.hpp, command_boundary.cpp) against what it did not produce:
// - the linear DDE x' = a x + b x(t - 1), T = 1: its Neimark-Sacker curve in (a, b) is the exact
//   Hopf curve a = w cot w, b = -w / sin w (w in (0, pi), the multiplier's angle), computed here
//   by bisection; each point's extrapolation (N = 50 .. 400) is within its error estimate of it;
//   the finest level is off by O(h^2);
// - the delayed Mathieu equation: the curves pass through the points that one-parameter
//   `continue` locates at fixed delta, to 1e-9 at equal N; a curve that leaves the y range ends
//   there with exit 0;
// - a circle, u^2 + v^2 = 1 (an equations model whose fold is exactly there at any N): followed
//   through its turning point in x;
// - the impact oscillator's grazing curve in (k, a) at tau = T / 2: below the obstacle the orbit
//   is the linear response x = |X| sin(w t + phi), |X| = a w^2 / |D(i w)|, D(s) = s^2 + (2 zeta +
//   k) s + 1 - k s e^{-s tau}, so it grazes x = e exactly where a = e |D(i w)| / w^2;
// - bad input (exit 2) and no bifurcation at the start (exit 3 with what was found).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <complex>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <sstream>

#include <nlohmann/json.hpp>

#include "cli_test_support.hpp"
#include "delayspec/errors.hpp"
#include "delayspec_test_paths.hpp"

namespace {

using delayspec::testing::CliResult;
using delayspec::testing::contains;
using delayspec::testing::run;
using delayspec::testing::with_sets;
using std::numbers::pi;

// The Hopf curve of x' = a x + b x(t - 1): w cot w = a (decreasing in w on (0, pi)), by bisection.
double hopf_frequency(double a) {
  double lo = 1e-12, hi = pi - 1e-12;
  for (int i = 0; i < 200; ++i) {
    const double mid = 0.5 * (lo + hi);
    (mid / std::tan(mid) > a ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

// b on that curve at a: -w / sin w.
double hopf_curve_b(double a) {
  const double w = hopf_frequency(a);
  return -w / std::sin(w);
}

// How far below or above the Hopf curve a point (a, b) may be and still lie within its bars
// (bar_a, bar_b) of it: bar_b plus |b'(a)| bar_a (b' by central differences over 2e-6).
double hopf_allowed_miss(double a, double bar_a, double bar_b) {
  const double slope = (hopf_curve_b(a + 1e-6) - hopf_curve_b(a - 1e-6)) / 2e-6;
  return bar_b + std::abs(slope) * bar_a;
}

// The forcing amplitude a at which the impact model's free-flight orbit touches x = e, at tau = T / 2
// (e^{-i w tau} = -1: the feedback k (v(t - tau) - v(t)) is -2 k v on the forced response):
// a = e |1 - w^2 + i w (2 zeta + 2 k)| / w^2.
double impact_grazing_amplitude(double e, double w, double zeta, double k) {
  return e * std::abs(std::complex<double>(1 - w * w, w * (2 * zeta + 2 * k))) / (w * w);
}

nlohmann::json boundary_json(std::vector<std::string> sets) {
  const CliResult r = run(with_sets({"boundary", "--json"}, std::move(sets)));
  EXPECT_EQ(r.status, 0) << r.err;
  return r.status == 0 ? nlohmann::json::parse(r.out) : nlohmann::json();
}

TEST(BoundaryCli, TheLinearNeimarkSackerCurveIsTheExactHopfCurve) {
  const auto j = boundary_json({"model=linear", "tau=1", "period=1", "boundary_x=a", "boundary_y=b",
                                "boundary_x_from=-1", "boundary_x_to=0.5", "boundary_y_from=-0.5", "boundary_y_to=-4",
                                "boundary_type=neimark-sacker", "N=400", "boundary_Ns=50,100,200,400"});
  ASSERT_FALSE(j.is_null());
  const auto& curve = j["curves"][0];
  EXPECT_EQ(curve["type"], "neimark-sacker");
  EXPECT_EQ(curve["end"], "to");
  const auto& points = curve["points"];
  ASSERT_GE(points.size(), 10u);
  EXPECT_EQ(points.front()["x"].get<double>(), -1.0);  // starts and lands exactly on the range's ends
  EXPECT_EQ(points.back()["x"].get<double>(), 0.5);
  for (const auto& p : points) {
    const double a = p["x"], w = hopf_frequency(a), b = hopf_curve_b(a);
    const double finest = p["y"];
    // The discrete curve at N = 400 is off by O(h^2): 1.1e-5 at N = 200 measured, so < 1e-5 here.
    EXPECT_LT(std::abs(finest - b), 1e-5) << a;
    EXPECT_GT(std::abs(finest - b), 1e-8) << a << ": the discretisation error is not zero";
    // The extrapolated point is within its error estimates of the exact curve (its vertical miss
    // |y - b(x)| at most the y bar plus |b'| times the x bar), and the estimates are small (four
    // levels: the h^4 column checked, so the bar is the h^6 column's correction).
    const double xe = p["x_extrapolated"], ye = p["y_extrapolated"];
    const double bar_x = p["x_error_estimate"], bar_y = p["error_estimate"];
    EXPECT_LE(std::abs(ye - hopf_curve_b(xe)), hopf_allowed_miss(xe, bar_x, bar_y) + 1e-12) << a;
    EXPECT_LT(std::max(bar_x, bar_y), 1e-7) << a;
    // The multiplier's angle is the Hopf frequency times T = 1, to O(h^2).
    EXPECT_NEAR(p["angle"].get<double>(), w, 1e-4) << a;
    // Order 2 between the two finest levels: the vertical miss of each level's point quarters.
    const auto miss = [&](int level) {
      const double x = p["by_N"][level]["x"], y = p["by_N"][level]["y"];
      return std::abs(y - hopf_curve_b(x));
    };
    EXPECT_NEAR(std::log2(miss(2) / miss(3)), 2.0, 0.05) << a;
  }
}

// The printed table gives the extrapolated point's both coordinates, each with its bar: the point
// moves along the curve's normal, so its b belongs to its own a, not to the finest N's. Each row
// against the exact Hopf curve, as the JSON above: the vertical miss |b - b(a)| within the b bar
// plus |b'| times the a bar, the bars printed to two significant digits (up to 5 % low: 1.049
// prints as 1.0) and the values to twelve (1e-11 at |a|, |b| < 5).
// Printed beside the finest N's a (the table before 2026-11-28), b misses by |b'| times the
// normal's shift, 3e-7 here against bars of 7.5e-10.
TEST(BoundaryCli, TheTableGivesTheExtrapolatedPointsBothCoordinates) {
  const CliResult r = run(with_sets({"boundary"}, {"model=linear", "tau=1", "period=1", "boundary_x=a", "boundary_y=b",
                                                   "boundary_x_from=-1", "boundary_x_to=0.5", "boundary_y_from=-0.5",
                                                   "boundary_y_to=-4", "boundary_type=neimark-sacker", "N=400",
                                                   "boundary_Ns=50,100,200,400"}));
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(contains(r.out, "extrapolated (N -> infinity)")) << r.out;
  std::istringstream lines(r.out);
  int rows = 0;
  double largest_shift = 0;
  for (std::string line; std::getline(lines, line);) {
    std::istringstream row(line);
    double a, b, xe, bar_x, ye, bar_y, angle;
    if (!(row >> a >> b >> xe >> bar_x >> ye >> bar_y >> angle)) continue;
    ++rows;
    largest_shift = std::max(largest_shift, std::abs(xe - a));
    EXPECT_LE(std::abs(ye - hopf_curve_b(xe)), 1.05 * hopf_allowed_miss(xe, bar_x, bar_y) + 1e-11) << line;
  }
  EXPECT_GE(rows, 10) << r.out;
  EXPECT_GT(largest_shift, 1e-7) << "the normal's shift in a, which the test is to see: " << r.out;
}

// The Mathieu curves against `continue` in b at fixed delta (the same discrete problem, N = 200).
TEST(BoundaryCli, TheMathieuCurvesPassThroughThePointsContinueLocates) {
  const std::vector<std::string> mathieu = {"model=mathieu", "kappa=0.1", "eps=1", "N=200"};
  for (const char* type : {"neimark-sacker", "period-doubling"}) {
    std::vector<std::string> sets = mathieu;
    for (const char* s : {"boundary_x=delta", "boundary_y=b", "boundary_x_from=2", "boundary_x_to=2.6",
                          "boundary_y_from=-1.5", "boundary_y_to=1.5"})
      sets.push_back(s);
    sets.push_back(std::string("boundary_type=") + type);
    const auto j = boundary_json(sets);
    ASSERT_FALSE(j.is_null());
    const auto& points = j["curves"][0]["points"];
    ASSERT_GE(points.size(), 3u) << type;
    if (std::string(type) == "period-doubling") {  // it leaves b >= -1.5 before delta = 2.6
      EXPECT_EQ(j["curves"][0]["end"], "y_range");
      EXPECT_TRUE(contains(j["curves"][0]["note"].get<std::string>(), "left the y range")) << j["curves"][0]["note"];
      EXPECT_NEAR(points.back()["y"].get<double>(), -1.5, 1e-12);
    }
    for (size_t k : {size_t{0}, points.size() / 2, points.size() - 1}) {
      const double delta = points[k]["x"], b = points[k]["y"];
      std::vector<std::string> c = mathieu;
      for (const std::string& s : std::vector<std::string>{"continue_key=b", "continue_from=" + std::to_string(b - 0.05),
                                                           "continue_to=" + std::to_string(b + 0.05),
                                                           "continue_tolerance=1e-12"})
        c.push_back(s);
      c.push_back("delta=" + delayspec::format_number(delta));
      const CliResult r = run(with_sets({"continue", "--json"}, c));
      ASSERT_EQ(r.status, 0) << r.err;
      double nearest = INFINITY;
      const nlohmann::json located = nlohmann::json::parse(r.out);
      for (const auto& bif : located["bifurcations"]) {
        const double at = bif["by_N"].back()["parameter"];  // (one level: N = 200)
        if (bif["type"] == type && std::abs(at - b) < std::abs(nearest - b)) nearest = at;
      }
      // Both locate the same zero of the same test function at the same N, each to ~1e-10.
      EXPECT_NEAR(nearest, b, 1e-9) << type << " at delta = " << delta;
    }
  }
}

// u^2 + v^2 = 1 as a fold: x' = (u^2 + v^2 - 1) x + (x(t - 1) - x) / 1000 keeps a constant history
// constant (multiplier 1) exactly when u^2 + v^2 = 1, at any N. From u = 0.6 the curve starts at
// v = -0.8 (the first fold in v from -1.2), goes right to the turning point u = 1 and comes back
// to u = 0.6 on the upper half.
TEST(BoundaryCli, ACurveIsFollowedThroughItsTurningPoint) {
  const std::filesystem::path dir = delayspec::testing::scratch_path("boundary");
  std::filesystem::create_directories(dir);
  const std::string scene = (dir / "circle.toml").string();
  std::ofstream(scene) << "model = \"equations\"\n[equations]\nstate = [\"x\"]\nparameters = { u = 0.6, v = 0 }\n"
                          "period = \"1\"\ndelay = \"1\"\nrhs = [\"(u^2 + v^2 - 1)*x + (x_tau - x)/1000\"]\n";
  const CliResult r = run(with_sets({"boundary", scene, "--json"},
                                    {"N=20", "solver=dense", "nev=2", "boundary_x=u", "boundary_y=v",
                                     "boundary_x_from=0.6", "boundary_x_to=1.5", "boundary_y_from=-1.2",
                                     "boundary_y_to=1.2", "boundary_type=fold",
                                     std::string("model_cache=") + DELAYSPEC_TEST_MODEL_CACHE}));
  ASSERT_EQ(r.status, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  const auto& points = j["curves"][0]["points"];
  EXPECT_EQ(j["curves"][0]["end"], "from");
  double x_max = 0;
  for (const auto& p : points) {
    const double u = p["x"], v = p["y"];
    x_max = std::max(x_max, u);
    // Each point to the tolerance 1e-10 of the scaled plane (ranges 0.9 and 2.4) and rounding.
    EXPECT_NEAR(u * u + v * v, 1.0, 1e-8) << u << " " << v;
  }
  EXPECT_GT(x_max, 0.999);  // through the turning point u = 1
  EXPECT_NEAR(points.front()["y"].get<double>(), -0.8, 1e-9);
  EXPECT_EQ(points.back()["x"].get<double>(), 0.6);
  EXPECT_NEAR(points.back()["y"].get<double>(), 0.8, 1e-9);
  std::filesystem::remove_all(dir);
}

// With T = 2 the same curve's multiplier e^{i w T} passes -1 where w = pi / 2: a = 0, b = -pi / 2,
// a 1:2 resonance, which the curve passes and reports. Its location is the vertex of |arg mu|
// interpolated between curve points (steps moving the angle by <= 0.02 there; measured 4e-5),
// plus the discretisation's O(h^2) (5e-5 at N = 400): 1e-3.
TEST(BoundaryCli, ANeimarkSackerCurveReportsTheStrongResonanceItPasses) {
  const auto j = boundary_json({"model=linear", "tau=1", "period=2", "boundary_x=a", "boundary_y=b",
                                "boundary_x_from=-1", "boundary_x_to=0.5", "boundary_y_from=-0.5", "boundary_y_to=-4",
                                "boundary_type=neimark-sacker", "N=400"});
  ASSERT_FALSE(j.is_null());
  const auto& codim2 = j["curves"][0]["codim2"];
  ASSERT_EQ(codim2.size(), 1u) << codim2;
  EXPECT_EQ(codim2[0]["kind"], "1:2 resonance");
  EXPECT_NEAR(codim2[0]["x"].get<double>(), 0.0, 1e-3);
  EXPECT_NEAR(codim2[0]["y"].get<double>(), -pi / 2, 1e-3);
  EXPECT_EQ(j["curves"][0]["end"], "to");
}

// boundary_starts = scan: a start at each of the scanned speeds, each curve followed once, both
// ways from its start. Milling at a/D = 0.05 between 9000 and 13000 rpm holds the right side of a
// Neimark-Sacker lobe, a period-doubling lobe and another Neimark-Sacker lobe (the chart's
// boundary, docs/milling.md); every curve passes through the depths `continue` locates at its
// speeds (the same N), and the orbit is stable below them.
// With boundary_Ns the starts are searched at the coarsest N and moved to the finest
// (command_boundary.cpp's first_start_at): the same curves, through the same points. On one
// thread, two, or all cores (the default): the same result.
TEST(BoundaryCli, AScanFollowsEveryLobeOnceThroughThePointsContinueLocates) {
  const std::vector<std::string> milling = {"model=milling", "radial_immersion=0.05", "N=100"};
  for (const char* levels : {"boundary_Ns=100", "boundary_Ns=50,100"}) {
    SCOPED_TRACE(levels);
    std::vector<std::string> sets = milling;
    for (const char* s :
         {"boundary_x=spindle_rpm", "boundary_y=depth", "boundary_x_from=9000", "boundary_x_to=13000",
          "boundary_y_from=1e-5", "boundary_y_to=5e-3", "boundary_starts=scan", "boundary_scan_points=8", levels})
      sets.push_back(s);
    const auto j = boundary_json(sets);
    ASSERT_FALSE(j.is_null());
    // The error bars on one thread and on two: the same curves to the bit (each block of points
    // searched alike whatever the thread count)
    for (const char* threads : {"threads=1", "threads=2"}) {
      sets.push_back(threads);
      EXPECT_EQ(boundary_json(sets)["curves"], j["curves"]) << threads;
      sets.pop_back();
    }
    EXPECT_EQ(j["stable_side"], "y_from");
    std::vector<std::string> types;
    for (const auto& curve : j["curves"]) types.push_back(curve["type"]);
    EXPECT_EQ(types, (std::vector<std::string>{"neimark-sacker", "period-doubling", "neimark-sacker"}));
    for (const auto& curve : j["curves"]) {
      const auto& points = curve["points"];
      for (size_t k : {size_t{0}, points.size() / 2, points.size() - 1}) {
        const double rpm = points[k]["x"], depth = points[k]["y"];
        if (depth >= 5e-3 * (1 - 1e-9)) continue;  // (where it left the range: no crossing below 5 mm there)
        std::vector<std::string> c = milling;
        for (const std::string& s : std::vector<std::string>{"continue_key=depth", "continue_from=1e-5",
                                                             "continue_to=5e-3", "continue_tolerance=1e-16"})
          c.push_back(s);
        c.push_back("spindle_rpm=" + delayspec::format_number(rpm));
        const CliResult r = run(with_sets({"continue", "--json"}, c));
        ASSERT_EQ(r.status, 0) << r.err;
        const nlohmann::json located = nlohmann::json::parse(r.out);
        double nearest = INFINITY;
        for (const auto& bif : located["bifurcations"]) {
          const double at = bif["by_N"].back()["parameter"];
          if (bif["type"] == curve["type"] && std::abs(at - depth) < std::abs(nearest - depth)) nearest = at;
        }
        // Both to ~1e-10 of the 5 mm range: 1e-9 of it.
        EXPECT_NEAR(nearest, depth, 5e-12) << curve["type"] << " at " << rpm << " rpm";
      }
    }
  }
  // The linear DDE's one Neimark-Sacker curve, scanned at ten values of a: found once.
  const auto linear = boundary_json({"model=linear", "tau=1", "period=1", "boundary_x=a", "boundary_y=b",
                                     "boundary_x_from=-1", "boundary_x_to=0.5", "boundary_y_from=-0.5",
                                     "boundary_y_to=-4", "N=50", "boundary_starts=scan", "boundary_scan_points=10"});
  ASSERT_FALSE(linear.is_null());
  EXPECT_EQ(linear["curves"].size(), 1u);
}

// The grazing curve against the exact one. e = 1.5 (not the paper's 1.26) and a from 0.5: the
// orbit grazes at a = 0.833 for k = 0; it also doubles its period 8e-4 above, which the curve
// (followed on the orbit of the free-flight field, step_options.hpp's fixed_region) never meets.
TEST(BoundaryCli, TheImpactGrazingCurveIsTheExactLinearResponseCurve) {
  const auto exact_a = [](double k) { return impact_grazing_amplitude(1.5, 0.802, 0.01, k); };
  const auto j = boundary_json({"model=impact", "tau_over_T=0.5", "e=1.5", "boundary_x=k", "boundary_y=a",
                                "boundary_x_from=0", "boundary_x_to=0.2", "boundary_y_from=0.5", "boundary_y_to=1.5",
                                "boundary_type=grazing", "boundary_Ns=50,100,200,400"});
  ASSERT_FALSE(j.is_null());
  const auto& curve = j["curves"][0];
  EXPECT_EQ(curve["type"], "grazing");
  EXPECT_EQ(curve["end"], "to");
  EXPECT_TRUE(j["stable_side"].is_null());  // a grazing curve bounds no stability region
  const auto& points = curve["points"];
  ASSERT_GE(points.size(), 10u);
  EXPECT_EQ(points.back()["x"].get<double>(), 0.2);
  size_t extrapolated = 0;
  for (const auto& p : points) {
    const double k = p["x"], a = p["y"];
    EXPECT_TRUE(p["angle"].is_null());
    // N = 400: O(h^2) off, 1.5e-5 at most measured; order 2 between the two finest levels
    EXPECT_LT(std::abs(a - exact_a(k)), 3e-5) << k;
    EXPECT_GT(std::abs(a - exact_a(k)), 1e-7) << k << ": the discretisation error is not zero";
    const auto miss = [&](int level) {
      const double x = p["by_N"][level]["x"], y = p["by_N"][level]["y"];
      return std::abs(y - exact_a(x));
    };
    EXPECT_NEAR(std::log2(miss(2) / miss(3)), 2.0, 0.05) << k;
    // Extrapolated: within its bars of the exact curve (3.5e-10 at most measured, at most 0.4 of
    // its bar; bars never below twice the location tolerance, 2e-10 here: boundary.hpp). A point
    // whose h^4 column falls to the location noise gets no estimate (richardson.hpp's plateau
    // rule: null, never a claim; none of 19 measured, 1 of 37 with the chord corrector's steps).
    if (p["y_extrapolated"].is_null()) continue;
    ++extrapolated;
    const double xe = p["x_extrapolated"], ye = p["y_extrapolated"];
    const double slope = (exact_a(xe + 1e-6) - exact_a(xe - 1e-6)) / 2e-6;
    EXPECT_LE(std::abs(ye - exact_a(xe)), p["error_estimate"].get<double>() +
                                              std::abs(slope) * p["x_error_estimate"].get<double>() + 1e-12)
        << k;
    EXPECT_LT(p["error_estimate"].get<double>(), 1e-7) << k;
  }
  EXPECT_GE(extrapolated, points.size() * 9 / 10);
}

// Where the grazing curve above meets a stability curve: the curve follows the orbit of the
// free-flight field, x'' + (2 zeta + k) x' + x = k x'(t - tau) + forcing, whose multipliers do not
// depend on a or e; its characteristic equation lambda^2 + (2 zeta + k) lambda + 1 = k lambda
// e^{-lambda tau} has roots i w0 (a Neimark-Sacker crossing) where 2 zeta + k (1 - cos w0 tau) = 0
// and 1 - w0^2 = k w0 sin w0 tau, that is 1 - w0^2 + 2 zeta w0 cot(w0 tau / 2) = 0 and
// k* = -2 zeta / (1 - cos w0 tau) (w0 = 0.99601, k* = -0.0115953 at tau = T / 2). The grazing
// orbit is stable for k > k*: the codim-2 point lies at k*, up to the discretisation's O(h^2).
TEST(BoundaryCli, TheGrazingCurveMeetsTheFreeFlightStabilityCurveAtTheExactGain) {
  const double zeta = 0.01, w = 0.802, tau = std::numbers::pi / w;
  const auto f = [&](double w0) { return 1 - w0 * w0 + 2 * zeta * w0 / std::tan(w0 * tau / 2); };
  double lo = 0.9, hi = 1.05;  // f(0.9) > 0 > f(1.05), one root between
  ASSERT_GT(f(lo), 0);
  ASSERT_LT(f(hi), 0);
  for (int i = 0; i < 200 && hi - lo > 1e-15; ++i) (f((lo + hi) / 2) > 0 ? lo : hi) = (lo + hi) / 2;
  const double w0 = (lo + hi) / 2, k_star = -2 * zeta / (1 - std::cos(w0 * tau));
  const double angle = std::abs(std::arg(std::polar(1.0, w0 * 2 * std::numbers::pi / w)));
  const auto meeting = [&](int N) {
    const auto j = boundary_json({"model=impact", "tau_over_T=0.5", "e=1.5", "boundary_x=k", "boundary_y=a",
                                  "boundary_x_from=0.02", "boundary_x_to=-0.03", "boundary_y_from=0.5",
                                  "boundary_y_to=1.5", "boundary_type=grazing", "N=" + std::to_string(N),
                                  "boundary_Ns=" + std::to_string(N)});
    EXPECT_FALSE(j.is_null());
    const auto& curve = j["curves"][0];
    EXPECT_EQ(curve["end"], "to");  // the meeting is passed
    EXPECT_EQ(curve["codim2"].size(), 1u) << curve["codim2"];
    return curve["codim2"].at(0);
  };
  const auto coarse = meeting(100), fine = meeting(200);
  EXPECT_EQ(fine["kind"], "grazing meets neimark-sacker");
  // O(h^2) in the gain and in the angle (measured: k off by 2.2e-6 and 5.6e-7, the angle by 9.7e-4
  // and 2.4e-4, at N = 100 and 200; located to 5e-12 in k, far below).
  const auto order = [&](const char* field, double exact) {
    return std::log2(std::abs(coarse[field].get<double>() - exact) / std::abs(fine[field].get<double>() - exact));
  };
  EXPECT_NEAR(order("x", k_star), 2.0, 0.2) << coarse << " " << fine;
  EXPECT_NEAR(order("angle", angle), 2.0, 0.2) << coarse << " " << fine;
  EXPECT_LT(std::abs(fine["x"].get<double>() - k_star), 1e-4 * std::abs(k_star)) << fine;
  // On the grazing curve: a(k) = e |1 - w^2 + i w (2 zeta + 2 k)| / w^2, to the curve's O(h^2)
  // (1.5e-5 at N = 400 in the test above, so about 6e-5 at N = 200)
  EXPECT_NEAR(fine["y"].get<double>(), impact_grazing_amplitude(1.5, w, zeta, fine["x"].get<double>()), 1e-4);
}

// A period-doubling curve whose follower stops is a failure unless it stops at a 1:2 resonance,
// where a second multiplier meets the critical one at -1. (Its angle is pi all along, which alone
// made every stop a "1:2 resonance", exit 0.) The impact orbit's period-doubling curve near its
// grazing, at N = 100, stops at k = 0.0037; floquet there, run apart, has its second multiplier
// far from -1 (-0.82). The milling lobes' flip curves, which do end at 1:2 points (two real
// multipliers meeting at -1), keep their resonances: the scan test above and docs/milling.md.
TEST(BoundaryCli, APeriodDoublingCurveThatStopsAwayFromA12ResonanceIsAFailure) {
  const std::vector<std::string> impact = {"--set", "model=impact", "--set", "tau_over_T=0.5", "--set", "e=1.5",
                                           "--set", "N=100"};
  std::vector<std::string> args = {"boundary", "--json"};
  args.insert(args.end(), impact.begin(), impact.end());
  const CliResult r = run(with_sets(args, {"boundary_x=k", "boundary_y=a", "boundary_x_from=0", "boundary_x_to=0.2",
                                           "boundary_y_from=0.5", "boundary_y_to=1.5",
                                           "boundary_type=period-doubling", "boundary_Ns=100"}));
  ASSERT_EQ(r.status, 3) << r.out << r.err;
  EXPECT_FALSE(contains(r.err, "resonance")) << r.err;
  // "... at x = K, y = A: no period-doubling candidate ...": the point as printed (every digit: the
  // multipliers there change fast, two real ones turning complex within 1e-6 in a)
  const size_t x_at = r.err.find("at x = "), y_at = r.err.find(", y = ", x_at);
  ASSERT_TRUE(x_at != std::string::npos && y_at != std::string::npos) << r.err;
  const std::string k = r.err.substr(x_at + 7, y_at - x_at - 7);
  const std::string a = r.err.substr(y_at + 6, r.err.find(':', y_at) - y_at - 6);
  EXPECT_TRUE(contains(r.err, "no period-doubling candidate")) << r.err;
  args = {"floquet", "--json"};
  args.insert(args.end(), impact.begin(), impact.end());
  // the curve's own discrete problem: contacts inside steps (boundary does not align them)
  const CliResult f = run(with_sets(args, {"k=" + k, "a=" + a, "nev=4", "grid=uniform"}));
  ASSERT_EQ(f.status, 0) << f.err;
  const auto mu = nlohmann::json::parse(f.out)["multipliers"];
  // the two nearest -1 (one of them the critical one, within 0.05 of it: the curve's last point)
  std::vector<double> gaps;
  for (const auto& m : mu) gaps.push_back(std::abs(std::complex<double>(m["re"], m["im"]) + 1.0));
  std::sort(gaps.begin(), gaps.end());
  ASSERT_GE(gaps.size(), 2u);
  EXPECT_LT(gaps[0], 0.05);
  EXPECT_GT(gaps[1], 0.1);
}

TEST(BoundaryCli, BadInputAndNoBifurcationAtTheStart) {
  const std::vector<std::string> linear = {"model=linear", "tau=1", "period=1", "boundary_x_from=-1",
                                           "boundary_x_to=0.5", "boundary_y_from=-0.5", "boundary_y_to=-4"};
  const auto with = [&](std::vector<std::string> extra) {
    std::vector<std::string> s = linear;
    s.insert(s.end(), extra.begin(), extra.end());
    return run(with_sets({"boundary"}, s));
  };
  CliResult r = with({"boundary_x=a", "boundary_y=a"});
  EXPECT_EQ(r.status, 2);
  EXPECT_TRUE(contains(r.err, "`boundary_x = boundary_y = a`")) << r.err;
  r = with({"boundary_x=N", "boundary_y=b"});
  EXPECT_EQ(r.status, 2);
  EXPECT_TRUE(contains(r.err, "`boundary_x = N`: not a model parameter")) << r.err;
  r = with({"boundary_x=a", "boundary_y=b", "boundary_y_to=-0.5"});
  EXPECT_EQ(r.status, 2);
  EXPECT_TRUE(contains(r.err, "an empty range")) << r.err;
  r = with({"boundary_x=a", "boundary_y=b", "boundary_chord_error=0"});
  EXPECT_EQ(r.status, 2);
  EXPECT_TRUE(contains(r.err, "`boundary_chord_error = 0`: must be > 0")) << r.err;
  r = with({"boundary_x=a", "boundary_y=b", "boundary_type=grazing"});  // the linear model does not switch
  EXPECT_EQ(r.status, 2);
  EXPECT_TRUE(contains(r.err, "`boundary_type = grazing`: model linear has no switching surface")) << r.err;
  // b from -0.5 to -4 at a = -1 crosses the Hopf curve (NS) only: no period doubling there.
  r = with({"boundary_x=a", "boundary_y=b", "boundary_type=period-doubling"});
  EXPECT_EQ(r.status, 3);
  EXPECT_TRUE(contains(r.err, "no period-doubling")) << r.err;
  EXPECT_TRUE(contains(r.err, "found: a = -1: neimark-sacker at ")) << r.err;
}

}  // namespace

// The lobe diagram of milling_lobes_curves.toml with 15 starts instead of 40: the lobe started at
// 6428.6 rpm, followed toward 5000 rpm, had its first corrector run to a point four y ranges away
// (a point of another part of the zero set), accepted, and the curve ended in a failure there
// (exit 3). A corrected point farther from its predictor than the step, or outside the ranges,
// is now a failed step: every curve stays in the ranges and ends at an edge or a resonance.
TEST(BoundaryCli, NoCurvePointLeavesTheRangesOrJumpsAway) {
  const std::string scene = std::string(DELAYSPEC_SOURCE_DIR) + "/data/scenes/milling_lobes_curves.toml";
  const CliResult r = run({"boundary", scene, "--json", "--set", "boundary_scan_points=15"});
  ASSERT_EQ(r.status, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  for (const auto& curve : j["curves"]) {
    EXPECT_NE(curve["end"], "failure") << curve["note"];
    for (const auto& p : curve["points"]) {
      EXPECT_GE(p["x"].get<double>(), 5000.0);
      EXPECT_LE(p["x"].get<double>(), 25000.0);
      EXPECT_GE(p["y"].get<double>(), 1e-5);
      EXPECT_LE(p["y"].get<double>(), 5e-3);
    }
  }
}

namespace {

// The bifurcation of `type` nearest y that `continue` in depth locates at the spindle speed x,
// over (1 -+ spread) y, extrapolated from the levels Ns (the finest the last) with its error
// estimate: an extrapolation along another line (fixed speed) from other levels than a boundary
// curve's along its normal. Null where continue has none with an estimate.
nlohmann::json continue_limit(const std::vector<std::string>& model, const nlohmann::json& type, double x, double y,
                              double spread, const std::vector<int>& Ns) {
  std::string levels;
  for (int N : Ns) {
    if (!levels.empty()) levels += ",";
    levels += std::to_string(N);
  }
  std::vector<std::string> c = model;
  for (const std::string& s : {std::string("continue_key=depth"), "continue_from=" + delayspec::format_number((1 - spread) * y),
                               "continue_to=" + delayspec::format_number((1 + spread) * y), "N=" + std::to_string(Ns.back()),
                               "continue_Ns=" + levels, std::string("continue_tolerance=1e-16"),
                               "spindle_rpm=" + delayspec::format_number(x)})
    c.push_back(s);
  const CliResult r = run(with_sets({"continue", "--json"}, c));
  EXPECT_EQ(r.status, 0) << r.err;
  if (r.status != 0) return nullptr;
  const nlohmann::json located = nlohmann::json::parse(r.out);
  nlohmann::json nearest;
  for (const auto& b : located["bifurcations"])
    if (b["type"] == type && !b["error_estimate"].is_null() &&
        (nearest.is_null() || std::abs(b["extrapolated"].get<double>() - y) <
                                  std::abs(nearest["extrapolated"].get<double>() - y)))
      nearest = b;
  return nearest;
}

}  // namespace

// The lobes between 9000 and 13000 rpm at a/D = 0.05 (a Neimark-Sacker lobe's side, a flip lobe
// with its tip, another Neimark-Sacker lobe), each point extrapolated from N = 100, 200, 400, and
// where those levels do not show their order (the flip lobe's tip, narrower at N = 100 than the
// offsets between the levels) from 200, 400, 800 (boundary_refine). Every third extrapolated
// point is checked against `continue` in depth at its speed over N = 200 .. 1600, an
// extrapolation of its own along another line (fixed speed) from other levels: the two differ by
// at most the curve's depth bar, plus its speed bar times the curve's slope there, plus
// continue's bar; and the extrapolation gains: its median miss is under a hundredth of the N =
// 400 level's at the same speed (measured: 3.8e-9 m against 2.7e-6 m, the largest miss 0.22 of
// its bar). (From N = 50 .. 400 the bars come from the h^4 column, and 8 of 85 points missed by
// up to 1.7 times theirs, on one lobe's side: the scene keeps three levels. Why, measured at
// 11500 rpm over N = 50 .. 1600: the h^4 column's differences (scaled offsets) are 8.7e-5,
// 5.5e-6 (ratio 16, the order 4 its check accepts from its one triple), then -1.8e-7 and
// -1.8e-9: N = 50, seven steps in the cut at a/D = 0.05, is not yet asymptotic, and the h^6
// step built on it overshoots.)
TEST(BoundaryCli, TheLobesExtrapolatedPointsAreWithinTheirBarsOfContinuesLimit) {
  const std::vector<std::string> milling = {"model=milling", "radial_immersion=0.05", "nev=4"};
  std::vector<std::string> sets = milling;
  for (const char* s : {"boundary_x=spindle_rpm", "boundary_y=depth", "boundary_x_from=9000", "boundary_x_to=13000",
                        "boundary_y_from=1e-5", "boundary_y_to=5e-3", "boundary_starts=scan", "boundary_scan_points=8",
                        "N=400", "boundary_Ns=100,200,400"})
    sets.push_back(s);
  const auto j = boundary_json(sets);
  ASSERT_FALSE(j.is_null());
  int refined = 0;
  std::vector<double> misses, finest_misses;
  for (const auto& curve : j["curves"]) {
    const auto& points = curve["points"];
    for (const auto& p : points)
      for (const auto& N : p["extrapolated_from"].is_null() ? nlohmann::json::array() : p["extrapolated_from"])
        refined += N == 800;
    for (size_t k = 1; k + 1 < points.size(); k += 3) {
      const auto& p = points[k];
      if (p["error_estimate"].is_null()) continue;
      const double x = p["x_extrapolated"], y = p["y_extrapolated"];
      const double slope = (points[k + 1]["y"].get<double>() - points[k - 1]["y"].get<double>()) /
                           (points[k + 1]["x"].get<double>() - points[k - 1]["x"].get<double>());
      const nlohmann::json nearest = continue_limit(milling, curve["type"], x, y, 0.01, {200, 400, 800, 1600});
      if (nearest.is_null()) continue;  // (no estimate of continue's there: nothing to check against)
      const double limit = nearest["extrapolated"], bar = nearest["error_estimate"];
      const double allowed = p["error_estimate"].get<double>() + std::abs(slope) * p["x_error_estimate"].get<double>() + bar;
      EXPECT_LE(std::abs(limit - y), allowed) << curve["type"] << " at " << x << " rpm";
      misses.push_back(std::abs(limit - y));
      for (const auto& level : nearest["by_N"])
        if (level["N"] == 400) finest_misses.push_back(std::abs(limit - level["parameter"].get<double>()));
    }
  }
  ASSERT_GE(misses.size(), 20u);
  ASSERT_EQ(finest_misses.size(), misses.size());
  const auto median = [](std::vector<double> v) {
    std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
    return v[v.size() / 2];
  };
  EXPECT_LT(median(misses), 0.01 * median(finest_misses));
  EXPECT_GE(refined, 1) << "no point extrapolated from the refinement's level";
}

// The flip lobe near 5900 rpm at a/D = 0.05, from its tip to its end at the 1:2 resonance: where
// neither N = 100, 200, 400 nor 200, 400, 800 show their order (even N = 200 has no flip lobe on
// the normal near the tip; near the end the offsets grow), the second refinement extrapolates
// from 400, 800, 1600 (boundary_refine). Every such point is checked against `continue` in depth
// at its speed over N = 400 .. 3200, an extrapolation along another line from other levels: the
// two differ by at most the curve's bars (depth, and speed times the slope) plus continue's
// (measured: at most 0.03 of that, over 16 points).
TEST(BoundaryCli, AFlipLobesPointsFromTheSecondRefinementAreWithinTheirBarsOfContinuesLimit) {
  const std::vector<std::string> milling = {"model=milling", "radial_immersion=0.05", "nev=4"};
  std::vector<std::string> sets = milling;
  for (const char* s : {"boundary_x=spindle_rpm", "boundary_y=depth", "boundary_x_from=5700", "boundary_x_to=6100",
                        "boundary_y_from=1e-5", "boundary_y_to=5e-3", "boundary_type=period-doubling",
                        "boundary_starts=scan", "boundary_scan_points=6", "N=400", "boundary_Ns=100,200,400"})
    sets.push_back(s);
  const auto j = boundary_json(sets);
  ASSERT_FALSE(j.is_null());
  int checked = 0;
  for (const auto& curve : j["curves"]) {
    const auto& points = curve["points"];
    for (size_t k = 0; k < points.size(); ++k) {
      const auto& p = points[k];
      if (p["extrapolated_from"] != nlohmann::json({400, 800, 1600})) continue;
      ASSERT_FALSE(p["error_estimate"].is_null());
      const double x = p["x_extrapolated"], y = p["y_extrapolated"];
      const auto& a = points[k > 0 ? k - 1 : k];
      const auto& b = points[k + 1 < points.size() ? k + 1 : k];
      const double slope = (b["y"].get<double>() - a["y"].get<double>()) / (b["x"].get<double>() - a["x"].get<double>());
      const nlohmann::json nearest = continue_limit(milling, curve["type"], x, y, 0.03, {400, 800, 1600, 3200});
      if (nearest.is_null()) continue;  // (no estimate of continue's there: nothing to check against)
      const double limit = nearest["extrapolated"], bar = nearest["error_estimate"];
      const double allowed = p["error_estimate"].get<double>() + std::abs(slope) * p["x_error_estimate"].get<double>() + bar;
      EXPECT_LE(std::abs(limit - y), allowed) << "at " << x << " rpm";
      ++checked;
    }
  }
  EXPECT_GE(checked, 5) << "too few points extrapolated from the second refinement were checked";
}
