#include "delayspec/errors.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <utility>

namespace delayspec {

std::string format_number(double value) {
  // The shortest text that reads back as the same double ("0.7", not "0.69999999999999996";
  // "10", not "1e+01"): exact, and what a person would have typed. Of the %.{1..17}g spellings
  // that read back exactly, the shortest (the first of equal length). to_chars with a precision is
  // %.*g and from_chars is strtod, both in the "C" locale, some ten times faster than snprintf and
  // strtod: every key read records its value in this spelling (Config), thousands per command.
  //
  // Not all 17 need trying. D, the fewest significant digits that read back, is the length of
  // to_chars' shortest scientific form (no %.Pg with P < D reads back). Of P >= D, within one
  // style of %g (exponent when the decimal exponent X < -4 or X >= P, fixed otherwise) no spelling
  // is shorter than one with fewer digits (%g strips trailing zeros, and a value whose P-digit
  // rounding strips to fewer digits rounds to those at fewer digits too), so the candidates are
  // P = D and the first fixed one, P = X + 1 ("150000" is shorter than "1.5e+05"). Where the
  // correctly rounded D digits do not read back (the shortest form may be rounded the other way
  // next to a power of two, where the gap below is half the gap above), every P is tried, as
  // before: the same text, its share of the lobe diagram's profile 1 % instead of 8 % (two
  // to_chars instead of 17, one from_chars instead of up to 17).
  if (!std::isfinite(value)) return format_number(value, 1);
  char buffer[64];
  std::string best;
  const auto try_digits = [&](int digits) {
    const auto written = std::to_chars(buffer, buffer + sizeof buffer, value, std::chars_format::general, digits);
    const auto length = static_cast<size_t>(written.ptr - buffer);
    if (!best.empty() && length >= best.size()) return;  // (no shorter: no need to read it back)
    double back = 0;
    std::from_chars(buffer, written.ptr, back);
    if (back == value) best.assign(buffer, length);
  };
  const auto shortest = std::to_chars(buffer, buffer + sizeof buffer, value, std::chars_format::scientific);
  int D = 0, X = 0;
  const char* p = buffer;
  for (; p < shortest.ptr && *p != 'e'; ++p) D += *p >= '0' && *p <= '9';
  if (p < shortest.ptr) std::from_chars(p + 1 + (p[1] == '+'), shortest.ptr, X);
  try_digits(D);
  if (!best.empty()) {
    if (X >= D && X + 1 <= 17) try_digits(X + 1);
    return best;
  }
  for (int digits = 1; digits <= 17; ++digits) try_digits(digits);
  return best;
}

std::string format_complex(std::complex<double> value) {
  return format_number(value.real()) + (value.imag() < 0 ? " - " : " + ") + format_number(std::abs(value.imag())) + "i";
}

std::string format_number(double value, int significant_digits) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, "%.*g", significant_digits, value);
  return buffer;
}

std::string format_text(const char* format, double a, double b, double c, double d) {
  const int n = std::max(std::snprintf(nullptr, 0, format, a, b, c, d), 0);
  std::string out(static_cast<size_t>(n) + 1, '\0');
  std::snprintf(out.data(), out.size(), format, a, b, c, d);
  out.resize(static_cast<size_t>(n));
  return out;
}

NonFiniteStep::NonFiniteStep(const std::string& what, std::vector<ModelPoint> points)
    : NumericalFailure(what), points_(std::move(points)) {}

std::string describe_point(const ModelPoint& point) {
  auto vector = [](const std::vector<double>& v) {
    std::string text = "(";
    for (size_t i = 0; i < v.size(); ++i) {
      if (i > 0) text += ", ";
      text += format_number(v[i]);
    }
    return text + ")";
  };
  return " at t = " + format_number(point.t) + ": y = " + vector(point.y) + ", y(t - tau) = " + vector(point.y_tau);
}

void require_finite(const char* name, double value) {
  if (!std::isfinite(value))
    throw BadInput(std::string("`") + name + " = " + format_number(value) + "`: must be a finite number");
}

void require_positive(const char* name, double value) {
  require_finite(name, value);
  if (!(value > 0)) throw BadInput(std::string("`") + name + " = " + format_number(value) + "`: must be > 0");
}

void require_nonnegative(const char* name, double value) {
  require_finite(name, value);
  if (!(value >= 0)) throw BadInput(std::string("`") + name + " = " + format_number(value) + "`: must be >= 0");
}

}  // namespace delayspec
