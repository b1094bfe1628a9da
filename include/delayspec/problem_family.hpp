#pragma once
// ProblemFamily: the analyses of one model as its parameters vary, each parameter set by name as
// a double (issue 57 item 1). Continuation follows a branch through the family in one parameter,
// a stability boundary in two; both ask for the model at thousands of parameter values, and the
// family gives it from typed values: the parameter is never printed as text and read back, and
// the scene is never re-read.
//
// A family is made once, by whoever knows the model (the scene layer for the built-in models and
// for a model written as equations; a C++ user for their own ModelAnalysesFor<Model>), and is
// then the engine's only way to the model at other parameter values. Its base values are those it
// was made with; `at` gives the model at any values of the same length. A value the model refuses
// (a negative stiffness, a delay that is not positive, a grid that no longer fits N) is an
// outcome, `rejected` with the model's reason, not an exception: a curve or a branch that walks
// into it ends there and says why.
#include <memory>
#include <string>
#include <vector>

#include "delayspec/model_analyses.hpp"

namespace delayspec {

// The model at one set of parameter values: its analyses, or why the model refuses the values.
struct FamilyMember {
  std::shared_ptr<const ModelAnalyses> analyses;  // null when rejected
  std::string rejected;                           // the model's reason ("" when accepted)
  explicit operator bool() const { return analyses != nullptr; }
};

class ProblemFamily {
 public:
  virtual ~ProblemFamily() = default;

  // The parameters that can be set, by name, in the order of the values; and their base values.
  virtual const std::vector<std::string>& parameter_names() const = 0;
  virtual const std::vector<double>& base_values() const = 0;
  // The model at `values` (one per parameter_names, in its order). The model's own checks decide
  // what is rejected; a wrong number of values is a programming error (std::invalid_argument).
  FamilyMember at(const std::vector<double>& values) const { return make(values); }

  // The model at `values`, rejected also when the grid of `map` cannot be made at those values
  // (a delay shorter than a step, too many steps) or two histories exceed the memory budget
  // (memory_budget.hpp): what every analysis at resolution map.N needs first.
  FamilyMember at(const std::vector<double>& values, const MapSettings& map) const;

  // The index of parameter `name`; -1 when the family has none of that name.
  int index_of(const std::string& name) const;
  // The base values with parameter `index` set to `value`.
  std::vector<double> with(int index, double value) const { return with(base_values(), index, value); }
  static std::vector<double> with(std::vector<double> values, int index, double value);

 protected:
  // at(values): what a family implements.
  virtual FamilyMember make(const std::vector<double>& values) const = 0;
};

// The one-parameter family through `values` along parameter `index` at the resolution of `map`
// (continuation's AnalysesAt): the model at values with entry `index` set to p. AnalysesAt's
// contract is the continuation's (continuation.hpp): a refused value throws BadInput with the
// family's reason, which ends the branch there.
AnalysesAt analyses_along(std::shared_ptr<const ProblemFamily> family, std::vector<double> values, int index,
                          const MapSettings& map);

}  // namespace delayspec
