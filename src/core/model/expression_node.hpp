#pragma once
// The tree of a parsed expression and the grammar's tables, shared by parsing
// (model/expression_parse.cpp), evaluation (model/expression_evaluate.cpp) and OpenCL C emission
// (model/expression_emit.cpp). Internal to the core.
#include <cstddef>
#include <memory>
#include <string>
#include <vector>

#include "amytiss/expression.hpp"

namespace amytiss {

// Chain: a left-associative run of '+'/'-' (or '*'/'/') kept flat, so a long sum is a loop in
// evaluate() and to_c(), not a deep tree.
enum class NodeKind { Number, Variable, Unary, Binary, Chain, Call, Conditional };
enum class VariableSpace { State, Input, Disturbance, Noise };
// Resolved when the node is built so that evaluation switches on an integer, never on text.
enum class Operation {
  None, Negate, Not, Add, Subtract, Multiply, Divide, Power, Less, LessEqual, Greater, GreaterEqual,
  Equal, NotEqual, And, Or, Sin, Cos, Tan, Asin, Acos, Atan, Atan2, Exp, Log, Sqrt, Pow, Abs, Min,
  Max, Floor, Ceil
};

struct ExpressionNode {
  NodeKind kind = NodeKind::Number;
  double number = 0.0;
  VariableSpace space = VariableSpace::State;
  std::size_t index = 0;
  std::string op;  // operator symbol (unary/binary) or function name (call), for to_c()
  Operation operation = Operation::None;
  std::vector<std::shared_ptr<const ExpressionNode>> children;
  std::vector<Operation> chain_operations;  // Chain: the operation joining children[i] and children[i+1]
  std::size_t height = 1;                   // levels of this subtree (a leaf: 1)

  ExpressionNode() = default;
  ExpressionNode(const ExpressionNode&) = delete;
  ExpressionNode& operator=(const ExpressionNode&) = delete;
  // The default destructor would recurse once per tree level; a tree abandoned half-built by a
  // ParseError may be deeper than the depth limit, so descendants are released from a list.
  ~ExpressionNode() {
    std::vector<std::shared_ptr<const ExpressionNode>> pending = std::move(children);
    while (!pending.empty()) {
      std::shared_ptr<const ExpressionNode> node = std::move(pending.back());
      pending.pop_back();
      if (node.use_count() == 1) {
        auto& grandchildren = const_cast<ExpressionNode&>(*node).children;
        for (auto& child : grandchildren) pending.push_back(std::move(child));
        grandchildren.clear();
      }
    }
  }
};

namespace detail {

using NodePtr = std::shared_ptr<const ExpressionNode>;

/// A function of the grammar: its name, number of arguments, the C function it emits (nullptr
/// for `if`, emitted as a conditional) and its operation.
struct FunctionInfo {
  const char* name;
  std::size_t arity;
  const char* c_name;
  Operation operation;
};

/// The function named `name`, or nullptr.
const FunctionInfo* find_function(const std::string& name);
/// "sin, cos, ..., if": every function name, for messages.
std::string function_list();
/// The operation of a unary or binary operator symbol ("-", "<=", ...).
Operation operator_operation(NodeKind kind, const std::string& op);
/// The C symbol joining two operands of a chain ("+", "&&", ...).
const char* chain_symbol(Operation operation);

}  // namespace detail
}  // namespace amytiss
