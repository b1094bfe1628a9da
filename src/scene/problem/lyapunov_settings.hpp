#pragma once
// Lyapunov keys shared by `lyapunov` and `sweep`: exponents, periods, transient, seed,
// qr_every, batches (CLI contract), and the one function that runs the exponents for any
// model of the problem from its constant initial history.
#include "scene/keys/config.hpp"
#include "delayspec/lyapunov.hpp"
#include "scene/problem/problem.hpp"

namespace delayspec::cli {

// Reads the keys; default_exponents when `exponents` is absent. Range checks that need the
// dimension happen in lyapunov_exponents (BadInput naming the key).
LyapunovOptions read_lyapunov_options(Config& config, int default_exponents = 2);

// Runs lyapunov_exponents on the problem's model from the constant initial history given by the
// model's keys (x0, v0). Thread-safe: builds its own stepper and buffers.
LyapunovResult run_lyapunov(const Problem& problem, const LyapunovOptions& options);

}  // namespace delayspec::cli
