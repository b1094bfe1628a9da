#include "equation_cxx_printer.hpp"

#include <algorithm>
#include <iostream>
#include <sstream>
#include <vector>

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
    if (text.empty())
      text = term;
    else if (term[0] == '-')
      text += " - " + term.substr(1);
    else
      text += " + " + term;
  }
  if (level >= kSumPrecedence) {
    c.s << "(" << text << ")";
  } else {
    c.s << text;
  }
}

// Whether the sum's first term, in the order of the terms' texts without a leading minus, has
// a minus: GiNaC stores k (z - y) as k (z - y) or as -k (y - z) depending on the run, and the
// product is printed with the sum's sign so that this first term is positive.
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

// A factor of a product in that sign convention: a sum, or a sum to an integer power, with its
// sign turned if it leads with a minus; `negate` flips when the factor's sign did.
GiNaC::ex sign_normal_factor(const GiNaC::ex& factor, bool& negate) {
  if (GiNaC::is_a<GiNaC::add>(factor) && leads_with_minus(factor)) {
    negate = !negate;
    return -factor;
  }
  if (GiNaC::is_a<GiNaC::power>(factor) && GiNaC::is_a<GiNaC::add>(factor.op(0)) &&
      GiNaC::is_a<GiNaC::numeric>(factor.op(1)) && GiNaC::ex_to<GiNaC::numeric>(factor.op(1)).is_integer() &&
      leads_with_minus(factor.op(0))) {
    if (GiNaC::ex_to<GiNaC::numeric>(factor.op(1)).is_odd()) negate = !negate;
    return GiNaC::pow(-factor.op(0), factor.op(1));
  }
  return factor;
}

bool negative_integer_power(const GiNaC::ex& e) {
  return GiNaC::is_a<GiNaC::power>(e) && GiNaC::is_a<GiNaC::numeric>(e.op(1)) &&
         GiNaC::ex_to<GiNaC::numeric>(e.op(1)).is_integer() && GiNaC::ex_to<GiNaC::numeric>(e.op(1)).is_negative();
}

std::string joined(std::vector<std::string> factors) {
  std::sort(factors.begin(), factors.end());
  std::string text;
  for (const auto& factor : factors) text += (text.empty() ? "" : "*") + factor;
  return text;
}

// A product: numerator / denominator (the factors with a negative integer exponent), each the
// numeric coefficient first and then the other factors (sign-normal, above) sorted by text:
// 2 pi / omega prints 2.0*pi_/p[4], computed as the built-in models compute it.
void print_product(const GiNaC::mul& product, const print_sorted_csrc& c, unsigned level) {
  GiNaC::numeric coefficient = 1;
  bool negate = false;
  std::vector<std::string> numerator, denominator;
  for (size_t i = 0; i < product.nops(); ++i) {
    if (GiNaC::is_a<GiNaC::numeric>(product.op(i))) {
      coefficient *= GiNaC::ex_to<GiNaC::numeric>(product.op(i));
      continue;
    }
    const GiNaC::ex factor = sign_normal_factor(product.op(i), negate);
    if (negative_integer_power(factor)) {
      denominator.push_back(text_at(GiNaC::pow(factor.op(0), -factor.op(1)), kProductPrecedence));
    } else {
      numerator.push_back(text_at(factor, kProductPrecedence));
    }
  }
  if (negate) coefficient = -coefficient;
  std::string text = joined(numerator);
  if (text.empty()) {
    text = text_at(coefficient, kProductPrecedence);
  } else if (coefficient == -1) {
    text = "-" + text;
  } else if (coefficient != 1) {
    text = text_at(coefficient, kProductPrecedence) + "*" + text;
  }
  if (!denominator.empty())
    text += denominator.size() == 1 ? "/" + denominator[0] : "/(" + joined(denominator) + ")";
  if (level >= kProductPrecedence) {  // the base of a power
    c.s << "(" << text << ")";
  } else {
    c.s << text;
  }
}

void register_printers() {
  static const bool registered = [] {
    GiNaC::set_print_func<GiNaC::add, print_sorted_csrc>(print_sum);
    GiNaC::set_print_func<GiNaC::mul, print_sorted_csrc>(print_product);
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
