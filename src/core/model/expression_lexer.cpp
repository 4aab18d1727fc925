// Splitting expression text into tokens with their 1-based columns.
#include "model/expression_lexer.hpp"

#include <cctype>
#include <cmath>
#include <cstdlib>

#include "amytiss/errors.hpp"

namespace amytiss::detail {

std::string describe(const Token& token) {
  switch (token.kind) {
    case TokenKind::End: return "the end of the expression";
    case TokenKind::Number: return "number " + token.text;
    case TokenKind::Identifier: return "'" + token.text + "'";
    default: return "'" + token.text + "'";
  }
}

std::vector<Token> tokenize(const std::string& text) {
  std::vector<Token> tokens;
  std::size_t i = 0;
  while (i < text.size()) {
    const char c = text[i];
    if (std::isspace(static_cast<unsigned char>(c))) {
      ++i;
      continue;
    }
    Token token;
    token.column = i + 1;
    if (std::isdigit(static_cast<unsigned char>(c)) ||
        (c == '.' && i + 1 < text.size() && std::isdigit(static_cast<unsigned char>(text[i + 1])))) {
      std::size_t j = i;
      while (j < text.size() && std::isdigit(static_cast<unsigned char>(text[j]))) ++j;
      if (j < text.size() && text[j] == '.') {
        ++j;
        while (j < text.size() && std::isdigit(static_cast<unsigned char>(text[j]))) ++j;
      }
      if (j < text.size() && (text[j] == 'e' || text[j] == 'E')) {
        std::size_t k = j + 1;
        if (k < text.size() && (text[k] == '+' || text[k] == '-')) ++k;
        if (k >= text.size() || !std::isdigit(static_cast<unsigned char>(text[k])))
          throw ParseError(k + 1, "expected digits of the exponent in number '" +
                                      text.substr(i, k - i) + "'");
        while (k < text.size() && std::isdigit(static_cast<unsigned char>(text[k]))) ++k;
        j = k;
      }
      token.kind = TokenKind::Number;
      token.text = text.substr(i, j - i);
      token.number = std::strtod(token.text.c_str(), nullptr);
      if (!std::isfinite(token.number))
        throw ParseError(token.column, "number " + token.text + " is out of the double range");
      i = j;
    } else if (std::isalpha(static_cast<unsigned char>(c)) || c == '_') {
      std::size_t j = i;
      while (j < text.size() && (std::isalnum(static_cast<unsigned char>(text[j])) || text[j] == '_')) ++j;
      token.kind = TokenKind::Identifier;
      token.text = text.substr(i, j - i);
      i = j;
    } else {
      static const char* const kTwoCharOperators[] = {"<=", ">=", "==", "!=", "&&", "||"};
      token.kind = TokenKind::Operator;
      for (const char* op : kTwoCharOperators)
        if (text.compare(i, 2, op) == 0) token.text = op;
      if (token.text.empty()) {
        if (std::string("+-*/^()<>,?:!").find(c) == std::string::npos) {
          std::string hint;
          if (c == '=') hint = " (did you mean '=='?)";
          if (c == '&') hint = " (did you mean '&&'?)";
          if (c == '|') hint = " (did you mean '||'?)";
          // Reported only when the parser reaches it, so earlier errors come first.
          token.kind = TokenKind::Invalid;
          token.text = "unexpected character '" + std::string(1, c) + "'" + hint;
          tokens.push_back(token);
          ++i;
          continue;
        }
        token.text = std::string(1, c);
      }
      i += token.text.size();
    }
    tokens.push_back(token);
  }
  Token end;
  end.column = text.size() + 1;
  tokens.push_back(end);
  return tokens;
}

}  // namespace amytiss::detail
