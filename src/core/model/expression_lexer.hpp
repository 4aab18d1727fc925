#pragma once
// Tokens of the expression grammar (include/amytiss/expression.hpp). Internal to the core.
#include <cstddef>
#include <string>
#include <vector>

namespace amytiss::detail {

enum class TokenKind { Number, Identifier, Operator, Invalid, End };

struct Token {
  TokenKind kind = TokenKind::End;
  std::string text;
  double number = 0.0;
  std::size_t column = 0;  // 1-based
};

/// "number 2.5", "'sin'", "the end of the expression": a token as messages name it.
std::string describe(const Token& token);
/// The tokens of `text`, ending with an End token. A malformed or out-of-range number throws
/// ParseError; an unknown character becomes an Invalid token that the parser reports when it
/// reaches it (so earlier errors come first).
std::vector<Token> tokenize(const std::string& text);

}  // namespace amytiss::detail
