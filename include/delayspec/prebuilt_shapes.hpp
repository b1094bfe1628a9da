#pragma once
// The shapes (model_functions.hpp) of models written as equations that the library
// libdelayspec_prebuilt is built for: a model of one of these shapes compiles only its own
// functions (under a second) and takes the analyses from that library; any other compiles them
// into its own object (about 20 s; docs/models.md). Each shape costs the library about 25 s of
// compile (src/prebuilt/prebuilt_shape.cpp, one unit per shape): the list holds the shapes of the
// scenes in data/scenes and of the models the tests compile most often.
#include "delayspec/model_functions.hpp"

namespace delayspec {

// One per line, `ModelShape{d, delay_count, switching, autonomous, affine_in_state, is_linear}`:
// CMakeLists.txt counts these lines for the number of units.
inline constexpr ModelShape kPrebuiltShapes[] = {
    ModelShape{2, 1, ModelSwitching::state, false, true, false},  // impact (equations_impact.toml)
    ModelShape{2, 1, ModelSwitching::none, false, false, false},  // forced, nonlinear
    ModelShape{2, 1, ModelSwitching::none, true, false, false},   // autonomous (pyragas_oscillator.toml)
    ModelShape{1, 1, ModelSwitching::none, true, true, true},     // linear scalar
    ModelShape{1, 1, ModelSwitching::none, true, true, false},    // Mackey-Glass
    ModelShape{1, 1, ModelSwitching::time, false, true, true},    // a scalar time switch
    ModelShape{4, 1, ModelSwitching::none, false, false, false},  // equations_two_oscillators.toml
    ModelShape{2, 2, ModelSwitching::none, false, false, false},  // equations_two_delays.toml
    ModelShape{4, 3, ModelSwitching::none, true, true, false},    // equilibrium_neuron_ring.toml
};

// Is `shape` one of them? (A model's unit checks this of its shape at compile time.)
constexpr bool is_prebuilt_shape(const ModelShape& shape) {
  for (const ModelShape& s : kPrebuiltShapes)
    if (s == shape) return true;
  return false;
}

}  // namespace delayspec
