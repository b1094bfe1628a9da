#include "scene/output/branch_output.hpp"

#include <cmath>
#include <complex>
#include <sstream>

#include "delayspec/detail/bifurcation_locator.hpp"
#include "scene/output/output.hpp"

namespace delayspec::cli {

using nlohmann::json;

json measures_json(const OrbitMeasures& m) {
  json j;
  j["max"] = m.max;
  j["min"] = m.min;
  j["max_H"] = m.max_H;  // NaN (no switching) is written as null
  j["contact_time"] = m.contact_time;
  if (!std::isnan(m.max_H)) {  // switching models: the contact regions (detail/contact_peaks.hpp)
    j["contact_regions"] = m.contact_regions;
    j["second_max_H"] = m.second_max_H;  // -infinity (no second hump) is written as null
  }
  return j;
}

json points_json(const std::vector<ContinuationPoint>& points, const std::vector<StabilityVerdict>& verdicts) {
  json list = json::array();
  for (size_t i = 0; i < points.size(); ++i) {
    const ContinuationPoint& p = points[i];
    json pj;
    pj["parameter"] = p.parameter;
    pj["multipliers"] = multipliers_json(p.multipliers);
    pj["unstable"] = p.unstable;
    pj["stable"] = p.stable();
    if (!verdicts.empty()) pj["verdict"] = to_string(verdicts.at(i));
    pj["measures"] = measures_json(p.measures);
    pj["newton_iterations"] = p.newton_iterations;
    pj["step"] = p.step;
    if (std::isfinite(p.period)) {  // an orbit of unknown period
      pj["period"] = p.period;
      pj["trivial_multiplier"] = multipliers_json({p.trivial_multiplier})[0];
    }
    list.push_back(pj);
  }
  return list;
}

json bifurcations_json(const std::vector<BifurcationEstimate>& estimates, const ContinuationResult& branch) {
  json list = json::array();
  for (size_t b = 0; b < estimates.size(); ++b) {
    const BifurcationEstimate& e = estimates[b];
    const Bifurcation& finest = branch.bifurcations[b];
    json bj;
    bj["type"] = to_string(e.type);
    bj["parameter"] = e.parameter;
    bj["multipliers"] = multipliers_json(finest.multipliers);
    bj["angle"] = e.angle;  // NaN for grazing: null
    bj["measures"] = measures_json(finest.measures);
    if (std::isfinite(finest.period)) bj["period"] = finest.period;
    bj["by_N"] = json::array();
    for (size_t i = 0; i < e.Ns.size(); ++i) bj["by_N"].push_back({{"N", e.Ns[i]}, {"parameter", e.parameters[i]}});
    bj["extrapolated"] = e.extrapolated;
    bj["error_estimate"] = e.error_estimate;  // infinity (one level): null
    bj["observed_order"] = e.observed_order;
    if (e.type == BifurcationType::neimark_sacker) {        // the angle extrapolated as the location is
      bj["angle_extrapolated"] = e.angle_extrapolated;      // NaN with one level: null
      bj["angle_error_estimate"] = e.angle_error_estimate;  // infinity with one level: null
    }
    bj["bracket"] = finest.bracket;
    if (!e.note.empty() || !finest.note.empty()) bj["note"] = finest.note + (finest.note.empty() ? "" : "; ") + e.note;
    list.push_back(bj);
  }
  return list;
}

std::string branch_csv(const std::string& header, const ContinuationResult& branch, int nev,
                       const std::vector<StabilityVerdict>& verdicts) {
  std::ostringstream rows;
  rows << header << "parameter,stable,unstable,abs_mu1";
  const size_t d = branch.points.front().measures.max.size();
  for (size_t c = 0; c < d; ++c) rows << ",max_y" << c + 1;
  for (size_t c = 0; c < d; ++c) rows << ",min_y" << c + 1;
  rows << ",max_H,contact_time,newton_iterations";
  const bool autonomous = std::isfinite(branch.points.front().period);
  if (autonomous) rows << ",period";
  for (int k = 0; k < nev; ++k) rows << ",mu" << k + 1 << "_re,mu" << k + 1 << "_im";
  if (!verdicts.empty()) rows << ",undecided";
  rows << "\n";
  for (size_t i = 0; i < branch.points.size(); ++i) {
    const ContinuationPoint& p = branch.points[i];
    rows << csv_number(p.parameter) << "," << (p.stable() ? 1 : 0) << "," << p.unstable << ","
         << csv_number(p.multipliers.empty() ? NAN : std::abs(p.multipliers[0]));
    for (double v : p.measures.max) rows << "," << csv_number(v);
    for (double v : p.measures.min) rows << "," << csv_number(v);
    rows << "," << csv_number(p.measures.max_H) << "," << csv_number(p.measures.contact_time) << ","
         << p.newton_iterations;
    if (autonomous) rows << "," << csv_number(p.period);
    for (int k = 0; k < nev; ++k) {
      const bool has = static_cast<size_t>(k) < p.multipliers.size();
      rows << "," << csv_number(has ? p.multipliers[k].real() : NAN) << ","
           << csv_number(has ? p.multipliers[k].imag() : NAN);
    }
    if (!verdicts.empty()) rows << "," << (verdicts.at(i) == StabilityVerdict::undecided ? 1 : 0);
    rows << "\n";
  }
  return rows.str();
}

std::string bifurcations_csv(const std::string& header, const std::vector<BifurcationEstimate>& estimates,
                             const ContinuationResult& branch) {
  std::ostringstream bifs;
  bifs << header << "type,parameter,extrapolated,error_estimate,observed_order,angle,abs_mu,by_N\n";
  for (size_t b = 0; b < estimates.size(); ++b) {
    const BifurcationEstimate& e = estimates[b];
    std::complex<double> critical;
    const double g = e.type == BifurcationType::grazing
                         ? NAN
                         : continuation_detail::multiplier_test(e.type, branch.bifurcations[b].multipliers, &critical);
    bifs << to_string(e.type) << "," << csv_number(e.parameter) << "," << csv_number(e.extrapolated) << ","
         << csv_number(e.error_estimate) << "," << csv_number(e.observed_order) << "," << csv_number(e.angle) << ","
         << csv_number(std::isfinite(g) ? std::abs(critical) : NAN) << ",";
    for (size_t i = 0; i < e.Ns.size(); ++i) bifs << (i ? ";" : "") << e.Ns[i] << ":" << format_number(e.parameters[i]);
    bifs << "\n";
  }
  return bifs.str();
}

}  // namespace delayspec::cli
