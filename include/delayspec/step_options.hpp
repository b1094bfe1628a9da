#pragma once
// What a step is asked to do and what it reports: shared by the stepper (stepper.hpp) and the
// event-splitting step (event_step.hpp), so that neither header includes the other.
#include <array>

#include "delayspec/types.hpp"

namespace delayspec {

// How a step treats a crossing of the switching surface H = 0 (design.md 1.5).
enum class EventMode { on, linear, off };
// Which derivative of a step with events: the exact derivative of the discrete map
// (event-time sensitivity included) or the paper's, with the split points frozen.
enum class JacobianMode { consistent, frozen };

// Where the grid's nodes go (grid.hpp): on every time switch of the model, each piece between
// switches uniform (aligned: the error expansion even, h^2, h^4, ...; design.md 1.4c), or
// uniform over the period, the switches falling inside steps (split there: time_switch_step.hpp).
// A model without time switches, or with a fractional or several delays, has a uniform grid
// either way.
enum class GridLayout { aligned, uniform };

struct StepOptions {
  EventMode events = EventMode::on;
  JacobianMode jacobian = JacobianMode::consistent;
  // Trapezoid sub-steps per piece of a step on the H > 0 side (contact), events on/linear only:
  // resolves a contact shorter than h (design.md 1.5). >= 1; 1 = one trapezoid per piece.
  // Default 4: a split step's trapezoid error depends on where the event falls in the step,
  // which adds an O(h^2) term to the multipliers whose constant jumps with N; m sub-steps shrink
  // it by m^2. On the paper's orbit m = 1 converges erratically (observed order -0.1 between
  // N = 1600 and 3200), m = 4 with order 1.95 (docs/events.md), at no measurable cost there.
  int contact_substeps = 4;
  // 0: each node in the region of its state (the switched system). 1 or 2 (models that switch in
  // the state): that region's field everywhere, H ignored and no event located: the orbit of one
  // smooth field, which stays smooth in the parameters where the switched orbit's is not. Its
  // max H = 0 is the grazing of the switched orbit (the two coincide while max H <= 0): what
  // `boundary` follows as a grazing curve (a switched orbit that barely touches has a contact
  // whose length grows as a square root, and Newton stalls there).
  int fixed_region = 0;
  GridLayout grid = GridLayout::aligned;  // where the grid's nodes go (above)
};

// What happened inside one step (filled by step() when asked; events off: always empty).
struct StepEvents {
  static constexpr int kMaxEvents = 16;  // more crossings than this in one step: NumericalFailure
  int count = 0;
  std::array<double, kMaxEvents> offset{};   // event time minus step start, in [0, h]
  std::array<int, kMaxEvents> new_region{};  // region entered at the event (1: H > 0, contact)
  // Number of entries into region 1 (impacts, for the impact model).
  int entries_into_region1() const {
    int n = 0;
    for (int i = 0; i < count; ++i) n += new_region[i] == 1;
    return n;
  }
};

// Region choice for the right node of a sub-step: a fixed region, or "the region of z1"
// (found together with z1: the plain, unsplit trapezoid rule).
inline constexpr int kRegionOfEndpoint = 0;

template <int D, int DW = D>
struct SubStepResult {
  Vec<D> z1;
  Mat<D> dz0;          // dz1 / dz0
  RectMat<D, DW> dw0;  // dz1 / dw0 (delayed value at the left node)
  RectMat<D, DW> dw1;  // dz1 / dw1 (delayed value at the right node)
  int right_region = 1;
};

}  // namespace delayspec
