// Evaluating a parsed expression in double precision, as the emitted OpenCL C computes it.
#include <cmath>

#include "amytiss/expression.hpp"
#include "model/expression_node.hpp"

namespace amytiss {
namespace {

double evaluate_node(const ExpressionNode& node, const double* x, const double* u, const double* w, double z);

// Left to right, as C evaluates `a - b + c` and `a && b && c` (the logical ones stop early).
double evaluate_chain(const ExpressionNode& node, const double* x, const double* u, const double* w, double z) {
  const Operation first = node.chain_operations.front();
  if (first == Operation::And || first == Operation::Or) {
    const bool stop_on = first == Operation::Or;
    for (const auto& child : node.children)
      if ((evaluate_node(*child, x, u, w, z) != 0.0) == stop_on) return stop_on ? 1.0 : 0.0;
    return stop_on ? 0.0 : 1.0;
  }
  double accumulated = evaluate_node(*node.children[0], x, u, w, z);
  for (std::size_t i = 1; i < node.children.size(); ++i) {
    const double operand = evaluate_node(*node.children[i], x, u, w, z);
    switch (node.chain_operations[i - 1]) {
      case Operation::Add: accumulated += operand; break;
      case Operation::Subtract: accumulated -= operand; break;
      case Operation::Multiply: accumulated *= operand; break;
      default: accumulated /= operand; break;
    }
  }
  return accumulated;
}

double evaluate_node(const ExpressionNode& node, const double* x, const double* u, const double* w, double z) {
  switch (node.kind) {
    case NodeKind::Number: return node.number;
    case NodeKind::Variable:
      switch (node.space) {
        case VariableSpace::State: return x[node.index];
        case VariableSpace::Input: return u[node.index];
        case VariableSpace::Disturbance: return w[node.index];
        case VariableSpace::Noise: return z;
      }
      return 0.0;
    case NodeKind::Unary: {
      const double operand = evaluate_node(*node.children[0], x, u, w, z);
      return node.operation == Operation::Negate ? -operand : (operand == 0.0 ? 1.0 : 0.0);
    }
    case NodeKind::Conditional:
      return evaluate_node(*node.children[0], x, u, w, z) != 0.0 ? evaluate_node(*node.children[1], x, u, w, z)
                                                               : evaluate_node(*node.children[2], x, u, w, z);
    case NodeKind::Chain: return evaluate_chain(node, x, u, w, z);
    case NodeKind::Binary: {
      const double left = evaluate_node(*node.children[0], x, u, w, z);
      const double right = evaluate_node(*node.children[1], x, u, w, z);
      switch (node.operation) {
        case Operation::Add: return left + right;
        case Operation::Subtract: return left - right;
        case Operation::Multiply: return left * right;
        case Operation::Divide: return left / right;
        case Operation::Power: return std::pow(left, right);
        case Operation::Less: return left < right ? 1.0 : 0.0;
        case Operation::LessEqual: return left <= right ? 1.0 : 0.0;
        case Operation::Greater: return left > right ? 1.0 : 0.0;
        case Operation::GreaterEqual: return left >= right ? 1.0 : 0.0;
        case Operation::Equal: return left == right ? 1.0 : 0.0;
        case Operation::NotEqual: return left != right ? 1.0 : 0.0;
        default: return 0.0;
      }
    }
    case NodeKind::Call: {
      const double a = evaluate_node(*node.children[0], x, u, w, z);
      switch (node.operation) {
        case Operation::Sin: return std::sin(a);
        case Operation::Cos: return std::cos(a);
        case Operation::Tan: return std::tan(a);
        case Operation::Asin: return std::asin(a);
        case Operation::Acos: return std::acos(a);
        case Operation::Atan: return std::atan(a);
        case Operation::Exp: return std::exp(a);
        case Operation::Log: return std::log(a);
        case Operation::Sqrt: return std::sqrt(a);
        case Operation::Abs: return std::fabs(a);
        case Operation::Floor: return std::floor(a);
        case Operation::Ceil: return std::ceil(a);
        default: break;
      }
      const double b = evaluate_node(*node.children[1], x, u, w, z);
      switch (node.operation) {
        case Operation::Atan2: return std::atan2(a, b);
        case Operation::Pow: return std::pow(a, b);
        case Operation::Min: return std::fmin(a, b);
        case Operation::Max: return std::fmax(a, b);
        default: return 0.0;
      }
    }
  }
  return 0.0;
}

}  // namespace

double Expression::evaluate(const double* x, const double* u, const double* w) const {
  return evaluate_node(*root_, x, u, w, 0.0);
}

double Expression::evaluate_density(double z) const { return evaluate_node(*root_, nullptr, nullptr, nullptr, z); }

}  // namespace amytiss
