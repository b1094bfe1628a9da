#include "delayspec/error_expansion.hpp"

namespace delayspec {

RichardsonOptions error_expansion(const ModelAnalyses& analyses, const StepOptions& step) {
  RichardsonOptions options;
  const bool switching = analyses.switches_in_state() || analyses.switches_in_time();
  const bool first_order = switching && step.events == EventMode::off;
  options.order = first_order ? 1 : 2;
  options.order_step = first_order ? 1 : 2;
  options.leading_term_may_hide = first_order;
  return options;
}

}  // namespace delayspec
