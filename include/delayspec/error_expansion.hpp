#pragma once
// The one home of the rule that says which powers of h the step maps' discretisation error has
// (design 1.5), for every analysis that extrapolates over several N: floquet's error bars, the
// autonomous orbit's period, converge's columns, continue's bifurcations, boundary's points.
//
// The trapezoid's error is even, h^2, h^4, ..., where the step never straddles a switch: smooth
// models, events located (on, linear) in the state and time switches split at their times. A
// switching model stepped with events = off has a first-order term besides: measured with
// converge on milling at a/D = 0.05 (N = 50 .. 1600), the aligned grid's columns show orders 1.7,
// 2.0, 3.9, 4.0, 5.9 (h, then the even series: the switch's node takes the new branch's field for
// the whole step), the uniform grid's a wandering h^2 that no column removes; with its
// leading_term_may_hide, richardson_extrapolate says so rather than trusting a column.
#include "delayspec/model_analyses.hpp"
#include "delayspec/richardson.hpp"

namespace delayspec {

// h^2, h^4, ... (order 2, step 2), or for a model that switches (in its state or in time)
// stepped with events = off: h, h^2, ... with the leading term possibly hidden.
RichardsonOptions error_expansion(const ModelAnalyses& analyses, const StepOptions& step);

}  // namespace delayspec
