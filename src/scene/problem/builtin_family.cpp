#include "scene/problem/builtin_family.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <utility>

#include "delayspec/errors.hpp"
#include "scene/problem/models_module_loader.hpp"

namespace delayspec::cli {

FamilyMember BuiltinFamily::make(const std::vector<double>& values) const {
  try {
    return {builtin_model_analyses(model_at(values)), ""};
  } catch (const BadInput& e) {
    return {nullptr, e.what()};
  }
}

namespace {

// A model's family over the members of its parameter struct: a copy of the scene's struct with
// the named members set, made into the model by `make` (which applies the model's own rules and
// checks).
template <class Parameters>
class ParametersFamily final : public BuiltinFamily {
 public:
  using Member = double Parameters::*;
  using Make = AnyModel (*)(Parameters);
  ParametersFamily(const Parameters& base, std::vector<std::pair<std::string, Member>> members, Make make)
      : base_(base), members_(std::move(members)), make_(make) {
    for (const auto& [name, member] : members_) {
      names_.push_back(name);
      base_values_.push_back(base_.*member);
    }
  }
  const std::vector<std::string>& parameter_names() const override { return names_; }
  const std::vector<double>& base_values() const override { return base_values_; }
  AnyModel model_at(const std::vector<double>& values) const override {
    if (values.size() != members_.size())
      throw std::invalid_argument("ParametersFamily::model_at: " + std::to_string(values.size()) + " values for " +
                                  std::to_string(members_.size()) + " parameters");
    Parameters p = base_;
    for (size_t i = 0; i < members_.size(); ++i) p.*(members_[i].second) = values[i];
    return make_(p);
  }

 private:
  Parameters base_;
  std::vector<std::pair<std::string, Member>> members_;
  Make make_;
  std::vector<std::string> names_;
  std::vector<double> base_values_;
};

// Made, and so checked, at the scene's own values: the read refuses what the model refuses,
// naming the key, before anything else is read.
template <class Parameters>
std::shared_ptr<const BuiltinFamily> checked_family(const Parameters& p,
                                                    std::vector<std::pair<std::string, double Parameters::*>> members,
                                                    AnyModel (*make)(Parameters)) {
  auto family = std::make_shared<const ParametersFamily<Parameters>>(p, std::move(members), make);
  family->model_at(family->base_values());
  return family;
}

// The key `period`, or NaN when the scene does not give it: then the delay's at every value of
// the family (with_period), not the scene's tau fixed. (Read either way: --help shows tau's value
// as its default.)
double period_or_nan(Config& c, double tau) {
  const bool given = c.has("period");
  const double period = c.get_double("period", tau);
  return given ? period : NAN;
}

// A period not given (NaN) is the delay's: the map samples once per delay.
template <class Parameters>
Parameters with_period(Parameters p) {
  if (std::isnan(p.period)) p.period = p.tau;
  return p;
}

}  // namespace

std::shared_ptr<const BuiltinFamily> read_impact_family(Config& c) {
  ImpactParameters p;
  p.zeta = c.get_double("zeta", p.zeta);
  p.e = c.get_double("e", p.e);
  p.a = c.get_double("a", p.a);
  p.beta = c.get_double("beta", p.beta);
  p.omega = c.get_double("omega", p.omega);
  p.k = c.get_double("k", p.k);
  p.x0 = c.get_double("x0", p.x0);
  p.v0 = c.get_double("v0", p.v0);
  if (c.has("tau") && c.has("tau_over_T")) throw BadInput("`tau` and `tau_over_T` are both given: give one of them");
  using P = ImpactParameters;
  std::vector<std::pair<std::string, double P::*>> members = {{"zeta", &P::zeta}, {"e", &P::e},         {"a", &P::a},
                                                             {"beta", &P::beta}, {"omega", &P::omega}, {"k", &P::k}};
  // The delay in time (tau) when the scene gives it; else in forcing periods (tau_over_T), with
  // tau = 0 ("use tau_over_T", model_impact.hpp) unless a family's value sets it.
  if (c.has("tau")) {
    p.tau = c.get_double("tau", 0);
    require_positive("tau", p.tau);
    members.push_back({"tau", &P::tau});
  } else {
    p.tau_over_T = c.get_double("tau_over_T", p.tau_over_T);
    require_positive("tau_over_T", p.tau_over_T);
    members.push_back({"tau_over_T", &P::tau_over_T});
    members.push_back({"tau", &P::tau});
  }
  if (c.has("tau"))
    return checked_family<P>(p, std::move(members), [](P q) -> AnyModel {
      require_positive("tau", q.tau);  // (0 would mean tau_over_T to the model)
      return ImpactModel(q);
    });
  return checked_family<P>(p, std::move(members), [](P q) -> AnyModel { return ImpactModel(q); });
}

std::shared_ptr<const BuiltinFamily> read_linear_family(Config& c) {
  using P = LinearParameters;
  P p;
  p.a = c.get_double("a", p.a);
  p.b = c.get_double("b", p.b);
  p.tau = c.get_double("tau", p.tau);
  p.period = period_or_nan(c, p.tau);
  return checked_family<P>(p, {{"a", &P::a}, {"b", &P::b}, {"tau", &P::tau}, {"period", &P::period}},
                           [](P q) -> AnyModel { return LinearModel(with_period(q)); });
}

std::shared_ptr<const BuiltinFamily> read_mathieu_family(Config& c) {
  using P = MathieuParameters;
  P p;
  p.kappa = c.get_double("kappa", p.kappa);
  p.delta = c.get_double("delta", p.delta);
  p.eps = c.get_double("eps", p.eps);
  p.b = c.get_double("b", p.b);
  return checked_family<P>(p, {{"kappa", &P::kappa}, {"delta", &P::delta}, {"eps", &P::eps}, {"b", &P::b}},
                           [](P q) -> AnyModel { return MathieuModel(q); });
}

std::shared_ptr<const BuiltinFamily> read_mackey_glass_family(Config& c) {
  using P = MackeyGlassParameters;
  P p;
  p.beta = c.get_double("beta", p.beta);
  p.gamma = c.get_double("gamma", p.gamma);
  p.n = c.get_double("n", p.n);
  p.tau = c.get_double("tau", p.tau);
  p.period = period_or_nan(c, p.tau);
  p.x0 = c.get_double("x0", p.x0);
  return checked_family<P>(
      p, {{"beta", &P::beta}, {"gamma", &P::gamma}, {"n", &P::n}, {"tau", &P::tau}, {"period", &P::period}},
      [](P q) -> AnyModel { return MackeyGlassModel(with_period(q)); });
}

// Equal pitch unless `pitch_angles` gives unequal spacings (VariablePitchMillingModel); angles all
// equal are the equal-pitch tool, the same model as without them.
std::shared_ptr<const BuiltinFamily> read_milling_family(Config& c) {
  using P = MillingParameters;
  P p;
  p.spindle_rpm = c.get_double("spindle_rpm", p.spindle_rpm);
  p.depth = c.get_double("depth", p.depth);
  p.radial_immersion = c.get_double("radial_immersion", p.radial_immersion);
  // The model names the allowed range (1..kMaxTeeth) in its own message; the wide range here
  // only keeps the cast safe.
  p.teeth = static_cast<int>(c.get_int_in_range("teeth", p.teeth, 1, MillingModel::kMaxTeeth));
  // `equal` (what --help prints as the default) is accepted as a value too: the equal pitch.
  if (c.get_string("pitch_angles", "equal") != "equal") p.pitch_angles = c.get_double_list("pitch_angles", "equal");
  p.Kt = c.get_double("Kt", p.Kt);
  p.Kn = c.get_double("Kn", p.Kn);
  p.omega_n = c.get_double("omega_n", p.omega_n);
  p.zeta = c.get_double("zeta", p.zeta);
  p.mass = c.get_double("mass", p.mass);
  p.direction = c.get_enum("milling", MillingDirection::down, {{"down", MillingDirection::down}, {"up", MillingDirection::up}});
  p.x0 = c.get_double("x0", p.x0);
  p.v0 = c.get_double("v0", p.v0);
  if (!p.pitch_angles.empty()) {
    if (!c.has("teeth"))
      p.teeth = static_cast<int>(std::min<size_t>(p.pitch_angles.size(), MillingModel::kMaxTeeth + 1));
    const VariablePitchMillingModel variable(p);  // (checks the angles against the teeth)
    if (variable.distinct_pitches() <= 1) p.pitch_angles.clear();
  }
  // The angles do not depend on a family's values: the tool's kind is decided once, here.
  return checked_family<P>(p,
                           {{"spindle_rpm", &P::spindle_rpm},
                            {"depth", &P::depth},
                            {"radial_immersion", &P::radial_immersion},
                            {"Kt", &P::Kt},
                            {"Kn", &P::Kn},
                            {"omega_n", &P::omega_n},
                            {"zeta", &P::zeta},
                            {"mass", &P::mass}},
                           [](P q) -> AnyModel {
                             if (q.pitch_angles.empty()) return MillingModel(q);
                             return VariablePitchMillingModel(q);
                           });
}

}  // namespace delayspec::cli
