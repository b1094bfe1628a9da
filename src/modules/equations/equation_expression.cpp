#include "modules/equations/equation_expression.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <optional>
#include <vector>

#include <ginac/parser.h>

#include "scene/keys/closest_key.hpp"
#include "delayspec/errors.hpp"
#include "modules/equations/equation_names.hpp"

namespace delayspec::cli {

namespace {

enum class TokenKind { number, name, op, open, close, comma };

struct Token {
  TokenKind kind;
  std::string text;
  size_t position;  // of its first character, from 1
};

// Numbers: at most this many digits, and a decimal exponent of the value within +-kMaxExponent
// (beyond the range of a double either way): bounds the exact rational GiNaC holds.
constexpr size_t kMaxDigits = 100;
constexpr long kMaxExponent = 400;
// Parentheses (and function calls) nested at most this deep, and at most this many tokens per
// expression. GiNaC's parser, its differentiation and its printer recurse once per level of
// nesting: 10 000 levels overflowed the stack (a crash where bad input is due, measured); no model
// written by hand comes near 100. The token bound keeps one expression to what compiles in seconds
// (the model's whole size is bounded again on the printed code, equation_model_source.cpp).
constexpr size_t kMaxNesting = 100;
constexpr size_t kMaxTokens = 20000;
// A constant raised to a constant power is evaluated exactly by GiNaC: 11^10000 has 10 414 digits
// (milliseconds); 11^1e308 cannot be held (check_powers).
constexpr int kMaxConstantExponent = 10000;

bool is_letter(char c) { return (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z'); }
bool is_digit(char c) { return c >= '0' && c <= '9'; }
bool is_space(char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r'; }

bool has_symbol(const GiNaC::ex& e) {
  return std::any_of(e.preorder_begin(), e.preorder_end(),
                     [](const GiNaC::ex& x) { return GiNaC::is_a<GiNaC::symbol>(x); });
}

std::string first_line(const std::string& text) { return text.substr(0, text.find('\n')); }

class ExpressionReader {
 public:
  ExpressionReader(const std::string& item, const std::string& text, const ExpressionScope& scope)
      : item_(item), text_(text), scope_(scope) {}

  GiNaC::ex read() {
    tokenize();
    check_grammar();  // before the size: deep nesting gets its own message
    if (tokens_.size() > kMaxTokens)
      fail(tokens_[kMaxTokens].position, "more than " + std::to_string(kMaxTokens) + " numbers, names and operators",
           "a model this large compiles for minutes; split it or simplify it");
    return parse();
  }

 private:
  [[noreturn]] void fail(size_t position, const std::string& problem, const std::string& hint = "") const {
    throw BadInput("`" + item_ + "`: " + problem + " at position " + std::to_string(position) + " of \"" +
                   excerpt(position) + "\"" + (hint.empty() ? "" : " (" + hint + ")"));
  }
  [[noreturn]] void fail_whole(const std::string& problem) const {
    throw BadInput("`" + item_ + "`: \"" + excerpt(1) + "\" " + problem);
  }

  // The expression as a message shows it: whole when short, else the part around `position`.
  std::string excerpt(size_t position) const {
    constexpr size_t kBefore = 60, kAfter = 40;
    if (text_.size() <= kBefore + kAfter) return printable(text_);
    const size_t from = position > kBefore ? position - kBefore : 0;
    const size_t to = std::min(text_.size(), std::max(position, from) + kAfter);
    return (from > 0 ? "..." : "") + printable(text_.substr(from, to - from)) + (to < text_.size() ? "..." : "");
  }

  [[noreturn]] void fail_nesting(size_t position) const {
    fail(position, "parentheses nested more than " + std::to_string(kMaxNesting) + " deep",
         "the limit of delayspec's expression reader");
  }

  // Number: digits [. digits] [e|E [+|-] digits], or . digits [exponent].
  size_t scan_number(size_t i) const {
    while (i < text_.size() && is_digit(text_[i])) ++i;
    if (i < text_.size() && text_[i] == '.') {
      ++i;
      while (i < text_.size() && is_digit(text_[i])) ++i;
    }
    if (i < text_.size() && (text_[i] == 'e' || text_[i] == 'E')) {
      size_t j = i + 1;
      if (j < text_.size() && (text_[j] == '+' || text_[j] == '-')) ++j;
      if (j < text_.size() && is_digit(text_[j])) {
        i = j;
        while (i < text_.size() && is_digit(text_[i])) ++i;
      }
    }
    return i;
  }

  void tokenize() {
    for (size_t i = 0; i < text_.size();) {
      const char c = text_[i];
      const size_t position = i + 1;
      if (is_space(c)) {
        ++i;
      } else if (is_digit(c) || (c == '.' && i + 1 < text_.size() && is_digit(text_[i + 1]))) {
        const size_t end = scan_number(i);
        tokens_.push_back({TokenKind::number, text_.substr(i, end - i), position});
        i = end;
      } else if (is_letter(c) || c == '_') {
        size_t end = i;
        while (end < text_.size() && (is_letter(text_[end]) || is_digit(text_[end]) || text_[end] == '_')) ++end;
        tokens_.push_back({TokenKind::name, text_.substr(i, end - i), position});
        i = end;
      } else if (c == '+' || c == '-' || c == '*' || c == '/' || c == '^') {
        tokens_.push_back({TokenKind::op, std::string(1, c), position});
        ++i;
      } else if (c == '(' || c == ')' || c == ',') {
        tokens_.push_back({c == '('   ? TokenKind::open
                           : c == ')' ? TokenKind::close
                                      : TokenKind::comma,
                           std::string(1, c), position});
        ++i;
      } else {
        fail(position, "unexpected character `" + printable(std::string(1, c)) + "`",
             "expressions use numbers, names, + - * / ^, ( ) and the functions");
      }
    }
  }

  bool is_function_call(size_t k) const {
    return tokens_[k].kind == TokenKind::name && k + 1 < tokens_.size() && tokens_[k + 1].kind == TokenKind::open;
  }

  void check_name(const Token& token) const {
    const auto& functions = equation_functions();
    if (std::find(functions.begin(), functions.end(), token.text) != functions.end())
      fail(token.position, "function `" + token.text + "` without an argument", "write " + token.text + "(...)");
    if (scope_.names.count(token.text)) return;
    if (auto why = scope_.elsewhere.find(token.text); why != scope_.elsewhere.end())
      fail(token.position, "`" + token.text + "` is " + why->second);
    std::vector<std::string> known;
    for (const auto& [name, value] : scope_.names) known.push_back(name);
    const std::string suggestion = closest_key(token.text, known);
    fail(token.position, "unknown name `" + printable(token.text) + "`",
         suggestion.empty() ? "" : "did you mean `" + suggestion + "`?");
  }

  void check_function(const Token& token) const {
    const auto& functions = equation_functions();
    if (std::find(functions.begin(), functions.end(), token.text) != functions.end()) return;
    if (scope_.names.count(token.text) || scope_.elsewhere.count(token.text))
      fail(token.position, "`" + token.text + "` is not a function", "write * for a product");
    std::string allowed;
    for (const auto& f : functions) allowed += (allowed.empty() ? "" : ", ") + f;
    fail(token.position, "function `" + printable(token.text) + "` is not allowed",
         "allowed: " + allowed + "; ^ for powers");
  }

  // operand := number | name | function '(' expression ')' | '(' expression ')'
  // expression := [sign] operand (binary-operator operand)*, a sign only at the start of the
  // whole expression or right after '(' (see the header), no a^b^c.
  void check_grammar() {
    if (tokens_.empty()) fail_whole("is empty");
    bool expect_operand = true;
    std::vector<size_t> open;         // positions of the open parentheses
    std::vector<char> last_operator;  // the last binary operator at each depth (0: none yet)
    last_operator.push_back(0);
    for (size_t k = 0; k < tokens_.size(); ++k) {
      const Token& token = tokens_[k];
      if (expect_operand) {
        switch (token.kind) {
          case TokenKind::number:
          case TokenKind::name:
            if (is_function_call(k)) {
              check_function(token);
              if (open.size() >= kMaxNesting) fail_nesting(tokens_[k + 1].position);
              open.push_back(tokens_[k + 1].position);
              last_operator.push_back(0);
              ++k;  // the '('
            } else {
              if (token.kind == TokenKind::name) check_name(token);
              expect_operand = false;
            }
            break;
          case TokenKind::open:
            if (open.size() >= kMaxNesting) fail_nesting(token.position);
            open.push_back(token.position);
            last_operator.push_back(0);
            break;
          case TokenKind::op: {
            if (token.text != "+" && token.text != "-")
              fail(token.position, "expected a number, a name or ( but found `" + token.text + "`");
            const bool at_start = k == 0 || tokens_[k - 1].kind == TokenKind::open;
            if (!at_start)
              fail(token.position, "a sign `" + token.text + "` after an operator",
                   "a sign may only start the expression or follow (: write x*(-y)");
            if (k + 1 < tokens_.size() && tokens_[k + 1].kind == TokenKind::op)
              fail(tokens_[k + 1].position, "a second sign or operator `" + tokens_[k + 1].text + "`");
            break;
          }
          case TokenKind::close:
          case TokenKind::comma: fail(token.position, "expected a number, a name or ( but found `" + token.text + "`");
        }
      } else {
        switch (token.kind) {
          case TokenKind::op:
            if (token.text == "^" && last_operator.back() == '^')
              fail(token.position, "a chain of powers", "write a^(b^c) or (a^b)^c");
            last_operator.back() = token.text[0];
            expect_operand = true;
            break;
          case TokenKind::close:
            if (open.empty()) fail(token.position, "`)` without a matching `(`");
            open.pop_back();
            last_operator.pop_back();
            break;
          case TokenKind::comma: fail(token.position, "`,`", "the functions take one argument");
          case TokenKind::number:
          case TokenKind::name:
          case TokenKind::open: fail(token.position, "missing operator before `" + printable(token.text) + "`");
        }
      }
    }
    if (expect_operand) fail(text_.size() + 1, "the expression ends after `" + tokens_.back().text + "`");
    if (!open.empty()) fail(open.back(), "`(` is not closed");
  }

  // The exact rational value of a number token (checked by scan_number): mantissa * 10^exponent.
  GiNaC::ex number_value(const Token& token) const {
    std::string digits;
    long exponent = 0;
    size_t i = 0;
    const std::string& s = token.text;
    for (; i < s.size() && is_digit(s[i]); ++i) digits += s[i];
    if (i < s.size() && s[i] == '.')
      for (++i; i < s.size() && is_digit(s[i]); ++i, --exponent) digits += s[i];
    if (i < s.size()) {  // exponent part
      ++i;
      const bool negative = s[i] == '-';
      if (s[i] == '+' || s[i] == '-') ++i;
      const std::string e = s.substr(i);
      if (e.size() > 6) fail(token.position, "number `" + s + "` out of range");
      exponent += negative ? -std::stol(e) : std::stol(e);
    }
    digits.erase(0, std::min(digits.find_first_not_of('0'), digits.size()));
    if (digits.empty()) return GiNaC::numeric(0);
    if (digits.size() > kMaxDigits || std::abs(exponent + static_cast<long>(digits.size())) > kMaxExponent)
      fail(token.position, "number `" + s + "` out of range");
    const GiNaC::numeric mantissa(digits.c_str());
    return mantissa * GiNaC::numeric(10).power(GiNaC::numeric(exponent));
  }

  // GiNaC's input: the tokens, each name and number replaced by a generated key of the symbol
  // table (n0, n1, ...), functions by their (whitelisted) names.
  GiNaC::ex parse() {
    GiNaC::symtab table;
    GiNaC::exmap exact_numbers, approximate_numbers;
    std::map<std::string, std::string> key_of_name;
    std::string input;
    for (size_t k = 0; k < tokens_.size(); ++k) {
      const Token& token = tokens_[k];
      if (token.kind == TokenKind::number || (token.kind == TokenKind::name && !is_function_call(k))) {
        std::string key;
        if (token.kind == TokenKind::name && key_of_name.count(token.text)) {
          key = key_of_name[token.text];
        } else {
          key = "n";
          key += std::to_string(table.size());  // (not "n" + ...: a false -Wrestrict of GCC 12)
          if (token.kind == TokenKind::number) {
            // A number is a placeholder symbol until the powers are checked (check_powers).
            const GiNaC::symbol placeholder(key);
            const GiNaC::ex exact = number_value(token);
            exact_numbers[placeholder] = exact;
            approximate_numbers[placeholder] = GiNaC::evalf(exact);
            table[key] = placeholder;
          } else {
            table[key] = scope_.names.at(token.text);
            key_of_name[token.text] = key;
          }
        }
        input += key;
      } else {
        input += token.text;
      }
      input += ' ';
    }
    GiNaC::ex value;
    try {
      GiNaC::parser parser(table, true, function_table());
      value = parser(input);
      check_powers(value, approximate_numbers);
      value = value.subs(exact_numbers);
    } catch (const BadInput&) {
      throw;
    } catch (const GiNaC::parse_error& e) {
      fail_whole("cannot be parsed: " + first_line(e.what()));
    } catch (const std::exception& e) {  // GiNaC's evaluation: 1/0, log(0), tan(pi/2) (pole_error)
      fail_whole("cannot be evaluated: " + first_line(e.what()));
    }
    // Complex constants: I (sqrt(-1)) or a constant function or power that GiNaC keeps
    // unevaluated but whose value is complex (log(-2), asin(2), (-8)^(1/3)): C++ would compute NaN.
    for (auto it = value.preorder_begin(); it != value.preorder_end(); ++it) {
      bool complex = GiNaC::is_a<GiNaC::numeric>(*it) && !GiNaC::ex_to<GiNaC::numeric>(*it).is_real();
      if ((GiNaC::is_a<GiNaC::function>(*it) || GiNaC::is_a<GiNaC::power>(*it)) && !has_symbol(*it)) {
        GiNaC::ex number;
        try {
          number = GiNaC::evalf(*it);
        } catch (const std::exception& e) {
          fail_whole("cannot be evaluated: " + first_line(e.what()));
        }
        complex = !GiNaC::is_a<GiNaC::numeric>(number) || !GiNaC::ex_to<GiNaC::numeric>(number).is_real();
      }
      if (complex) fail_whole("has a complex value (e.g. sqrt or log of a negative number, asin(2))");
      if (GiNaC::is_a<GiNaC::numeric>(*it) && !std::isfinite(GiNaC::ex_to<GiNaC::numeric>(*it).to_double()))
        fail_whole("has a number beyond the range of a double");
    }
    return value;
  }

  // GiNaC raises a number to a number exactly: 11^1e308 asked GMP for more memory than there is
  // (an abort, or 24 GB before the kernel killed the process; found by the fuzz driver). So the
  // expression is first parsed with its numbers as placeholder symbols, and every power whose base
  // is a constant must have an exponent, evaluated in floating point (`approximate` gives each
  // placeholder its value as a float), of at most kMaxConstantExponent in magnitude. A power of a
  // variable (x^1e308) is never evaluated exactly and is left to the compiled code.
  void check_powers(const GiNaC::ex& value, const GiNaC::exmap& approximate) const {
    for (auto it = value.preorder_begin(); it != value.preorder_end(); ++it) {
      if (!GiNaC::is_a<GiNaC::power>(*it)) continue;
      const GiNaC::ex base = it->op(0).subs(approximate), exponent = it->op(1).subs(approximate);
      if (has_symbol(base) || has_symbol(exponent)) continue;
      bool too_large = true;
      try {
        const GiNaC::ex e = GiNaC::evalf(exponent);
        too_large = !GiNaC::is_a<GiNaC::numeric>(e) || !GiNaC::ex_to<GiNaC::numeric>(e).is_real() ||
                    GiNaC::abs(GiNaC::ex_to<GiNaC::numeric>(e)) > kMaxConstantExponent;
      } catch (const std::exception&) {  // the exponent itself overflows
      }
      if (too_large)
        fail_whole("raises a constant to a power beyond " + std::to_string(kMaxConstantExponent) +
                   " in magnitude, which is evaluated exactly (write a smaller power, or its value)");
    }
  }

  // The whitelisted functions of GiNaC's default reader (one argument each).
  static const GiNaC::prototype_table& function_table() {
    static const GiNaC::prototype_table table = [] {
      GiNaC::prototype_table t;
      const auto& functions = equation_functions();
      for (const auto& [prototype, reader] : GiNaC::get_default_reader())
        if (prototype.second == 1 && std::find(functions.begin(), functions.end(), prototype.first) != functions.end())
          t.insert({prototype, reader});
      return t;
    }();
    return table;
  }

  const std::string& item_;
  const std::string& text_;
  const ExpressionScope& scope_;
  std::vector<Token> tokens_;
};

}  // namespace

GiNaC::ex parse_equation_expression(const std::string& item, const std::string& text, const ExpressionScope& scope) {
  return ExpressionReader(item, text, scope).read();
}

}  // namespace delayspec::cli
