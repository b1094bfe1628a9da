#pragma once
// A scene's [equations] table (docs/models.md) read, checked and differentiated with GiNaC: the
// model as symbolic expressions, before it is printed as C++ (equation_model_source.hpp).
//
// Every user name is replaced by a symbol with a generated name at parse time: state i is y[i],
// its value delayed by delay k z[k d + i] (the user's NAME_X for delay X; NAME_tau with one
// delay), parameter k p[k], time t; pi stays GiNaC's exact constant Pi. Messages show the user's
// names again (display()).
#include <string>
#include <vector>

#include <ginac/ginac.h>
#include <toml++/toml.h>

#include "delayspec/model_functions.hpp"

namespace delayspec::cli {

// The kind of switch: the engine's ModelSwitching (model_functions.hpp), part of the model's shape.
using SwitchKind = ModelSwitching;

// One vector field f_j and what the engine needs of it, by GiNaC's diff.
struct SymbolicField {
  std::string entry;                         // "rhs" or "rhs_switched"
  std::vector<std::string> text;             // the entry's components as the scene wrote them (messages)
  std::vector<GiNaC::ex> f;                  // f_j, d components
  std::vector<std::vector<GiNaC::ex>> A, B;  // A[i][a] = d f_i / d y_a, B[i][a] = d f_i / d z_a (d n of them)
  std::vector<GiNaC::ex> f_t, f_tt;          // d f / dt, d2 f / dt2 at fixed y, z
};

struct SymbolicEquationModel {
  std::vector<std::string> state;       // user names, in order
  std::vector<std::string> parameters;  // user names, in the table's (sorted) order
  std::vector<double> parameter_defaults;
  // The delays' names (the `delays` table's keys, sorted; {"tau"} for `delay` or none) and their
  // expressions, in p and Pi only.
  std::vector<std::string> delay_names;
  std::vector<GiNaC::ex> delays;
  GiNaC::symbol t{"t"};
  std::vector<GiNaC::symbol> y, z, p;  // printed y[i], z[k d + i], p[k]
  GiNaC::ex period;                    // in p and Pi only
  std::vector<GiNaC::ex> history;      // d entries, in p and Pi only
  SwitchKind switch_kind = SwitchKind::none;
  GiNaC::ex switch_function;      // H (0 without a switch): of t only, or affine in y
  std::vector<GiNaC::ex> grad_H;  // state switch only: d H / d y_a (constant in y)
  // fields[0] is f_1 (rhs_switched, H > 0) and fields[1] f_2 (rhs) with a switch; without a
  // switch the one field rhs.
  std::vector<SymbolicField> fields;
  bool affine_in_state = false;  // every d2 f_j / dy_a dy_b == 0
  bool is_linear = false;        // no state switch, every f_j affine in (y, z) jointly
  bool autonomous = false;       // no switch, and d f / dt == 0: no forcing (equilibria)

  int d() const { return static_cast<int>(state.size()); }
  int delay_count() const { return static_cast<int>(delays.size()); }
  // The user's name of z[a]: NAME_X (state a mod d, delay a / d).
  std::string delayed_name(size_t a) const { return state[a % state.size()] + "_" + delay_names[a / state.size()]; }
  // e with the user's names for the generated symbols, for messages.
  GiNaC::ex display(const GiNaC::ex& e) const;
};

// What of the model is not a finite real number at a point (t, y, the delayed states z) and
// parameter values p, evaluated by GiNaC from the exact expressions (not the compiled code): each component
// of every field and its derivatives by y and y_tau, one line each, e.g. "`equations.rhs[1]` =
// a*x^(1/3)+b*x_tau: its derivative by x, 1/3*a*x^(-2/3), is undefined (division by zero)".
// Empty when all are finite. For messages about a step that failed. Not thread-safe (GiNaC).
std::vector<std::string> terms_not_finite(const SymbolicEquationModel& model, double t, const std::vector<double>& y,
                                          const std::vector<double>& y_tau, const std::vector<double>& p);

// BadInput naming the item for every input error (docs/models.md, "What is checked").
// reserved_keys: the engine's keys, which a parameter may not be named. Not thread-safe (GiNaC).
SymbolicEquationModel analyse_equations(const toml::table& equations, const std::vector<std::string>& reserved_keys);

}  // namespace delayspec::cli
