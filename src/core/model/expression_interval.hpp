#pragma once
// A dynamics expression evaluated in interval arithmetic with interval gradients: the natural
// interval extension of the expression and its derivatives (docs/semantics.md, "Image enclosures").
#include <vector>

#include "amytiss/expression.hpp"
#include "amytiss/expression_step.hpp"
#include "model/interval_jet.hpp"

namespace amytiss {

class IntervalExpression {
 public:
  /// Replays `expression` (of x, u, w; not a density of z) over intervals.
  explicit IntervalExpression(const Expression& expression);

  /// The expression over jets of x, u and w (arrays of the expression's dimensions; u, w may be
  /// null when it reads none). Every jet has `gradient_dims` gradient components.
  IntervalJet evaluate(const IntervalJet* x, const IntervalJet* u, const IntervalJet* w,
                       std::size_t gradient_dims) const;

 private:
  struct Step {
    ExpressionStep::Kind kind;
    double number;
    char space;
    std::size_t index;
    JetOperation operation;
    std::size_t arity;
  };
  std::vector<Step> steps_;
};

}  // namespace amytiss
