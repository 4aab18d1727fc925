// The grammar's tables: functions, operators, and the names they reserve.
#include <string>

#include "model/expression_node.hpp"

namespace amytiss {
namespace detail {

namespace {

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

}  // namespace

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

}  // namespace detail

bool is_function_name(const std::string& name) { return detail::find_function(name) != nullptr; }

std::string expression_excerpt(const std::string& text) {
  constexpr std::size_t kShown = 60;
  if (text.size() <= kShown) return text;
  return text.substr(0, kShown) + "... (" + std::to_string(text.size()) + " characters)";
}

}  // namespace amytiss
