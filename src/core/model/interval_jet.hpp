#pragma once
// An interval with its interval gradient (forward-mode automatic differentiation over a box), for
// the centred form of enclosures and the interval Jacobian (model/enclosure.cpp).
#include <string>
#include <vector>

#include "amytiss/interval.hpp"

namespace amytiss {

/// `value` encloses a function over a box of the state; gradient[j] encloses its partial
/// derivative in x_j over the same box (an empty gradient: derivatives not tracked).
struct IntervalJet {
  Interval value;
  std::vector<Interval> gradient;
  /// False when the gradient does not bound the differences (a jump may lie in the box: floor,
  /// an undecided comparison or branch, a value outside its domain).
  bool smooth = true;

  /// A quantity that does not depend on x: zero gradient of `dims` components.
  static IntervalJet constant(const Interval& value, std::size_t dims);
  /// x_j itself over `value`: gradient the j-th unit vector of `dims` components.
  static IntervalJet variable(const Interval& value, std::size_t j, std::size_t dims);
};

/// The operations of the expression grammar (expression_step.hpp); Power is both '^' and pow().
enum class JetOperation {
  Negate, Not, Add, Subtract, Multiply, Divide, Power, Less, LessEqual, Greater, GreaterEqual, Equal, NotEqual,
  And, Or, Sin, Cos, Tan, Asin, Acos, Atan, Atan2, Exp, Log, Sqrt, Abs, Min, Max, Floor, Ceil, Select
};
/// The operation of an operator step: its symbol or function name and arity. Throws
/// std::logic_error for one outside the grammar (the parser lets none through).
JetOperation jet_operation(const std::string& symbol, std::size_t arity);

IntervalJet operator+(const IntervalJet& a, const IntervalJet& b);
IntervalJet operator*(const IntervalJet& a, const IntervalJet& b);
/// Operations of one and two operands (Select takes three: select()).
IntervalJet apply(JetOperation operation, const IntervalJet& a);
IntervalJet apply(JetOperation operation, const IntervalJet& a, const IntervalJet& b);
/// condition ? a : b: the branch the condition picks over the whole box, else the hull of both
/// (not smooth).
IntervalJet select(const IntervalJet& condition, const IntervalJet& a, const IntervalJet& b);

}  // namespace amytiss
