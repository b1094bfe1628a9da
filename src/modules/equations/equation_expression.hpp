#pragma once
// One expression string of a scene's [equations] table (a right-hand side, the switch, the
// period, ...) read into a GiNaC expression.
//
// The text is first checked by a small tokenizer and grammar of our own, which knows the position
// of every token: allowed characters, numbers, names (each must be allowed in this expression),
// function calls (the whitelist of equation_functions(), one argument), operators + - * / ^ and
// parentheses. It also refuses what GiNaC's parser reads differently from the usual convention:
// a sign after an operator (GiNaC reads `2^-1+3` as 2^(-(1+3))) or a second sign (`- -x`), and
// a chain `a^b^c`. Only then does GiNaC's parser (ginac/parser.h, strict) see the tokens, with
// every name and number replaced by a generated key of its symbol table: a number becomes its
// exact rational value (0.01 is 1/100, so symbolic identities such as the continuity check of a
// switch hold exactly), a name its symbol. Nothing of the text itself reaches GiNaC as a name.
#include <map>
#include <string>

#include <ginac/ginac.h>

namespace delayspec::cli {

// What the names of one expression mean.
struct ExpressionScope {
  std::map<std::string, GiNaC::ex> names;        // allowed here: name -> its symbol (or constant)
  std::map<std::string, std::string> elsewhere;  // known names not allowed here -> why, for the message
};

// The expression `text` of the item `item` (e.g. "equations.rhs[2]"), parsed and evaluated by
// GiNaC (real-valued: a complex constant such as sqrt(-1) is refused). BadInput
// "`item`: ... at position N of "text"" for every error (positions count characters from 1).
// Not thread-safe (GiNaC is not).
GiNaC::ex parse_equation_expression(const std::string& item, const std::string& text, const ExpressionScope& scope);

}  // namespace delayspec::cli
