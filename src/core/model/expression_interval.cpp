#include "model/expression_interval.hpp"

#include <stdexcept>

#include "amytiss/expression_step.hpp"

namespace amytiss {

IntervalExpression::IntervalExpression(const Expression& expression) {
  for (const ExpressionStep& step : expression.postfix()) {
    if (step.kind == ExpressionStep::Kind::Variable && step.space == 'z')
      throw std::logic_error("IntervalExpression: a noise density (of z) is not a dynamics expression");
    const JetOperation operation = step.kind == ExpressionStep::Kind::Operator
                                       ? jet_operation(step.symbol, step.arity)
                                       : JetOperation::Add;  // unused for numbers and variables
    steps_.push_back({step.kind, step.number, step.space, step.index, operation, step.arity});
  }
}

IntervalJet IntervalExpression::evaluate(const IntervalJet* x, const IntervalJet* u, const IntervalJet* w,
                                         std::size_t gradient_dims) const {
  std::vector<IntervalJet> stack;
  for (const Step& step : steps_) {
    switch (step.kind) {
      case ExpressionStep::Kind::Number:
        stack.push_back(IntervalJet::constant(Interval::point(step.number), gradient_dims));
        break;
      case ExpressionStep::Kind::Variable:
        stack.push_back(step.space == 'x' ? x[step.index] : step.space == 'u' ? u[step.index] : w[step.index]);
        break;
      case ExpressionStep::Kind::Operator: {
        const auto operands = stack.end() - static_cast<std::ptrdiff_t>(step.arity);
        IntervalJet result = step.arity == 3   ? select(operands[0], operands[1], operands[2])
                             : step.arity == 2 ? apply(step.operation, operands[0], operands[1])
                                               : apply(step.operation, operands[0]);
        stack.erase(operands, stack.end());
        stack.push_back(std::move(result));
        break;
      }
    }
  }
  return stack.back();
}

}  // namespace amytiss
