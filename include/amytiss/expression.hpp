#pragma once
// Dynamics expressions (docs/configuration.md): a whitelisted grammar, evaluated in C++ and emitted as
// OpenCL C. Nothing outside the grammar is accepted, so no parameter text reaches a compiler.
//
// Grammar (precedence low to high):
//   expr    := cond
//   cond    := or ( '?' expr ':' expr )?
//   or      := and ( '||' and )*
//   and     := cmp ( '&&' cmp )*
//   cmp     := sum ( ('<' | '<=' | '>' | '>=' | '==' | '!=') sum )?
//   sum     := product ( ('+' | '-') product )*
//   product := unary ( ('*' | '/') unary )*
//   unary   := ('-' | '+' | '!') unary | power
//   power   := atom ( '^' unary )?            (right-associative: 2^3^2 = 2^9)
//   atom    := number | variable | constant | function '(' expr (',' expr)* ')' | '(' expr ')'
// Variables: x0.., u0.., w0.. (state, input, disturbance components); in a noise density only z. Constants: names given to
// parse() (and pi). Functions: sin cos tan asin acos atan atan2 exp log sqrt pow abs min max floor
// ceil, plus if(cond, a, b). Comparisons and logic give 1 or 0. Also: `cond ? a : b`.
#include <cstddef>
#include <map>
#include <memory>
#include <string>
#include <vector>

namespace amytiss {

/// Limits of one expression; beyond them parse() throws a ParseError that names the limit. They
/// bound the memory and stack any input can take (evaluate() and to_c() recurse at most
/// kMaxExpressionDepth deep); real dynamics stay far below them.
constexpr std::size_t kMaxExpressionLength = 65536;  // characters
constexpr std::size_t kMaxExpressionDepth = 256;     // nesting levels: '(', arguments, '?:', unary, '^'
constexpr std::size_t kMaxExpressionNodes = 10000;   // numbers, variables, operators and calls

/// Whether `name` is a function of the grammar ("sin", ..., "if"): such a name cannot be a constant.
bool is_function_name(const std::string& name);

/// `text` itself when short, else its first characters and its length: for error messages.
std::string expression_excerpt(const std::string& text);

struct ExpressionNode;  // model/expression_node.hpp (internal)
struct ExpressionStep;  // expression_step.hpp

/// Which components an expression reads: sorted, distinct indices of x, u and w.
struct VariableUse {
  std::vector<std::size_t> states, inputs, disturbances;
};

class Expression {
 public:
  /// Parses `text`. `constants` are named values substituted at parse time. Index limits: a
  /// variable x<i> needs i < state_dims (likewise u, w). Throws ParseError (1-based column).
  static Expression parse(const std::string& text, const std::map<std::string, double>& constants,
                          std::size_t state_dims, std::size_t input_dims,
                          std::size_t disturbance_dims);

  /// A noise density (docs/configuration.md, noise.density): the same grammar with one variable,
  /// `z` (the noise value, state units), and no x, u, w. Throws ParseError (1-based column).
  static Expression parse_density(const std::string& text, const std::map<std::string, double>& constants);

  /// Evaluates with the given component arrays (double precision).
  double evaluate(const double* x, const double* u, const double* w) const;
  /// Evaluates an expression of z (parse_density()) at z.
  double evaluate_density(double z) const;

  /// OpenCL C (and C++) expression text over arrays named `x`, `u`, `w` of type double; numbers
  /// are printed as c_double_literal() (format.hpp): the shortest text that reads back exactly. Example: "(x[0] + (10.0 * (u[0] * cos(u[1]))))".
  std::string to_c() const;

  const std::string& text() const { return text_; }

  /// The variables that occur in the expression (after constant substitution). The value depends
  /// on no other component.
  VariableUse variables() const;

  /// The parsed tree in postfix order (expression_step.hpp), chains unrolled left to right.
  std::vector<ExpressionStep> postfix() const;

 private:
  std::shared_ptr<const ExpressionNode> root_;
  std::string text_;
};

}  // namespace amytiss
