#pragma once
// Scenes with a model written as equations, shared by the tests that read them.

namespace delayspec::testing {

// Mackey-Glass as equations: the built-in model's right-hand side with beta = 0.2, gamma = 0.1,
// n = 10, tau = 8 (its period the delay), history 0.5.
inline constexpr const char* kMackeyGlassEquationsScene = R"scene(model = "equations"
[equations]
state = ["x"]
parameters = { beta = 0.2, gamma = 0.1, n = 10, tau = 8 }
period = "tau"
delay = "tau"
rhs = ["beta*x_tau/(1 + x_tau^n) - gamma*x"]
history = { x = 0.5 }
)scene";

}  // namespace delayspec::testing
