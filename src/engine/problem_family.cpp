#include "delayspec/problem_family.hpp"

#include <stdexcept>

#include "delayspec/errors.hpp"
#include "delayspec/memory_budget.hpp"

namespace delayspec {

FamilyMember ProblemFamily::at(const std::vector<double>& values, const MapSettings& map) const {
  FamilyMember member = at(values);
  if (!member) return member;
  try {
    // The grid throws BadInput when N does not fit the delays and period at these values; the
    // least any analysis holds is two histories (the state and a vector the map is applied to).
    const long n = member.analyses->grid(map).dimension(member.analyses->state_dimension());
    require_memory(2 * 8.0 * static_cast<double>(n), "`N = " + std::to_string(map.N) + "`",
                   "two histories of d (N + 1) = " + std::to_string(n) + " doubles");
  } catch (const BadInput& e) {
    return {nullptr, e.what()};
  }
  return member;
}

int ProblemFamily::index_of(const std::string& name) const {
  const std::vector<std::string>& names = parameter_names();
  for (size_t i = 0; i < names.size(); ++i)
    if (names[i] == name) return static_cast<int>(i);
  return -1;
}

std::vector<double> ProblemFamily::with(std::vector<double> values, int index, double value) {
  if (index < 0 || static_cast<size_t>(index) >= values.size())
    throw std::invalid_argument("ProblemFamily::with: no parameter " + std::to_string(index));
  values[static_cast<size_t>(index)] = value;
  return values;
}

AnalysesAt analyses_along(std::shared_ptr<const ProblemFamily> family, std::vector<double> values, int index,
                          const MapSettings& map) {
  if (index < 0 || static_cast<size_t>(index) >= values.size())
    throw std::invalid_argument("analyses_along: no parameter " + std::to_string(index));
  // The values live in the function and are changed in place (no copy per call): a family along
  // a parameter serves one thread, as the continuation does.
  return [family = std::move(family), values = std::move(values), index, map](double p) mutable {
    values[static_cast<size_t>(index)] = p;
    FamilyMember member = family->at(values, map);
    if (!member) throw BadInput(member.rejected);
    return member.analyses;
  };
}

}  // namespace delayspec
