// Emitting a parsed expression: as OpenCL C (and C++) text, and as postfix steps for analyses in
// other arithmetics.
#include <string>
#include <vector>

#include "amytiss/expression.hpp"
#include "amytiss/expression_step.hpp"
#include "amytiss/format.hpp"
#include "model/expression_node.hpp"

namespace amytiss {
namespace {

using detail::chain_symbol;
using detail::find_function;
using detail::FunctionInfo;

std::string c_number(double value) {
  std::string text = c_double_literal(value);
  if (value < 0) text = "(" + text + ")";
  return text;
}

std::string to_c_node(const ExpressionNode& node) {
  switch (node.kind) {
    case NodeKind::Number: return c_number(node.number);
    case NodeKind::Variable: {
      if (node.space == VariableSpace::Noise) return "z";
      static const char kNames[] = {'x', 'u', 'w'};
      return std::string(1, kNames[static_cast<int>(node.space)]) + "[" + std::to_string(node.index) + "]";
    }
    case NodeKind::Unary:
      if (node.op == "-") return "(-" + to_c_node(*node.children[0]) + ")";
      return "((double)(" + to_c_node(*node.children[0]) + " == 0.0))";
    case NodeKind::Conditional:
      return "((" + to_c_node(*node.children[0]) + " != 0.0) ? " + to_c_node(*node.children[1]) + " : " +
             to_c_node(*node.children[2]) + ")";
    case NodeKind::Binary: {
      const std::string left = to_c_node(*node.children[0]);
      const std::string right = to_c_node(*node.children[1]);
      const std::string& op = node.op;
      if (op == "^") return "pow(" + left + ", " + right + ")";
      return "((double)(" + left + " " + op + " " + right + "))";
    }
    case NodeKind::Chain: {
      // C's operators associate to the left as the Chain does, so no inner parentheses are needed
      // (and OpenCL compilers' bracket-nesting limits are not approached by long sums).
      const Operation first = node.chain_operations.front();
      const bool logical = first == Operation::And || first == Operation::Or;
      std::string text = logical ? "((double)(" : "(";
      for (std::size_t i = 0; i < node.children.size(); ++i) {
        if (i) text += std::string(" ") + chain_symbol(node.chain_operations[i - 1]) + " ";
        const std::string operand = to_c_node(*node.children[i]);
        text += logical ? "(" + operand + " != 0.0)" : operand;
      }
      return text + (logical ? "))" : ")");
    }
    case NodeKind::Call: {
      const FunctionInfo* function = find_function(node.op);
      std::string text = std::string(function->c_name) + "(";
      for (std::size_t i = 0; i < node.children.size(); ++i) {
        if (i) text += ", ";
        text += to_c_node(*node.children[i]);
      }
      return text + ")";
    }
  }
  return "0.0";
}

void append_postfix(const ExpressionNode& node, std::vector<ExpressionStep>& steps) {
  ExpressionStep step;
  switch (node.kind) {
    case NodeKind::Number: step.number = node.number; break;
    case NodeKind::Variable:
      step.kind = ExpressionStep::Kind::Variable;
      step.space = "xuwz"[static_cast<int>(node.space)];
      step.index = node.index;
      break;
    case NodeKind::Chain:
      append_postfix(*node.children[0], steps);
      for (std::size_t i = 1; i < node.children.size(); ++i) {
        append_postfix(*node.children[i], steps);
        steps.push_back({ExpressionStep::Kind::Operator, 0.0, 'x', 0, chain_symbol(node.chain_operations[i - 1]), 2});
      }
      return;
    default:
      for (const auto& child : node.children) append_postfix(*child, steps);
      step.kind = ExpressionStep::Kind::Operator;
      step.symbol = node.op;
      step.arity = node.children.size();
      break;
  }
  steps.push_back(step);
}

}  // namespace

std::string Expression::to_c() const { return to_c_node(*root_); }

std::vector<ExpressionStep> Expression::postfix() const {
  std::vector<ExpressionStep> steps;
  append_postfix(*root_, steps);
  return steps;
}

}  // namespace amytiss
