#include "delayspec/family_equilibria.hpp"

#include <stdexcept>
#include <string>
#include <utility>

#include "delayspec/error_expansion.hpp"
#include "delayspec/errors.hpp"

namespace delayspec {

EquilibriumFamily equilibria_along(AnalysesAt at, const EquilibriumOptions& options) {
  auto shared_at = std::make_shared<const AnalysesAt>(std::move(at));
  return EquilibriumFamily{
      [shared_at](const Eigen::VectorXd& y, double p) { return (*shared_at)(p)->at_constant_history(y); },
      [shared_at, options](const Eigen::VectorXd& guess, double p, int nroots) {
        EquilibriumOptions with = options;
        with.nroots = nroots;
        return (*shared_at)(p)->equilibrium(guess, with);
      },
      [shared_at, last = std::make_shared<std::pair<double, std::shared_ptr<const ModelAnalyses>>>()](
          const Eigen::VectorXd& y, const Eigen::VectorXd& delayed, double p) {
        if (!last->second || last->first != p) *last = {p, (*shared_at)(p)};
        return last->second->jacobian_at(y, delayed);
      }};
}

namespace {

// The model at (x, y), made once per pair.
class ModelAtPair {
 public:
  ModelAtPair(std::shared_ptr<const ProblemFamily> family, std::vector<double> values, int x, int y,
              const MapSettings& map)
      : family_(std::move(family)), values_(std::move(values)), x_(x), y_(y), map_(map) {}
  std::shared_ptr<const ModelAnalyses> operator()(double x, double y) {
    if (!analyses_ || x != x_value_ || y != y_value_) {
      values_[static_cast<size_t>(x_)] = x;
      values_[static_cast<size_t>(y_)] = y;
      const FamilyMember member = family_->at(values_, map_);
      if (!member) throw BadInput(member.rejected);
      analyses_ = member.analyses;
      x_value_ = x, y_value_ = y;
    }
    return analyses_;
  }

 private:
  std::shared_ptr<const ProblemFamily> family_;
  std::vector<double> values_;
  int x_, y_;
  MapSettings map_;
  std::shared_ptr<const ModelAnalyses> analyses_;
  double x_value_ = 0, y_value_ = 0;
};

}  // namespace

EquilibriumFamily2 equilibria_over(std::shared_ptr<const ProblemFamily> family, std::vector<double> values, int x,
                                   int y, const MapSettings& map, const EquilibriumOptions& options) {
  const size_t n = family->parameter_names().size();
  if (values.size() != n || x < 0 || y < 0 || static_cast<size_t>(x) >= n || static_cast<size_t>(y) >= n || x == y)
    throw std::invalid_argument("equilibria_over: parameters " + std::to_string(x) + " and " + std::to_string(y) +
                                " of " + std::to_string(n) + ", " + std::to_string(values.size()) + " values");
  auto at = std::make_shared<ModelAtPair>(std::move(family), std::move(values), x, y, map);
  return EquilibriumFamily2{
      [at](const Eigen::VectorXd& s, double px, double py) { return (*at)(px, py)->at_constant_history(s); },
      [at, options](const Eigen::VectorXd& guess, double px, double py, int nroots) {
        EquilibriumOptions with = options;
        with.nroots = nroots;
        return (*at)(px, py)->equilibrium(guess, with);
      },
      [at](const Eigen::VectorXd& s, const Eigen::VectorXd& w, double px, double py) {
        return (*at)(px, py)->jacobian_at(s, w);
      }};
}

std::vector<HopfOrbitBranch> orbits_from_hopf_points(const EquilibriumBranch& equilibria, const AnalysesAt& at,
                                                     const std::vector<int>& Ns, const ContinuationOptions& options) {
  std::vector<HopfOrbitBranch> out;
  for (const EquilibriumBifurcation& b : equilibria.bifurcations) {
    if (b.type != EquilibriumBifurcationType::hopf) continue;
    HopfOrbitBranch branch;
    branch.hopf = &b;
    std::vector<std::vector<Bifurcation>> by_N;
    for (int N : Ns) {
      ContinuationOptions o = options;
      o.N = N;
      branch.levels.push_back(at(b.parameter)->continue_from_hopf(at, b, o));
      by_N.push_back(branch.levels.back().bifurcations);
    }
    branch.estimates =
        extrapolate_bifurcations(Ns, by_N, options.tolerance, error_expansion(*at(b.parameter), options.step_options));
    out.push_back(std::move(branch));
  }
  return out;
}

}  // namespace delayspec
