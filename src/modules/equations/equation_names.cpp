#include "modules/equations/equation_names.hpp"

#include <algorithm>
#include <array>
#include <cstdio>
#include <string_view>

#include "delayspec/errors.hpp"

namespace delayspec::cli {

namespace {

// C++20 keywords, alternative tokens and identifiers with special meaning ([lex.key], [lex.digraph],
// [lex.name]: final, override, import, module).
constexpr std::array<std::string_view, 97> kCppWords = {
    "alignas",     "alignof",   "and",        "and_eq",    "asm",      "auto",         "bitand",
    "bitor",       "bool",      "break",      "case",      "catch",    "char",         "char8_t",
    "char16_t",    "char32_t",  "class",      "compl",     "concept",  "const",        "consteval",
    "constexpr",   "constinit", "const_cast", "continue",  "co_await", "co_return",    "co_yield",
    "decltype",    "default",   "delete",     "do",        "double",   "dynamic_cast", "else",
    "enum",        "explicit",  "export",     "extern",    "false",    "float",        "for",
    "friend",      "goto",      "if",         "inline",    "int",      "long",         "mutable",
    "namespace",   "new",       "noexcept",   "not",       "not_eq",   "nullptr",      "operator",
    "or",          "or_eq",     "private",    "protected", "public",   "register",     "reinterpret_cast",
    "requires",    "return",    "short",      "signed",    "sizeof",   "static",       "static_assert",
    "static_cast", "struct",    "switch",     "template",  "this",     "thread_local", "throw",
    "true",        "try",       "typedef",    "typeid",    "typename", "union",        "unsigned",
    "using",       "virtual",   "void",       "volatile",  "wchar_t",  "while",        "xor",
    "xor_eq",      "final",     "override",   "import",    "module",   "_Pragma"};

// GiNaC's parser reads these as constants whatever its symbol table says (I is the imaginary unit).
constexpr std::array<std::string_view, 4> kGinacLiterals = {"I", "Pi", "Euler", "Catalan"};

bool is_plain_identifier(const std::string& name) {
  if (name.empty() || !((name[0] >= 'A' && name[0] <= 'Z') || (name[0] >= 'a' && name[0] <= 'z'))) return false;
  return std::all_of(name.begin(), name.end(), [](char c) {
    return (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_';
  });
}

template <size_t N>
bool among(const std::array<std::string_view, N>& words, const std::string& name) {
  return std::find(words.begin(), words.end(), name) != words.end();
}

}  // namespace

const std::vector<std::string>& equation_functions() {
  static const std::vector<std::string> functions = {"sin",  "cos",  "tan",  "asin", "acos", "atan",
                                                     "sinh", "cosh", "tanh", "exp",  "log",  "sqrt"};
  return functions;
}

void check_equation_name(const std::string& item, const std::string& name) {
  const std::string head = "`" + item + "`: `" + printable(name) + "` ";
  if (!is_plain_identifier(name)) throw BadInput(head + "is not a plain name (a letter, then letters, digits or _)");
  if (name.find("__") != std::string::npos) throw BadInput(head + "is a reserved C++ name (contains __)");
  if (among(kCppWords, name)) throw BadInput(head + "is a C++ keyword");
  if (name == "t" || name == "pi") throw BadInput(head + "is reserved: the expressions' time or pi");
  if (among(kGinacLiterals, name)) throw BadInput(head + "is reserved (a constant of the expression parser)");
  const auto& functions = equation_functions();
  if (std::find(functions.begin(), functions.end(), name) != functions.end())
    throw BadInput(head + "is a function of the expressions");
  if (name.size() >= 4 && name.compare(name.size() - 4, 4, "_tau") == 0)
    throw BadInput(head + "ends in _tau (NAME_tau is the state NAME at t - tau)");
}

}  // namespace delayspec::cli
