#pragma once
// One step of a parsed expression in postfix order (Expression::postfix()): operands come before
// the operator that combines them, so a stack machine replays the expression. For analyses that
// evaluate the same grammar in another arithmetic (interval enclosures, derivatives).
#include <cstddef>
#include <string>

namespace amytiss {

struct ExpressionStep {
  enum class Kind { Number, Variable, Operator };
  Kind kind = Kind::Number;
  double number = 0.0;  ///< Number: the value (constants are already substituted)
  char space = 'x';     ///< Variable: 'x', 'u', 'w' (state, input, disturbance) or 'z' (noise density)
  std::size_t index = 0;  ///< Variable: the component
  /// Operator: the symbol or function name as written, with `arity` operands on the stack:
  /// unary "-" "!" (1); "+" "-" "*" "/" "^" "<" "<=" ">" ">=" "==" "!=" "&&" "||" (2); the
  /// functions of the grammar by name (1 or 2); "?" for both `c ? a : b` and if(c, a, b) (3,
  /// condition first).
  std::string symbol;
  std::size_t arity = 0;
};

}  // namespace amytiss
