#include "modules/equations/equation_model_source.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <functional>
#include <set>
#include <sstream>
#include <stdexcept>

#include "modules/equations/equation_cxx_printer.hpp"
#include "modules/equations/equation_model_symbolic.hpp"
#include "delayspec/errors.hpp"
#include "modules/equations/equation_names.hpp"

namespace delayspec::cli {

namespace {

// The largest model compiled: the printed functions' size. Measured (2 cores, load 2): 500 terms
// c x^a v_tau^b sin(k t) in a d = 2 model print 165 kB and compile in 14.8 s, and the time grows
// with the text; 1 MB is about 3000 such terms, a minute and a half. The impact scene prints 6 kB.
constexpr size_t kMaxModelCode = 1'000'000;

std::string bool_text(bool b) { return b ? "true" : "false"; }

const char* switching_text(ModelSwitching kind) {
  switch (kind) {
    case ModelSwitching::state: return "delayspec::ModelSwitching::state";
    case ModelSwitching::time: return "delayspec::ModelSwitching::time";
    case ModelSwitching::none: break;
  }
  return "delayspec::ModelSwitching::none";
}

// What the engine's templates must know of the model (model_functions.hpp).
ModelShape shape_of(const SymbolicEquationModel& m) {
  return {m.d(), m.delay_count(), m.switch_kind, m.autonomous, m.affine_in_state, m.is_linear};
}

// The model as the functions of model_functions.hpp (static, in the caller's namespace), its
// shape kShape and the table kFunctions of them.
class ModelPrinter {
 public:
  explicit ModelPrinter(const SymbolicEquationModel& m) : m_(m) {
    generated_.insert("t");
    generated_.insert(pi_.get_name());
    for (const auto* symbols : {&m_.y, &m_.z, &m_.p})
      for (const auto& s : *symbols) generated_.insert(s.get_name());
  }

  std::string print() {
    const bool state_switch = m_.switch_kind == SwitchKind::state;
    const bool time_switch = m_.switch_kind == SwitchKind::time;
    const ModelShape shape = shape_of(m_);
    out_ << "constexpr int d = " << shape.d << ";\n"
         << "constexpr int parameter_count = " << m_.p.size() << ";\n"
         << "constexpr delayspec::ModelShape kShape{d, " << shape.delay_count << ", " << switching_text(shape.switching)
         << ", " << bool_text(shape.autonomous) << ", " << bool_text(shape.affine_in_state) << ", "
         << bool_text(shape.is_linear) << "};\n";
    out_ << "// The functions of the expressions, as <cmath>'s (the printed expressions call them unqualified).\n";
    // sin and cos through the per-thread memo of the built-in models (detail/remembered_trig.hpp,
    // the same values bit for bit): a forcing term sin(w t) is evaluated at one t by f, f_t,
    // f_tt, the event test and the next step's left node. Measured on the impact equations,
    // lyapunov N = 1000, 1e4 periods (bench_equations): 1.43 s with std::sin, 1.24 s with the
    // memo, against 1.07 s for the built-in model.
    for (const auto& f : equation_functions())
      out_ << "[[maybe_unused]] static double " << f << "(double x) { return "
           << (f == "sin" || f == "cos" ? "delayspec::detail::remembered_" : "std::") << f << "(x); }\n";
    out_ << "[[maybe_unused]] static double pow(double x, double y) { return std::pow(x, y); }\n"
         << "[[maybe_unused]] constexpr double " << pi_.get_name() << " = "
         << "3.141592653589793238462643383279502884;\n";
    out_ << "static double period_of([[maybe_unused]] const double* p) { return " << cxx(m_.period) << "; }\n"
         << "static void delays_of([[maybe_unused]] const double* p, double* taus) {\n";
    for (int k = 0; k < m_.delay_count(); ++k) out_ << "  taus[" << k << "] = " << cxx(m_.delays[k]) << ";\n";
    out_ << "}\n"
         << "static void history_of([[maybe_unused]] const double* p, double* r) {\n";
    for (int i = 0; i < m_.d(); ++i) out_ << "  r[" << i << "] = " << cxx(m_.history[i]) << ";\n";
    out_ << "}\n";
    print_field_vector("f", [](const SymbolicField& f) -> const std::vector<GiNaC::ex>& { return f.f; });
    print_field_matrix("A", [](const SymbolicField& f) -> const auto& { return f.A; });
    print_field_matrix("B", [](const SymbolicField& f) -> const auto& { return f.B; });
    if (state_switch) {
      print_field_vector("f_t", [](const SymbolicField& f) -> const std::vector<GiNaC::ex>& { return f.f_t; });
      print_field_vector("f_tt", [](const SymbolicField& f) -> const std::vector<GiNaC::ex>& { return f.f_tt; });
      print_state_switch();
    }
    if (time_switch)
      out_ << "static double switch_value([[maybe_unused]] double t, [[maybe_unused]] const double* p) { return "
           << cxx(m_.switch_function) << "; }\n";
    out_ << "const delayspec::ModelFunctions kFunctions = {f, A, B, "
         << (state_switch ? "f_t, f_tt, H, grad_H, nullptr" : "nullptr, nullptr, nullptr, nullptr, ")
         << (state_switch ? "" : time_switch ? "switch_value" : "nullptr") << "};\n";
    return out_.str();
  }

 private:
  using Components = std::function<const std::vector<GiNaC::ex>&(const SymbolicField&)>;
  using Matrix = std::function<const std::vector<std::vector<GiNaC::ex>>&(const SymbolicField&)>;

  // The C++ text of e (equation_cxx_printer.hpp), pi as pi_. Checks that only generated names,
  // the whitelisted functions and real numbers appear.
  std::string cxx(const GiNaC::ex& e) const {
    const GiNaC::ex printed = e.subs(GiNaC::Pi == pi_);
    for (auto it = printed.preorder_begin(); it != printed.preorder_end(); ++it) {
      if (GiNaC::is_a<GiNaC::symbol>(*it) && !generated_.count(GiNaC::ex_to<GiNaC::symbol>(*it).get_name()))
        throw std::logic_error("equation model: a symbol without a generated name");
      if (GiNaC::is_a<GiNaC::function>(*it)) {
        const auto& functions = equation_functions();
        const std::string name = GiNaC::ex_to<GiNaC::function>(*it).get_name();
        if (std::find(functions.begin(), functions.end(), name) == functions.end())
          throw std::logic_error("equation model: GiNaC produced the function " + name);
      }
      if (GiNaC::is_a<GiNaC::constant>(*it) ||
          (GiNaC::is_a<GiNaC::numeric>(*it) && !GiNaC::ex_to<GiNaC::numeric>(*it).is_real()))
        throw std::logic_error("equation model: a constant other than a real number or pi");
    }
    return cxx_text(printed);
  }

  static std::string arguments() {
    return "([[maybe_unused]] int j, [[maybe_unused]] double t, [[maybe_unused]] const double* y, "
           "[[maybe_unused]] const double* z, [[maybe_unused]] const double* p, double* r) {\n";
  }

  // The body for each field: one field, or `if (j == 1) f_1 else f_2`.
  void per_field(const std::function<void(const SymbolicField&, const std::string&)>& body) {
    if (m_.fields.size() == 1) {
      body(m_.fields[0], "  ");
      return;
    }
    out_ << "  if (j == 1) {\n";
    body(m_.fields[0], "    ");
    out_ << "  } else {\n";
    body(m_.fields[1], "    ");
    out_ << "  }\n";
  }

  void print_field_vector(const std::string& name, const Components& components) {
    out_ << "static void " << name << arguments();
    per_field([&](const SymbolicField& field, const std::string& indent) {
      const auto& c = components(field);
      for (size_t i = 0; i < c.size(); ++i) out_ << indent << "r[" << i << "] = " << cxx(c[i]) << ";\n";
    });
    out_ << "}\n";
  }

  // Column by column (model_functions.hpp): entry (i, a) is r[i + d a]; r arrives zeroed.
  void print_field_matrix(const std::string& name, const Matrix& matrix) {
    out_ << "static void " << name << arguments();
    per_field([&](const SymbolicField& field, const std::string& indent) {
      const auto& entries = matrix(field);
      for (size_t i = 0; i < entries.size(); ++i)
        for (size_t a = 0; a < entries[i].size(); ++a)
          if (!entries[i][a].is_zero())
            out_ << indent << "r[" << i + entries.size() * a << "] = " << cxx(entries[i][a]) << ";\n";
    });
    out_ << "}\n";
  }

  void print_state_switch() {
    out_ << "static double H([[maybe_unused]] const double* y, [[maybe_unused]] const double* p) { return "
         << cxx(m_.switch_function) << "; }\n"
         << "static void grad_H([[maybe_unused]] const double* y, [[maybe_unused]] const double* p, double* r) {\n";
    for (size_t a = 0; a < m_.grad_H.size(); ++a) out_ << "  r[" << a << "] = " << cxx(m_.grad_H[a]) << ";\n";
    out_ << "}\n";
  }

  const SymbolicEquationModel& m_;
  const GiNaC::symbol pi_{"pi_"};
  std::set<std::string> generated_;
  std::ostringstream out_;
};

}  // namespace

EquationModelSource generate_equation_model(const toml::table& equations,
                                            const std::vector<std::string>& reserved_keys) {
  const SymbolicEquationModel model = analyse_equations(equations, reserved_keys);
  EquationModelSource source;
  source.state = model.state;
  source.parameters = model.parameters;
  source.parameter_defaults = model.parameter_defaults;
  source.delays = model.delay_names;
  source.written_with_delays = equations.contains("delays");
  for (size_t a = 0; a < model.z.size(); ++a) source.delayed.push_back(model.delayed_name(a));
  source.shape = shape_of(model);
  source.code = ModelPrinter(model).print();
  if (source.code.size() > kMaxModelCode)
    throw BadInput("`equations`: the model's derivatives print as " + std::to_string(source.code.size() / 1000) +
                   " kB of C++, more than the " + std::to_string(kMaxModelCode / 1000) +
                   " kB delayspec compiles (a model this large compiles for minutes): simplify it");
  std::vector<GiNaC::ex> constants = {model.period};
  constants.insert(constants.end(), model.delays.begin(), model.delays.end());
  constants.insert(constants.end(), model.history.begin(), model.history.end());
  source.constants = [constants, p = model.p](const std::vector<double>& values) {
    GiNaC::lst at;
    for (size_t k = 0; k < p.size() && k < values.size(); ++k) at.append(p[k] == GiNaC::numeric(values[k]));
    std::vector<double> out;
    for (const auto& e : constants) {
      double v = std::numeric_limits<double>::quiet_NaN();
      try {
        const GiNaC::ex x = GiNaC::evalf(e.subs(at));
        if (GiNaC::is_a<GiNaC::numeric>(x) && GiNaC::ex_to<GiNaC::numeric>(x).is_real())
          v = GiNaC::ex_to<GiNaC::numeric>(x).to_double();
      } catch (const std::exception&) {  // 1/0 and other poles at these values
      }
      out.push_back(std::isfinite(v) ? v : std::numeric_limits<double>::quiet_NaN());
    }
    return out;
  };
  source.terms_not_finite = [symbolic = std::make_shared<const SymbolicEquationModel>(model)](
                                double t, const std::vector<double>& y, const std::vector<double>& y_tau,
                                const std::vector<double>& p) { return terms_not_finite(*symbolic, t, y, y_tau, p); };
  return source;
}

}  // namespace delayspec::cli
