#pragma once
// The `dynamics` expressions as a model: the discrete map itself, or dx/dt for an integrator.
#include <cstddef>
#include <memory>
#include <vector>

#include "amytiss/expression.hpp"
#include "amytiss/model.hpp"

namespace amytiss::detail {

/// `dynamics` without an integrator: the expressions are the discrete map.
std::unique_ptr<Dynamics> make_expression_dynamics(std::vector<Expression> expressions, std::size_t input_dims,
                                                   std::size_t disturbance_dims);
/// `dynamics` with `integrator.tau`: the expressions are dx/dt.
std::unique_ptr<VectorField> make_expression_field(std::vector<Expression> expressions, std::size_t input_dims,
                                                   std::size_t disturbance_dims);

}  // namespace amytiss::detail
