#include "amytiss/expression.hpp"

#include "amytiss/format.hpp"

#include <cctype>
#include <cmath>
#include <algorithm>
#include <cstdio>
#include <vector>

#include "amytiss/errors.hpp"
#include "amytiss/expression_step.hpp"

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

namespace {

using NodePtr = std::shared_ptr<const ExpressionNode>;

struct FunctionInfo {
  const char* name;
  std::size_t arity;
  const char* c_name;
  Operation operation;
};

const FunctionInfo kFunctions[] = {
    {"sin", 1, "sin", Operation::Sin},       {"cos", 1, "cos", Operation::Cos},
    {"tan", 1, "tan", Operation::Tan},       {"asin", 1, "asin", Operation::Asin},
    {"acos", 1, "acos", Operation::Acos},    {"atan", 1, "atan", Operation::Atan},
    {"atan2", 2, "atan2", Operation::Atan2}, {"exp", 1, "exp", Operation::Exp},
    {"log", 1, "log", Operation::Log},       {"sqrt", 1, "sqrt", Operation::Sqrt},
    {"pow", 2, "pow", Operation::Pow},       {"abs", 1, "fabs", Operation::Abs},
    {"min", 2, "fmin", Operation::Min},      {"max", 2, "fmax", Operation::Max},
    {"floor", 1, "floor", Operation::Floor}, {"ceil", 1, "ceil", Operation::Ceil},
    {"if", 3, nullptr, Operation::None},
};

Operation operator_operation(NodeKind kind, const std::string& op) {
  if (kind == NodeKind::Unary) return op == "-" ? Operation::Negate : Operation::Not;
  static const struct {
    const char* symbol;
    Operation operation;
  } kBinary[] = {{"+", Operation::Add},        {"-", Operation::Subtract}, {"*", Operation::Multiply},
                 {"/", Operation::Divide},     {"^", Operation::Power},    {"<", Operation::Less},
                 {"<=", Operation::LessEqual}, {">", Operation::Greater},  {">=", Operation::GreaterEqual},
                 {"==", Operation::Equal},     {"!=", Operation::NotEqual}, {"&&", Operation::And},
                 {"||", Operation::Or}};
  for (const auto& entry : kBinary)
    if (op == entry.symbol) return entry.operation;
  return Operation::None;
}

const FunctionInfo* find_function(const std::string& name) {
  for (const auto& info : kFunctions)
    if (name == info.name) return &info;
  return nullptr;
}

std::string function_list() {
  std::string list;
  for (const auto& info : kFunctions) {
    if (!list.empty()) list += ", ";
    list += info.name;
  }
  return list;
}

enum class TokenKind { Number, Identifier, Operator, Invalid, End };

struct Token {
  TokenKind kind = TokenKind::End;
  std::string text;
  double number = 0.0;
  std::size_t column = 0;  // 1-based
};

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

const char* chain_symbol(Operation operation) {
  switch (operation) {
    case Operation::Add: return "+";
    case Operation::Subtract: return "-";
    case Operation::Multiply: return "*";
    case Operation::Divide: return "/";
    case Operation::And: return "&&";
    default: return "||";
  }
}

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

double Expression::evaluate(const double* x, const double* u, const double* w) const {
  return evaluate_node(*root_, x, u, w, 0.0);
}

double Expression::evaluate_density(double z) const { return evaluate_node(*root_, nullptr, nullptr, nullptr, z); }

std::string Expression::to_c() const { return to_c_node(*root_); }

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

namespace amytiss {

std::string expression_excerpt(const std::string& text) {
  constexpr std::size_t kShown = 60;
  if (text.size() <= kShown) return text;
  return text.substr(0, kShown) + "... (" + std::to_string(text.size()) + " characters)";
}

}  // namespace amytiss

namespace amytiss {

namespace {
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

std::vector<ExpressionStep> Expression::postfix() const {
  std::vector<ExpressionStep> steps;
  append_postfix(*root_, steps);
  return steps;
}

}  // namespace amytiss
