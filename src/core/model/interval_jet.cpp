#include "model/interval_jet.hpp"

#include <cmath>
#include <stdexcept>

namespace amytiss {

namespace {

using Gradient = std::vector<Interval>;

Gradient scaled(const Gradient& gradient, const Interval& factor) {
  Gradient out(gradient.size());
  for (std::size_t j = 0; j < gradient.size(); ++j) out[j] = gradient[j] * factor;
  return out;
}

// fa * ga + fb * gb, component by component.
Gradient combined(const Gradient& ga, const Interval& fa, const Gradient& gb, const Interval& fb) {
  Gradient out(ga.size());
  for (std::size_t j = 0; j < ga.size(); ++j) out[j] = ga[j] * fa + gb[j] * fb;
  return out;
}

Gradient hulls(const Gradient& ga, const Gradient& gb) {
  Gradient out(ga.size());
  for (std::size_t j = 0; j < ga.size(); ++j) out[j] = hull(ga[j], gb[j]);
  return out;
}

bool constant_in_x(const IntervalJet& jet) {
  for (const Interval& component : jet.gradient)
    if (component.lo != 0.0 || component.hi != 0.0) return false;
  return jet.smooth;
}

// An unbounded value means a pole inside the box (tan, 1/x): f jumps there, so no mean-value form.
bool bounded(const Interval& value) { return value.defined && std::isfinite(value.lo) && std::isfinite(value.hi); }

// f(a) with f' over a's values: the chain rule.
IntervalJet chain(const IntervalJet& a, const Interval& value, const Interval& derivative) {
  return {value, scaled(a.gradient, derivative), a.smooth && bounded(value)};
}

// A truth value or a step function: constant over the box when its value is one number.
IntervalJet discrete(const Interval& value, std::size_t dims) {
  IntervalJet jet = IntervalJet::constant(value, dims);
  jet.smooth = value.is_point() && value.defined;
  return jet;
}

const Interval kOne = Interval::point(1.0);

// The generalised (Clarke) derivative of |v|: a mean-value form holds with it for Lipschitz
// functions, so |.|, min and max keep the centred form.
Interval sign(const Interval& v) {
  if (v.lo > 0.0) return kOne;
  if (v.hi < 0.0) return -kOne;
  return Interval(-1.0, 1.0);
}

IntervalJet power(const IntervalJet& a, const IntervalJet& b) {
  const Interval value = pow(a.value, b.value);
  if (constant_in_x(b)) {
    const Interval& n = b.value;
    const Interval derivative = is_integer_exponent(n) ? n * integer_power(a.value, static_cast<long>(n.lo) - 1)
                                        : n * pow(a.value, n - kOne);
    return chain(a, value, derivative);
  }
  // d(a^b) = a^b (b/a da + log(a) db), for a > 0.
  return {value, scaled(combined(a.gradient, b.value / a.value, b.gradient, log(a.value)), value),
          a.smooth && b.smooth && bounded(value) && a.value.lo > 0.0};
}

IntervalJet extremum(const IntervalJet& a, const IntervalJet& b, bool is_min) {
  const Interval value = is_min ? min(a.value, b.value) : max(a.value, b.value);
  const bool a_wins = is_min ? a.value.hi <= b.value.lo : a.value.lo >= b.value.hi;
  const bool b_wins = is_min ? b.value.hi <= a.value.lo : b.value.lo >= a.value.hi;
  if (a_wins) return {value, a.gradient, a.smooth && value.defined};
  if (b_wins) return {value, b.gradient, b.smooth && value.defined};
  return {value, hulls(a.gradient, b.gradient), a.smooth && b.smooth && value.defined};
}

IntervalJet arc_tangent2(const IntervalJet& y, const IntervalJet& x) {
  const Interval value = atan2(y.value, x.value);
  const Interval radius2 = sqr(y.value) + sqr(x.value);
  const bool meets_cut = x.value.lo <= 0.0 && y.value.contains_zero();
  return {value, combined(y.gradient, x.value / radius2, x.gradient, -y.value / radius2),
          y.smooth && x.smooth && bounded(value) && !meets_cut};
}

}  // namespace

IntervalJet IntervalJet::constant(const Interval& value, std::size_t dims) {
  return {value, Gradient(dims, Interval::point(0.0)), true};
}

IntervalJet IntervalJet::variable(const Interval& value, std::size_t j, std::size_t dims) {
  IntervalJet jet = constant(value, dims);
  jet.gradient[j] = kOne;
  return jet;
}

IntervalJet operator+(const IntervalJet& a, const IntervalJet& b) {
  return {a.value + b.value, combined(a.gradient, kOne, b.gradient, kOne), a.smooth && b.smooth};
}

IntervalJet operator*(const IntervalJet& a, const IntervalJet& b) {
  return {a.value * b.value, combined(a.gradient, b.value, b.gradient, a.value), a.smooth && b.smooth};
}

JetOperation jet_operation(const std::string& symbol, std::size_t arity) {
  static const struct {
    const char* symbol;
    std::size_t arity;
    JetOperation operation;
  } kOperations[] = {
      {"-", 1, JetOperation::Negate},    {"!", 1, JetOperation::Not},          {"+", 2, JetOperation::Add},
      {"-", 2, JetOperation::Subtract},  {"*", 2, JetOperation::Multiply},     {"/", 2, JetOperation::Divide},
      {"^", 2, JetOperation::Power},     {"pow", 2, JetOperation::Power},      {"<", 2, JetOperation::Less},
      {"<=", 2, JetOperation::LessEqual}, {">", 2, JetOperation::Greater},     {">=", 2, JetOperation::GreaterEqual},
      {"==", 2, JetOperation::Equal},    {"!=", 2, JetOperation::NotEqual},    {"&&", 2, JetOperation::And},
      {"||", 2, JetOperation::Or},       {"sin", 1, JetOperation::Sin},        {"cos", 1, JetOperation::Cos},
      {"tan", 1, JetOperation::Tan},     {"asin", 1, JetOperation::Asin},      {"acos", 1, JetOperation::Acos},
      {"atan", 1, JetOperation::Atan},   {"atan2", 2, JetOperation::Atan2},    {"exp", 1, JetOperation::Exp},
      {"log", 1, JetOperation::Log},     {"sqrt", 1, JetOperation::Sqrt},      {"abs", 1, JetOperation::Abs},
      {"min", 2, JetOperation::Min},     {"max", 2, JetOperation::Max},        {"floor", 1, JetOperation::Floor},
      {"ceil", 1, JetOperation::Ceil},   {"?", 3, JetOperation::Select},
  };
  for (const auto& entry : kOperations)
    if (symbol == entry.symbol && arity == entry.arity) return entry.operation;
  throw std::logic_error("interval evaluation: no operation '" + symbol + "' of " + std::to_string(arity) +
                         " operands in the expression grammar");
}

IntervalJet apply(JetOperation operation, const IntervalJet& a) {
  const Interval& v = a.value;
  const std::size_t dims = a.gradient.size();
  switch (operation) {
    case JetOperation::Negate: return {-v, scaled(a.gradient, -kOne), a.smooth};
    case JetOperation::Not: return discrete(logical_not(v), dims);
    case JetOperation::Sin: return chain(a, sin(v), cos(v));
    case JetOperation::Cos: return chain(a, cos(v), -sin(v));
    case JetOperation::Tan: {
      const Interval t = tan(v);
      return chain(a, t, kOne + sqr(t));
    }
    case JetOperation::Asin: return chain(a, asin(v), kOne / sqrt(kOne - sqr(v)));
    case JetOperation::Acos: return chain(a, acos(v), -(kOne / sqrt(kOne - sqr(v))));
    case JetOperation::Atan: return chain(a, atan(v), kOne / (kOne + sqr(v)));
    case JetOperation::Exp: {
      const Interval e = exp(v);
      return chain(a, e, e);
    }
    case JetOperation::Log: return chain(a, log(v), kOne / v);
    case JetOperation::Sqrt: {
      const Interval s = sqrt(v);
      return chain(a, s, kOne / (Interval::point(2.0) * s));
    }
    case JetOperation::Abs: return chain(a, abs(v), sign(v));
    case JetOperation::Floor: return discrete(floor(v), dims);
    case JetOperation::Ceil: return discrete(ceil(v), dims);
    default: break;
  }
  throw std::logic_error("interval evaluation: operation of two or three operands given one");
}

IntervalJet apply(JetOperation operation, const IntervalJet& a, const IntervalJet& b) {
  const Interval &u = a.value, &v = b.value;
  const std::size_t dims = a.gradient.size();
  switch (operation) {
    case JetOperation::Add: return a + b;
    case JetOperation::Subtract: return {u - v, combined(a.gradient, kOne, b.gradient, -kOne), a.smooth && b.smooth};
    case JetOperation::Multiply: return a * b;
    case JetOperation::Divide: {
      const Interval quotient = u / v;
      return {quotient, combined(a.gradient, kOne / v, b.gradient, -(quotient / v)),
              a.smooth && b.smooth && bounded(quotient)};
    }
    case JetOperation::Power: return power(a, b);
    case JetOperation::Less: return discrete(less(u, v), dims);
    case JetOperation::LessEqual: return discrete(less_equal(u, v), dims);
    case JetOperation::Greater: return discrete(less(v, u), dims);
    case JetOperation::GreaterEqual: return discrete(less_equal(v, u), dims);
    case JetOperation::Equal: return discrete(equal(u, v), dims);
    case JetOperation::NotEqual: return discrete(logical_not(equal(u, v)), dims);
    case JetOperation::And: return discrete(logical_and(u, v), dims);
    case JetOperation::Or: return discrete(logical_or(u, v), dims);
    case JetOperation::Atan2: return arc_tangent2(a, b);
    case JetOperation::Min: return extremum(a, b, true);
    case JetOperation::Max: return extremum(a, b, false);
    default: break;
  }
  throw std::logic_error("interval evaluation: operation of one or three operands given two");
}

IntervalJet select(const IntervalJet& condition, const IntervalJet& a, const IntervalJet& b) {
  const Interval truth_value = truth(condition.value);
  if (truth_value.is_empty()) return discrete(truth_value, a.gradient.size());
  IntervalJet chosen;
  if (truth_value.lo == 1.0) chosen = a;
  else if (truth_value.hi == 0.0) chosen = b;
  else return {select(condition.value, a.value, b.value), hulls(a.gradient, b.gradient), false};
  chosen.value.defined = chosen.value.defined && truth_value.defined;
  chosen.smooth = chosen.smooth && truth_value.defined;
  return chosen;
}

}  // namespace amytiss
