#include "modules/equations/equation_model_symbolic.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <optional>
#include <set>
#include <sstream>

#include "scene/keys/closest_key.hpp"
#include "delayspec/errors.hpp"
#include "modules/equations/equation_expression.hpp"
#include "modules/equations/equation_names.hpp"

namespace delayspec::cli {

namespace {

const std::vector<std::string>& table_entries() {
  static const std::vector<std::string> entries = {"state",  "parameters", "period",       "delay",  "delays",
                                                   "rhs",    "switch",     "rhs_switched", "history"};
  return entries;
}

std::string item_of(const std::string& entry) { return "equations." + entry; }
std::string item_of(const std::string& entry, size_t index) {  // components count from 1
  return "equations." + entry + "[" + std::to_string(index + 1) + "]";
}

std::string text_of(const GiNaC::ex& e) {
  std::ostringstream out;
  out << e;
  return out.str();
}

// The text of an expression entry: a string, or a number (read as its shortest exact decimal).
std::string expression_text(const toml::node& node, const std::string& item) {
  if (const auto* s = node.as_string()) return s->get();
  if (const auto* i = node.as_integer()) return std::to_string(i->get());
  if (const auto* f = node.as_floating_point()) {
    if (!std::isfinite(f->get())) throw BadInput("`" + item + "`: must be finite");
    return format_number(f->get());
  }
  throw BadInput("`" + item + "`: must be an expression (a string) or a number");
}

const toml::array& required_array(const toml::table& table, const std::string& entry) {
  const toml::node* node = table.get(entry);
  if (!node) throw BadInput("`" + item_of(entry) + "` is required");
  const toml::array* array = node->as_array();
  if (!array) throw BadInput("`" + item_of(entry) + "`: must be an array");
  return *array;
}

class EquationsReader {
 public:
  EquationsReader(const toml::table& table, const std::vector<std::string>& reserved_keys)
      : table_(table), reserved_keys_(reserved_keys) {}

  SymbolicEquationModel read() {
    check_entries();
    read_state();
    read_parameters();
    read_delay_names();
    make_scopes();
    read_constants();
    read_fields();
    classify_switch();
    differentiate();
    return std::move(m_);
  }

 private:
  void check_entries() const {
    for (const auto& [key, node] : table_) {
      const std::string name(key.str());
      const auto& entries = table_entries();
      if (std::find(entries.begin(), entries.end(), name) != entries.end()) continue;
      // The closest by spelling, else one that the name begins or ends (param, switching), else the list.
      std::string suggestion = closest_key(name, entries);
      for (const auto& e : entries)
        if (suggestion.empty() && name.size() >= 3 &&
            (e.compare(0, name.size(), name) == 0 || name.compare(0, e.size(), e) == 0))
          suggestion = e;
      std::string all;
      for (const auto& e : entries) all += (all.empty() ? "" : ", ") + e;
      throw BadInput("`" + item_of(printable(name)) + "`: unknown entry of [equations] (" +
                     (suggestion.empty() ? "the entries are " + all : "did you mean `" + suggestion + "`?") + ")");
    }
  }

  void read_state() {
    const toml::array& state = required_array(table_, "state");
    if (state.empty()) throw BadInput("`equations.state`: must name at least one state");
    for (size_t i = 0; i < state.size(); ++i) {
      const auto* name = state[i].as_string();
      if (!name) throw BadInput("`" + item_of("state", i) + "`: must be a name (a string)");
      check_equation_name(item_of("state", i), name->get());
      if (std::find(m_.state.begin(), m_.state.end(), name->get()) != m_.state.end())
        throw BadInput("`" + item_of("state", i) + "`: `" + name->get() + "` is named twice");
      m_.state.push_back(name->get());
      m_.y.emplace_back("y[" + std::to_string(i) + "]");
    }
  }

  // `delays = { X = "expr", ... }` (several delays, NAME_X) or `delay = "expr"` (one, NAME_tau;
  // the same as delays = { tau = "expr" }), or neither (tau = period). A delay's name may not be
  // a state's or a parameter's, nor make NAME_X one.
  void read_delay_names() {
    const toml::node* several = table_.get("delays");
    if (several && table_.contains("delay"))
      throw BadInput("`equations.delay` and `equations.delays` are both given: `delay = \"...\"` is the same as "
                     "`delays = { tau = \"...\" }`; keep one");
    if (!several) {
      m_.delay_names = {"tau"};
    } else {
      const toml::table* delays = several->as_table();
      if (!delays || delays->empty())
        throw BadInput("`equations.delays`: must be a table of named delays, e.g. { tau1 = \"1\", tau2 = \"sqrt(2)\" }");
      // The symbolic stage and the generated code grow with the delays (d per delay delayed
      // states, each differentiated): 300 took 12 s, 2000 did not finish (issue 61 item 3).
      constexpr size_t kMaxDelays = 128;
      if (delays->size() > kMaxDelays)
        throw BadInput("`equations.delays`: " + std::to_string(delays->size()) + " delays, at most " +
                       std::to_string(kMaxDelays) + " (the symbolic stage and the compiled model grow with each)");
      for (const auto& [key, value] : *delays) {  // sorted by name
        const std::string name(key.str());
        const std::string item = "equations.delays." + printable(name);
        check_equation_name(item, name);
        const auto named = [&](const std::vector<std::string>& names) {
          return std::find(names.begin(), names.end(), name) != names.end();
        };
        if (named(m_.state)) throw BadInput("`" + item + "`: `" + name + "` is also a state");
        if (named(m_.parameters)) throw BadInput("`" + item + "`: `" + name + "` is also a parameter");
        m_.delay_names.push_back(name);
      }
    }
    const size_t d = m_.state.size();
    // STATE_DELAY must name one delayed state: with states u, u_v and delays v_w, w, `u_v_w` would
    // be both u delayed by v_w and u_v delayed by w, one picked silently (issue 61 item 5).
    std::map<std::string, std::string> reading;  // delayed name -> "STATE delayed by DELAY"
    for (size_t k = 0; k < m_.delay_names.size(); ++k)
      for (size_t i = 0; i < d; ++i) {
        m_.z.emplace_back("z[" + std::to_string(k * d + i) + "]");
        const std::string delayed = m_.delayed_name(k * d + i);
        const std::string meaning = "`" + m_.state[i] + "` delayed by `" + m_.delay_names[k] + "`";
        if (const auto [it, fresh] = reading.emplace(delayed, meaning); !fresh)
          throw BadInput("`equations.delays`: the delayed state `" + printable(delayed) + "` would mean both " +
                         it->second + " and " + meaning + ": rename a state or a delay");
        for (const auto* names : {&m_.state, &m_.parameters})
          if (std::find(names->begin(), names->end(), delayed) != names->end())
            throw BadInput("`equations.delays." + printable(m_.delay_names[k]) + "`: the delayed state `" + delayed +
                           "` would be the " + (names == &m_.state ? "state" : "parameter") + " of that name");
      }
  }

  void read_parameters() {
    const toml::node* node = table_.get("parameters");
    if (!node) return;
    const toml::table* parameters = node->as_table();
    if (!parameters) throw BadInput("`equations.parameters`: must be a table name = number");
    for (const auto& [key, value] : *parameters) {  // toml++ keeps a table sorted by key
      const std::string name(key.str());
      const std::string item = "equations.parameters." + printable(name);
      check_equation_name(item, name);
      if (std::find(m_.state.begin(), m_.state.end(), name) != m_.state.end())
        throw BadInput("`" + item + "`: `" + name + "` is also a state");
      if (std::find(reserved_keys_.begin(), reserved_keys_.end(), name) != reserved_keys_.end())
        throw BadInput("`" + item + "`: `" + name + "` collides with an engine key (a parameter is a key: rename it)");
      std::optional<double> number;
      if (const auto* i = value.as_integer()) number = static_cast<double>(i->get());
      if (const auto* f = value.as_floating_point()) number = f->get();
      if (!number) throw BadInput("`" + item + "`: must be a number");
      if (!std::isfinite(*number)) throw BadInput("`" + item + "`: must be finite");
      m_.p.emplace_back("p[" + std::to_string(m_.parameters.size()) + "]");
      m_.parameters.push_back(name);
      m_.parameter_defaults.push_back(*number);
    }
  }

  // Constants (period, delays, history): the parameters and pi. Fields and switch: also t, the
  // states and the delayed states NAME_X.
  void make_scopes() {
    for (size_t k = 0; k < m_.parameters.size(); ++k) constants_.names[m_.parameters[k]] = m_.p[k];
    constants_.names["pi"] = GiNaC::Pi;
    fields_ = constants_;
    fields_.names["t"] = m_.t;
    const std::string only = ": period, delay and history may use only the parameters and pi";
    constants_.elsewhere["t"] = "the time" + only;
    for (size_t i = 0; i < m_.state.size(); ++i) {
      fields_.names[m_.state[i]] = m_.y[i];
      constants_.elsewhere[m_.state[i]] = "a state" + only;
    }
    for (size_t a = 0; a < m_.z.size(); ++a) {
      fields_.names[m_.delayed_name(a)] = m_.z[a];
      constants_.elsewhere[m_.delayed_name(a)] = "a delayed state" + only;
    }
  }

  GiNaC::ex expression(const toml::node& node, const std::string& item, const ExpressionScope& scope) const {
    return parse_equation_expression(item, expression_text(node, item), scope);
  }

  void read_constants() {
    // The period T: the forcing's for a forced model; for an autonomous one only the sampling time
    // of lyapunov and simulate (an orbit's own period is period_guess's), so there it defaults to
    // the one delay (issue 61 item 6: it had to be stated, "the forcing period", for a model with
    // none). A forced model must state it (checked in differentiate, once t's presence is known).
    const toml::node* period = table_.get("period");
    if (period) m_.period = expression(*period, item_of("period"), constants_);
    if (const toml::table* delays = table_.get("delays") ? table_.get("delays")->as_table() : nullptr) {
      for (const auto& [key, value] : *delays)
        m_.delays.push_back(expression(value, "equations.delays." + std::string(key.str()), constants_));
    } else if (const toml::node* delay = table_.get("delay")) {
      m_.delays = {expression(*delay, item_of("delay"), constants_)};
    } else if (period) {
      m_.delays = {m_.period};  // tau = T by default
    }
    if (!period) {
      if (m_.delays.size() != 1)
        throw BadInput(std::string("`equations.period` is required") +
                       (m_.delays.empty() ? " (or `equations.delay`)" : " with several delays") +
                       ": the forcing period T, e.g. \"2*pi/omega\"; for an autonomous model the sampling time of "
                       "lyapunov and simulate, e.g. the longest delay");
      m_.period = m_.delays.front();
      period_defaulted_ = true;
    }
    m_.history.assign(m_.state.size(), 0);
    const toml::node* history = table_.get("history");
    if (!history) return;
    const toml::table* entries = history->as_table();
    if (!entries) throw BadInput("`equations.history`: must be a table state = value");
    for (const auto& [key, value] : *entries) {
      const std::string name(key.str());
      const auto it = std::find(m_.state.begin(), m_.state.end(), name);
      if (it == m_.state.end()) {
        const std::string suggestion = closest_key(name, m_.state);
        throw BadInput("`equations.history." + printable(name) + "`: not a state" +
                       (suggestion.empty() ? "" : " (did you mean `" + suggestion + "`?)"));
      }
      m_.history[it - m_.state.begin()] = expression(value, "equations.history." + name, constants_);
    }
  }

  std::vector<GiNaC::ex> read_field(const std::string& entry) const {
    const toml::array& array = required_array(table_, entry);
    if (array.size() != m_.state.size())
      throw BadInput("`" + item_of(entry) + "`: has " + std::to_string(array.size()) +
                     " entries, the state has d = " + std::to_string(m_.state.size()));
    std::vector<GiNaC::ex> field;
    for (size_t i = 0; i < array.size(); ++i) field.push_back(expression(array[i], item_of(entry, i), fields_));
    return field;
  }

  std::vector<std::string> field_text(const std::string& entry) const {
    std::vector<std::string> text;
    const toml::array& array = required_array(table_, entry);
    for (size_t i = 0; i < array.size(); ++i) text.push_back(expression_text(array[i], item_of(entry, i)));
    return text;
  }

  void read_fields() {
    rhs_ = read_field("rhs");
    const toml::node* h = table_.get("switch");
    const bool switched = table_.contains("rhs_switched");
    if (h && !switched)
      throw BadInput("`equations.rhs_switched` is required with `equations.switch` (the field where switch > 0)");
    if (!h && switched) throw BadInput("`equations.rhs_switched` is given without `equations.switch`");
    if (!h) return;
    m_.switch_function = expression(*h, item_of("switch"), fields_);
    rhs_switched_ = read_field("rhs_switched");
  }

  bool depends_on(const GiNaC::ex& e, const std::vector<GiNaC::symbol>& symbols) const {
    return std::any_of(symbols.begin(), symbols.end(), [&](const GiNaC::symbol& s) { return e.has(s); });
  }

  // A switch of t only is a time window; a switch of the state must be affine in y, free of t and
  // of the delayed states (event location takes grad H constant, design.md 1.5), and the two
  // fields must agree on H = 0 (no saltation).
  void classify_switch() {
    if (rhs_switched_.empty()) return;
    const GiNaC::ex& h = m_.switch_function;
    const std::string item = "`equations.switch`: ";
    const bool of_t = h.has(m_.t), of_y = depends_on(h, m_.y);
    if (depends_on(h, m_.z))
      throw BadInput(item + "may not use delayed states (a switch is of t or of the state y(t))");
    if (of_t && of_y)
      throw BadInput(item + "depends on both t and the state: a switch is a time window (t only) or a state switch");
    if (!of_t && !of_y) throw BadInput(item + "depends on neither t nor the state: the field would never switch");
    if (of_t) {
      m_.switch_kind = SwitchKind::time;
      return;
    }
    m_.switch_kind = SwitchKind::state;
    for (const auto& ya : m_.y) {
      m_.grad_H.push_back(h.diff(ya));  // printed: not normal(), whose form may vary between runs
      if (depends_on(m_.grad_H.back().normal(), m_.y))
        throw BadInput(item +
                       "a state switch must be affine in the state (event location assumes a constant "
                       "gradient of the switch): d/d" +
                       text_of(m_.display(ya)) + " = " + text_of(m_.display(m_.grad_H.back())));
    }
    if (std::all_of(m_.grad_H.begin(), m_.grad_H.end(), [](const GiNaC::ex& c) { return c.normal().is_zero(); }))
      throw BadInput(item + "depends on neither t nor the state: the field would never switch");
    check_continuity();
  }

  // On H = 0, y_a = y_a - H / c_a with c_a = dH/dy_a != 0 (a number if some coefficient is one,
  // else the first non-zero symbolic coefficient, taken non-zero): each f_1 - f_2 with that
  // substitution must vanish identically (GiNaC's normal form).
  void check_continuity() const {
    int a = -1;
    for (size_t b = 0; b < m_.grad_H.size() && a < 0; ++b)
      if (GiNaC::is_a<GiNaC::numeric>(m_.grad_H[b]) && !m_.grad_H[b].is_zero()) a = static_cast<int>(b);
    for (size_t b = 0; b < m_.grad_H.size() && a < 0; ++b)
      if (!m_.grad_H[b].normal().is_zero()) a = static_cast<int>(b);
    const GiNaC::ex on_switch = (m_.y[a] - m_.switch_function / m_.grad_H[a]).expand();
    for (size_t i = 0; i < rhs_.size(); ++i) {
      const GiNaC::ex difference = (rhs_switched_[i] - rhs_[i]).subs(m_.y[a] == on_switch).normal();
      if (!difference.is_zero())
        throw BadInput("`" + item_of("rhs_switched", i) + "` differs from `" + item_of("rhs", i) +
                       "` on switch = 0: difference " + text_of(m_.display(difference)) +
                       " (a state switch needs a continuous field; only a switch of t alone may join "
                       "discontinuous fields)");
    }
  }

  // The expression's size in nodes (every sub-expression counted once per occurrence), stopping
  // once it passes `limit`.
  static size_t nodes(const GiNaC::ex& e, size_t limit) {
    size_t count = 1;
    for (size_t k = 0; k < e.nops() && count <= limit; ++k) count += nodes(e.op(k), limit - count);
    return count;
  }

  SymbolicField differentiate_field(const std::vector<GiNaC::ex>& f, const std::string& entry) const {
    // The derivatives are printed as C++ and compiled: beyond this many nodes in one component's
    // (a product of 300 binomials in x and x_tau has some 1.8e5) the compile takes minutes and
    // the model is better written another way (issue 61 item 3).
    constexpr size_t kMaxNodes = 100'000;
    SymbolicField field;
    field.entry = entry;
    field.text = field_text(entry);
    field.f = f;
    for (size_t i = 0; i < f.size(); ++i) {
      try {
        field.A.emplace_back();
        field.B.emplace_back();
        for (size_t a = 0; a < f.size(); ++a) field.A[i].push_back(f[i].diff(m_.y[a]));
        for (const auto& za : m_.z) field.B[i].push_back(f[i].diff(za));
        field.f_t.push_back(f[i].diff(m_.t));
        field.f_tt.push_back(field.f_t[i].diff(m_.t));
      } catch (const std::exception& e) {
        throw BadInput("`" + item_of(entry, i) + "`: cannot be differentiated: " + e.what());
      }
      size_t size = 0;
      for (const auto* row : {&field.A[i], &field.B[i]})
        for (const auto& derivative : *row) size += nodes(derivative, kMaxNodes - std::min(size, kMaxNodes));
      if (size > kMaxNodes)
        throw BadInput("`" + item_of(entry, i) + "`: its derivatives have more than " + std::to_string(kMaxNodes) +
                       " terms and factors in all, more than delayspec compiles (expand or factor it by hand, or "
                       "write it with fewer products)");
    }
    return field;
  }

  // Whether every second derivative of the field's components in `of` x `of` vanishes.
  static bool affine_in(const SymbolicField& field, const std::vector<GiNaC::symbol>& of) {
    for (const auto& fi : field.f)
      for (size_t a = 0; a < of.size(); ++a)
        for (size_t b = a; b < of.size(); ++b)
          if (!fi.diff(of[a]).diff(of[b]).normal().is_zero()) return false;
    return true;
  }

  void differentiate() {
    if (m_.switch_kind != SwitchKind::none) m_.fields.push_back(differentiate_field(rhs_switched_, "rhs_switched"));
    m_.fields.push_back(differentiate_field(rhs_, "rhs"));
    std::vector<GiNaC::symbol> state_and_delayed = m_.y;
    state_and_delayed.insert(state_and_delayed.end(), m_.z.begin(), m_.z.end());
    m_.affine_in_state =
        std::all_of(m_.fields.begin(), m_.fields.end(), [&](const SymbolicField& f) { return affine_in(f, m_.y); });
    m_.is_linear = m_.switch_kind != SwitchKind::state &&
                   std::all_of(m_.fields.begin(), m_.fields.end(),
                               [&](const SymbolicField& f) { return affine_in(f, state_and_delayed); });
    m_.autonomous = m_.switch_kind == SwitchKind::none &&
                    std::all_of(m_.fields.front().f_t.begin(), m_.fields.front().f_t.end(),
                                [](const GiNaC::ex& e) { return e.normal().is_zero(); });
    if (period_defaulted_ && !m_.autonomous)
      throw BadInput("`equations.period` is required: the right-hand side depends on t (or switches), a forced "
                     "model, whose forcing period T is not the delay's by default (e.g. \"2*pi/omega\")");
  }

  const toml::table& table_;
  const std::vector<std::string>& reserved_keys_;
  SymbolicEquationModel m_;
  ExpressionScope constants_, fields_;
  std::vector<GiNaC::ex> rhs_, rhs_switched_;
  bool period_defaulted_ = false;  // no `period`: the one delay (read_constants)
};

}  // namespace

GiNaC::ex SymbolicEquationModel::display(const GiNaC::ex& e) const {
  GiNaC::exmap names;
  for (size_t i = 0; i < state.size(); ++i) names[y[i]] = GiNaC::symbol(state[i]);
  for (size_t a = 0; a < z.size(); ++a) names[z[a]] = GiNaC::symbol(delayed_name(a));
  for (size_t k = 0; k < parameters.size(); ++k) names[p[k]] = GiNaC::symbol(parameters[k]);
  return e.subs(names);
}

std::vector<std::string> terms_not_finite(const SymbolicEquationModel& model, double t, const std::vector<double>& y,
                                          const std::vector<double>& y_tau, const std::vector<double>& p) {
  GiNaC::lst at{model.t == GiNaC::numeric(t)};
  for (size_t i = 0; i < model.y.size() && i < y.size(); ++i) at.append(model.y[i] == GiNaC::numeric(y[i]));
  for (size_t a = 0; a < model.z.size() && a < y_tau.size(); ++a) at.append(model.z[a] == GiNaC::numeric(y_tau[a]));
  for (size_t k = 0; k < model.p.size() && k < p.size(); ++k) at.append(model.p[k] == GiNaC::numeric(p[k]));
  // "" when e is a finite real number at the point, else what it is.
  auto not_finite = [&](const GiNaC::ex& e) -> std::string {
    try {
      const GiNaC::ex v = GiNaC::evalf(e.subs(at));
      if (!GiNaC::is_a<GiNaC::numeric>(v)) return "undefined";
      const GiNaC::numeric n = GiNaC::ex_to<GiNaC::numeric>(v);
      if (!n.is_real()) return "not a real number (" + text_of(v) + ")";
      const double x = n.to_double();
      return std::isfinite(x) ? "" : "not finite (" + format_number(x) + ")";
    } catch (const std::exception& e) {  // GiNaC's pole_error: 1/0, log(0), 0^(-2/3)
      return std::string("undefined (") + e.what() + ")";
    }
  };
  std::vector<std::string> found;
  for (const SymbolicField& field : model.fields) {
    for (size_t i = 0; i < field.f.size(); ++i) {
      std::string text = field.text[i];  // parsed, so printable; long ones cut
      if (text.size() > 120) text.replace(100, std::string::npos, "...");
      std::string item = "`";
      item.append(item_of(field.entry, i)).append(" = \"").append(text).append("\"`");
      if (const std::string why = not_finite(field.f[i]); !why.empty()) {
        found.push_back(item + " is " + why);
        continue;
      }
      for (const auto* derivatives : {&field.A, &field.B})
        for (size_t a = 0; a < derivatives->at(i).size(); ++a) {
          const GiNaC::ex& e = derivatives->at(i)[a];
          if (const std::string why = not_finite(e); !why.empty())
            found.push_back(item + ": its derivative by " +
                            (derivatives == &field.B ? model.delayed_name(a) : model.state[a]) + ", " +
                            text_of(model.display(e)) + ", is " + why);
        }
    }
  }
  return found;
}

SymbolicEquationModel analyse_equations(const toml::table& equations, const std::vector<std::string>& reserved_keys) {
  return EquationsReader(equations, reserved_keys).read();
}

}  // namespace delayspec::cli
