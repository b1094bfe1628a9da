#pragma once
// The built-in models as problem families (delayspec/problem_family.hpp): each model's keys read
// once into its parameter struct, and its continuable parameters set by name on a copy of that
// struct, the model made from it with its own checks. What the keys mean is said here once:
// `period` of linear and mackey-glass follows `tau` unless the scene gives it; the impact model's
// `tau` (time) or `tau_over_T` (forcing periods), whichever the scene gives.
//
// Not parameters of a family: the initial history (x0, v0: where the orbit search starts, not the
// equations), milling's tooth count and pitch angles (integers and lists, which change the model's
// shape) and direction.
#include <memory>
#include <string>
#include <vector>

#include "delayspec/problem_family.hpp"
#include "modules/models/any_model.hpp"
#include "scene/keys/config.hpp"

namespace delayspec::cli {

class BuiltinFamily : public ProblemFamily {
 public:
  // The model at `values` (BadInput from its own checks).
  virtual AnyModel model_at(const std::vector<double>& values) const = 0;

 protected:
  FamilyMember make(const std::vector<double>& values) const override;
};

// Each built-in model's family from its keys (the key `model` chose it). BadInput naming the
// key for a value the model refuses at the scene's own values.
std::shared_ptr<const BuiltinFamily> read_impact_family(Config& config);
std::shared_ptr<const BuiltinFamily> read_linear_family(Config& config);
std::shared_ptr<const BuiltinFamily> read_mathieu_family(Config& config);
std::shared_ptr<const BuiltinFamily> read_mackey_glass_family(Config& config);
std::shared_ptr<const BuiltinFamily> read_milling_family(Config& config);

}  // namespace delayspec::cli
