#include "modules/equations/equation_cxx_printer.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <sstream>
#include <vector>

#include "delayspec/errors.hpp"

namespace delayspec::cli {

// print_csrc_double whose sums and products print sorted (the print functions registered below).
// GiNaC finds a context's parent by the name given to GINAC_IMPLEMENT_PRINT_CONTEXT: the
// unqualified name, as GiNaC registers its own.
using GiNaC::print_csrc_double;
class print_sorted_csrc : public print_csrc_double {
  GINAC_DECLARE_PRINT_CONTEXT(print_sorted_csrc, print_csrc_double)
 public:
  explicit print_sorted_csrc(std::ostream& os, unsigned opt = 0) : print_csrc_double(os, opt) {}
};
print_sorted_csrc::print_sorted_csrc() : print_csrc_double(std::cout) {}  // the registry's
GINAC_IMPLEMENT_PRINT_CONTEXT(print_sorted_csrc, print_csrc_double)

namespace {

// GiNaC's operator precedences (add.h, mul.h; public as sum.precedence(), not as constants).
constexpr unsigned kSumPrecedence = 40;
constexpr unsigned kProductPrecedence = 50;
constexpr unsigned kPowerPrecedence = 60;

std::string text_at(const GiNaC::ex& e, unsigned level) {
  std::ostringstream out;
  print_sorted_csrc context(out);
  e.print(context, level);
  return out.str();
}

// A sum: its terms sorted, a term's leading minus sign written as subtraction (a + (-b) and
// a - b are the same double). Parenthesised where an operator binds tighter (level = the
// precedence of the enclosing product or power; a function argument's level is lower).
void print_sum(const GiNaC::add& sum, const print_sorted_csrc& c, unsigned level) {
  std::vector<std::string> terms;
  for (size_t i = 0; i < sum.nops(); ++i) terms.push_back(text_at(sum.op(i), 0));
  std::sort(terms.begin(), terms.end());
  std::string text;
  for (const auto& term : terms) {
    if (text.empty()) text = term;
    else if (term[0] == '-') text += " - " + term.substr(1);
    else text += " + " + term;
  }
  if (level >= kSumPrecedence) {
    c.s << "(" << text << ")";
  } else {
    c.s << text;
  }
}

// Whether the sum's first term, in the order of the terms' texts without a leading minus, has
// a minus. GiNaC stores k (z - y) as k (z - y) or as -k (y - z), and (x - e)^3 as (x - e)^3 or
// -(e - x)^3, depending on the run: a sum is printed as a factor with the sign that makes this
// first term positive, the sign moved to the product's coefficient.
bool leads_with_minus(const GiNaC::ex& sum) {
  std::string first;
  bool minus = false;
  for (size_t i = 0; i < sum.nops(); ++i) {
    const std::string text = text_at(sum.op(i), 0);
    const bool negative = !text.empty() && text[0] == '-';
    const std::string magnitude = negative ? text.substr(1) : text;
    if (i == 0 || magnitude < first) {
      first = magnitude;
      minus = negative;
    }
  }
  return minus;
}

// base^n for an integer n >= 1, base already printed as a factor: a product for small n (the
// compiler turns pow with a large exponent into a library call), else pow.
constexpr long kMaxPowerAsProduct = 8;
std::string integer_power_text(const std::string& base, const GiNaC::numeric& n) {
  if (n == 1) return base;
  if (n > kMaxPowerAsProduct) return "pow(" + base + ", " + text_at(n, 0) + ")";
  std::string text = base;
  for (long i = 1; i < n.to_long(); ++i) text += "*" + base;
  return "(" + text + ")";
}

// One factor of a product: its text, whether it belongs to the denominator (a negative integer
// power, printed with the positive exponent), whether its sign was turned (leads_with_minus).
struct Factor {
  std::string text;
  bool denominator = false;
  bool negated = false;
};

Factor factor_of(const GiNaC::ex& f) {
  Factor factor;
  GiNaC::ex base = f;
  GiNaC::numeric n = 1;
  if (GiNaC::is_a<GiNaC::power>(f) && GiNaC::is_a<GiNaC::numeric>(f.op(1)) &&
      GiNaC::ex_to<GiNaC::numeric>(f.op(1)).is_integer()) {
    base = f.op(0);
    n = GiNaC::ex_to<GiNaC::numeric>(f.op(1));
  } else if (!GiNaC::is_a<GiNaC::add>(f)) {
    factor.text = text_at(f, kProductPrecedence);
    return factor;
  }
  std::string base_text;
  if (GiNaC::is_a<GiNaC::add>(base) && leads_with_minus(base)) {
    base_text = text_at(-base, kPowerPrecedence);  // -1 * sum is the sum of the negated terms
    factor.negated = n.is_odd();
  } else {
    base_text = text_at(base, kPowerPrecedence);
  }
  factor.denominator = n.is_negative();
  factor.text = integer_power_text(base_text, n.is_negative() ? -n : n);
  return factor;
}

std::string joined(std::vector<std::string> factors) {
  std::sort(factors.begin(), factors.end());
  std::string text;
  for (const auto& factor : factors) text += (text.empty() ? "" : "*") + factor;
  return text;
}

// coefficient * factors as numerator / denominator, each the coefficient first and then the
// factors sorted by text: 2 pi / omega prints 2.0*pi_/p[4], computed as the built-in models do.
void print_factors(GiNaC::numeric coefficient, const std::vector<GiNaC::ex>& factors, const print_sorted_csrc& c,
                   unsigned level) {
  std::vector<std::string> numerator, denominator;
  for (const auto& f : factors) {
    const Factor factor = factor_of(f);
    if (factor.negated) coefficient = -coefficient;
    (factor.denominator ? denominator : numerator).push_back(factor.text);
  }
  std::string text = joined(numerator);
  if (text.empty()) {
    text = text_at(coefficient, 0);
  } else if (coefficient == -1) {
    text = "-" + text;
  } else if (coefficient != 1) {
    text = text_at(coefficient, 0) + "*" + text;
  }
  if (!denominator.empty()) text += denominator.size() == 1 ? "/" + denominator[0] : "/(" + joined(denominator) + ")";
  if (level >= kProductPrecedence) {  // the base of a power
    c.s << "(" << text << ")";
  } else {
    c.s << text;
  }
}

void print_product(const GiNaC::mul& product, const print_sorted_csrc& c, unsigned level) {
  GiNaC::numeric coefficient = 1;
  std::vector<GiNaC::ex> factors;
  for (size_t i = 0; i < product.nops(); ++i) {
    if (GiNaC::is_a<GiNaC::numeric>(product.op(i))) {
      coefficient *= GiNaC::ex_to<GiNaC::numeric>(product.op(i));
    } else {
      factors.push_back(product.op(i));
    }
  }
  print_factors(coefficient, factors, c, level);
}

// A power: an integer power as a product of one factor (above); sqrt for the exponent 1/2;
// else pow.
void print_power(const GiNaC::power& power, const print_sorted_csrc& c, unsigned level) {
  const GiNaC::ex base = power.op(0), exponent = power.op(1);
  if (GiNaC::is_a<GiNaC::numeric>(exponent) && GiNaC::ex_to<GiNaC::numeric>(exponent).is_integer()) {
    print_factors(1, {GiNaC::ex(power)}, c, level);
  } else if (exponent == GiNaC::numeric(1, 2)) {
    c.s << "sqrt(" << text_at(base, 0) << ")";
  } else if (exponent == GiNaC::numeric(-1, 2)) {
    c.s << (level >= kProductPrecedence ? "(1.0/sqrt(" : "1.0/sqrt(") << text_at(base, 0)
        << (level >= kProductPrecedence ? "))" : ")");
  } else {
    c.s << "pow(" << text_at(base, 0) << ", " << text_at(exponent, 0) << ")";
  }
}

// A number (always rational here: the expressions' numbers are exact): p.0 or (p.0/q.0) when p
// and q are doubles exactly (|p|, q <= 2^53: the division is then correctly rounded), else the
// double nearest to p/q (CLN's conversion) with 17 significant digits, which reads back as
// that double. A sign is written in front, never in parentheses (leads_with_minus reads it).
void print_number(const GiNaC::numeric& number, const print_sorted_csrc& c, unsigned) {
  const GiNaC::numeric exact_limit = GiNaC::numeric(2).power(53);
  const GiNaC::numeric p = GiNaC::abs(number.numer()), q = number.denom();
  const std::string sign = number.is_negative() ? "-" : "";
  if (number.is_rational() && p <= exact_limit && q <= exact_limit) {
    if (q == 1) {
      c.s << sign << p.to_long() << ".0";
    } else {
      c.s << sign << "(" << p.to_long() << ".0/" << q.to_long() << ".0)";
    }
    return;
  }
  const double value = number.to_double();
  if (!std::isfinite(value) || !number.is_real())
    throw BadInput("a constant of the model, " + format_number(value) + ", is not a finite real double");
  char text[40];
  std::snprintf(text, sizeof text, "%.17g", value);
  const std::string digits = text;
  c.s << digits << (digits.find_first_of(".e") == std::string::npos ? ".0" : "");
}

void register_printers() {
  static const bool registered = [] {
    GiNaC::set_print_func<GiNaC::add, print_sorted_csrc>(print_sum);
    GiNaC::set_print_func<GiNaC::mul, print_sorted_csrc>(print_product);
    GiNaC::set_print_func<GiNaC::power, print_sorted_csrc>(print_power);
    GiNaC::set_print_func<GiNaC::numeric, print_sorted_csrc>(print_number);
    return true;
  }();
  (void)registered;
}

}  // namespace

std::string cxx_text(const GiNaC::ex& e) {
  register_printers();
  return text_at(e, 0);
}

}  // namespace delayspec::cli
