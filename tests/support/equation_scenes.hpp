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

// A damped, forced, weakly nonlinear oscillator in (x, v): one stable orbit for every b in
// [0, 0.3]; its states named x and v (the output's names, issue 61 item 8).
inline constexpr const char* kForcedPairEquationsScene = R"scene(model = "equations"
[equations]
state = ["x", "v"]
parameters = { b = 0.1, c = 1.0 }
period = "2*pi"
delay = "1"
rhs = ["v", "-x - c*v - 0.1*x^3 + b*x_tau + cos(t)"]
history = { x = 0, v = 0 }
)scene";

}  // namespace delayspec::testing
