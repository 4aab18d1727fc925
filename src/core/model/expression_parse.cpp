// Parsing the expression grammar (include/amytiss/expression.hpp) into an ExpressionNode tree, with
// the limits on length, depth and size that bound what any input can cost.
#include <cmath>
#include <map>
#include <string>
#include <vector>

#include "amytiss/errors.hpp"
#include "amytiss/expression.hpp"
#include "model/expression_lexer.hpp"
#include "model/expression_node.hpp"

namespace amytiss {
namespace {

using detail::describe;
using detail::find_function;
using detail::function_list;
using detail::FunctionInfo;
using detail::NodePtr;
using detail::operator_operation;
using detail::Token;
using detail::TokenKind;
using detail::tokenize;

class Parser {
 public:
  Parser(const std::string& text, const std::map<std::string, double>& constants, std::size_t state_dims,
         std::size_t input_dims, std::size_t disturbance_dims, bool noise_variable = false)
      : tokens_(tokenize(text)), constants_(constants),
        dims_{state_dims, input_dims, disturbance_dims}, noise_variable_(noise_variable) {}

  NodePtr parse_all() {
    NodePtr root = parse_expr();
    if (peek().kind != TokenKind::End)
      throw ParseError(peek().column,
                       "expected an operator or the end of the expression, got " + describe(peek()));
    return root;
  }

 private:
  const Token& peek() const {
    const Token& token = tokens_[position_];
    if (token.kind == TokenKind::Invalid) throw ParseError(token.column, token.text);
    return token;
  }
  bool peek_operator(const char* op) const {
    return peek().kind == TokenKind::Operator && peek().text == op;
  }
  Token next() {
    const Token token = peek();
    ++position_;
    return token;
  }

  // Counts one nesting level while alive; every recursive descent passes through one, so the
  // parser's stack stays proportional to kMaxExpressionDepth.
  class Nesting {
   public:
    explicit Nesting(Parser& parser) : parser_(parser) {
      if (++parser_.depth_ > kMaxExpressionDepth)
        throw ParseError(parser_.peek().column, "nested deeper than the limit of " +
                                                    std::to_string(kMaxExpressionDepth) + " levels" + kDepthHint);
    }
    ~Nesting() { --parser_.depth_; }

   private:
    Parser& parser_;
  };
  static constexpr const char* kDepthHint =
      " (each parenthesis, function argument, '?:' branch, unary operator and '^' is a level)";

  NodePtr count(std::shared_ptr<ExpressionNode> node) {
    if (++nodes_ > kMaxExpressionNodes)
      throw ParseError(peek().column, "more than the limit of " + std::to_string(kMaxExpressionNodes) +
                                          " terms (numbers, variables, operators and calls)");
    for (const auto& child : node->children) node->height = std::max(node->height, child->height + 1);
    if (node->height > kMaxExpressionDepth)
      throw ParseError(peek().column, "nested deeper than the limit of " + std::to_string(kMaxExpressionDepth) +
                                          " levels" + kDepthHint);
    return node;
  }

  NodePtr make_number(double value) {
    auto node = std::make_shared<ExpressionNode>();
    node->kind = NodeKind::Number;
    node->number = value;
    return count(std::move(node));
  }

  NodePtr make_operator(NodeKind kind, const std::string& op, std::vector<NodePtr> children) {
    auto node = std::make_shared<ExpressionNode>();
    node->kind = kind;
    node->op = op;
    node->children = std::move(children);
    if (kind == NodeKind::Unary || kind == NodeKind::Binary) node->operation = operator_operation(kind, op);
    if (kind == NodeKind::Call) node->operation = find_function(op)->operation;
    return count(std::move(node));
  }

  // One operand gives the operand itself; more give a flat left-associative Chain.
  NodePtr make_chain(std::vector<NodePtr> operands, std::vector<Operation> operations) {
    if (operands.size() == 1) return operands.front();
    auto node = std::make_shared<ExpressionNode>();
    node->kind = NodeKind::Chain;
    node->children = std::move(operands);
    node->chain_operations = std::move(operations);
    return count(std::move(node));
  }

  NodePtr parse_expr() {
    Nesting nesting(*this);
    return parse_conditional();
  }

  NodePtr parse_conditional() {
    NodePtr condition = parse_or();
    if (!peek_operator("?")) return condition;
    const Token question = next();
    NodePtr when_true = parse_expr();
    if (!peek_operator(":"))
      throw ParseError(peek().column, "expected ':' of the conditional '?' at column " +
                                          std::to_string(question.column) + ", got " + describe(peek()));
    next();
    NodePtr when_false = parse_expr();
    return make_operator(NodeKind::Conditional, "?", {condition, when_true, when_false});
  }

  NodePtr parse_or() {
    std::vector<NodePtr> operands{parse_and()};
    std::vector<Operation> operations;
    while (peek_operator("||")) {
      next();
      operands.push_back(parse_and());
      operations.push_back(Operation::Or);
    }
    return make_chain(std::move(operands), std::move(operations));
  }

  NodePtr parse_and() {
    std::vector<NodePtr> operands{parse_comparison()};
    std::vector<Operation> operations;
    while (peek_operator("&&")) {
      next();
      operands.push_back(parse_comparison());
      operations.push_back(Operation::And);
    }
    return make_chain(std::move(operands), std::move(operations));
  }

  NodePtr parse_comparison() {
    NodePtr left = parse_sum();
    for (const char* op : {"<", "<=", ">", ">=", "==", "!="}) {
      if (peek_operator(op)) {
        next();
        NodePtr right = parse_sum();
        for (const char* again : {"<", "<=", ">", ">=", "==", "!="})
          if (peek_operator(again))
            throw ParseError(peek().column, "comparisons cannot be chained; use '&&' (got " +
                                                describe(peek()) + ")");
        return make_operator(NodeKind::Binary, op, {left, right});
      }
    }
    return left;
  }

  NodePtr parse_sum() {
    std::vector<NodePtr> operands{parse_product()};
    std::vector<Operation> operations;
    while (peek_operator("+") || peek_operator("-")) {
      operations.push_back(next().text == "+" ? Operation::Add : Operation::Subtract);
      operands.push_back(parse_product());
    }
    return make_chain(std::move(operands), std::move(operations));
  }

  NodePtr parse_product() {
    std::vector<NodePtr> operands{parse_unary()};
    std::vector<Operation> operations;
    while (peek_operator("*") || peek_operator("/")) {
      operations.push_back(next().text == "*" ? Operation::Multiply : Operation::Divide);
      operands.push_back(parse_unary());
    }
    return make_chain(std::move(operands), std::move(operations));
  }

  NodePtr parse_unary() {
    Nesting nesting(*this);
    if (peek_operator("-") || peek_operator("+") || peek_operator("!")) {
      const std::string op = next().text;
      NodePtr operand = parse_unary();
      if (op == "+") return operand;
      return make_operator(NodeKind::Unary, op, {operand});
    }
    return parse_power();
  }

  NodePtr parse_power() {
    NodePtr base = parse_atom();
    if (!peek_operator("^")) return base;
    next();
    return make_operator(NodeKind::Binary, "^", {base, parse_unary()});
  }

  NodePtr parse_atom() {
    const Token token = next();
    if (token.kind == TokenKind::Number) return make_number(token.number);
    if (token.kind == TokenKind::Operator && token.text == "(") {
      NodePtr inner = parse_expr();
      if (!peek_operator(")"))
        throw ParseError(peek().column, "expected ')' to close '(' at column " +
                                            std::to_string(token.column) + ", got " + describe(peek()));
      next();
      return inner;
    }
    if (token.kind == TokenKind::Identifier) return parse_identifier(token);
    throw ParseError(token.column,
                     "expected a number, a variable (x0, u0, w0, ...), a constant, a function or '(', got " +
                         describe(token));
  }

  NodePtr parse_identifier(const Token& token) {
    const std::string& name = token.text;
    if (const FunctionInfo* function = find_function(name)) return parse_call(token, *function);
    if (auto variable = parse_variable(token)) return variable;
    const auto constant = constants_.find(name);
    if (constant != constants_.end()) return make_number(constant->second);
    if (name == "pi") return make_number(M_PI);
    std::string known_constants = "pi";
    for (const auto& entry : constants_) known_constants += ", " + entry.first;
    throw ParseError(token.column, "unknown name '" + name + "': expected a variable (" + variable_ranges() +
                                       "), a constant (" + known_constants + ") or a function (" +
                                       function_list() + ")");
  }

  std::string variable_ranges() const {
    static const char kLetters[] = {'x', 'u', 'w'};
    std::string ranges = noise_variable_ ? "z" : "";
    for (int space = 0; space < 3; ++space) {
      if (dims_[space] == 0) continue;
      if (!ranges.empty()) ranges += ", ";
      ranges += std::string(1, kLetters[space]) + "0";
      if (dims_[space] > 1) ranges += ".." + std::string(1, kLetters[space]) + std::to_string(dims_[space] - 1);
    }
    return ranges.empty() ? "none" : ranges;
  }

  NodePtr parse_variable(const Token& token) {
    const std::string& name = token.text;
    if (noise_variable_ && name == "z") {
      auto node = std::make_shared<ExpressionNode>();
      node->kind = NodeKind::Variable;
      node->space = VariableSpace::Noise;
      return count(std::move(node));
    }
    if (name.size() < 2) return nullptr;
    const std::string letters = "xuw";
    const auto space = letters.find(name[0]);
    if (space == std::string::npos) return nullptr;
    for (std::size_t i = 1; i < name.size(); ++i)
      if (!std::isdigit(static_cast<unsigned char>(name[i]))) return nullptr;
    if (name.size() > 12)
      throw ParseError(token.column, "variable index of '" + name + "' is too large");
    const std::size_t index = std::stoull(name.substr(1));
    static const char* const kSpaceNames[] = {"state", "input", "disturbance"};
    if (index >= dims_[space]) {
      std::string have = dims_[space] == 0
                             ? std::string("no ") + kSpaceNames[space] + " components"
                             : std::to_string(dims_[space]) + " " + kSpaceNames[space] +
                                   (dims_[space] == 1 ? " component" : " components");
      throw ParseError(token.column, "'" + name + "' is out of range: the system has " + have +
                                         " (valid: " + variable_ranges() + ")");
    }
    auto node = std::make_shared<ExpressionNode>();
    node->kind = NodeKind::Variable;
    node->space = static_cast<VariableSpace>(space);
    node->index = index;
    return count(std::move(node));
  }

  NodePtr parse_call(const Token& name, const FunctionInfo& function) {
    if (!peek_operator("("))
      throw ParseError(peek().column, "expected '(' after function name " + name.text + ", got " +
                                          describe(peek()));
    next();
    std::vector<NodePtr> arguments;
    arguments.push_back(parse_expr());
    while (peek_operator(",")) {
      next();
      arguments.push_back(parse_expr());
    }
    if (!peek_operator(")")) {
      if (arguments.size() < function.arity)
        throw ParseError(peek().column, "expected ',' and the next argument of " + name.text + " (it takes " +
                                            std::to_string(function.arity) + "), got " + describe(peek()));
      throw ParseError(peek().column, "expected ')' after argument list of " + name.text + ", got " +
                                          describe(peek()));
    }
    next();
    if (arguments.size() != function.arity)
      throw ParseError(name.column, name.text + " takes " + std::to_string(function.arity) +
                                        (function.arity == 1 ? " argument" : " arguments") + ", got " +
                                        std::to_string(arguments.size()));
    if (name.text == "if") return make_operator(NodeKind::Conditional, "?", std::move(arguments));
    return make_operator(NodeKind::Call, name.text, std::move(arguments));
  }

  std::vector<Token> tokens_;
  std::size_t position_ = 0;
  const std::map<std::string, double>& constants_;
  std::size_t dims_[3];
  bool noise_variable_ = false;  // a density: `z` is the only variable
  std::size_t depth_ = 0;
  std::size_t nodes_ = 0;
};

void check_length(const std::string& text) {
  if (text.size() > kMaxExpressionLength)
    throw ParseError(kMaxExpressionLength + 1, "the expression is " + std::to_string(text.size()) +
                                                   " characters long, more than the limit of " +
                                                   std::to_string(kMaxExpressionLength));
}

}  // namespace

Expression Expression::parse(const std::string& text, const std::map<std::string, double>& constants,
                             std::size_t state_dims, std::size_t input_dims, std::size_t disturbance_dims) {
  check_length(text);
  Parser parser(text, constants, state_dims, input_dims, disturbance_dims);
  Expression expression;
  expression.root_ = parser.parse_all();
  expression.text_ = text;
  return expression;
}

Expression Expression::parse_density(const std::string& text, const std::map<std::string, double>& constants) {
  check_length(text);
  Parser parser(text, constants, 0, 0, 0, true);
  Expression expression;
  expression.root_ = parser.parse_all();
  expression.text_ = text;
  return expression;
}

VariableUse Expression::variables() const {
  std::vector<char> seen[4];
  // An explicit stack: the walk's depth must not depend on the expression's nesting.
  std::vector<const ExpressionNode*> pending{root_.get()};
  while (!pending.empty()) {
    const ExpressionNode* node = pending.back();
    pending.pop_back();
    if (node->kind == NodeKind::Variable) {
      std::vector<char>& space = seen[static_cast<int>(node->space)];
      if (space.size() <= node->index) space.resize(node->index + 1, 0);
      space[node->index] = 1;
    }
    for (const auto& child : node->children) pending.push_back(child.get());
  }
  auto indices = [](const std::vector<char>& flags) {
    std::vector<std::size_t> out;
    for (std::size_t i = 0; i < flags.size(); ++i)
      if (flags[i]) out.push_back(i);
    return out;
  };
  return {indices(seen[int(VariableSpace::State)]), indices(seen[int(VariableSpace::Input)]),
          indices(seen[int(VariableSpace::Disturbance)])};
}

}  // namespace amytiss
