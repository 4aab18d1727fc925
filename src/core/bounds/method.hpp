#pragma once
// Which method the bounds engine runs for the rows' robust expectations (docs/engine.md, "The
// bounds' methods"): the choice of `auto`, or the one the configuration forces, checked.
#include <optional>
#include <string>

#include "amytiss/abstraction.hpp"
#include "amytiss/config.hpp"
#include "bounds/row_bounds.hpp"
#include "factored/factored_plan.hpp"

namespace amytiss::detail {

struct MethodChoice {
  BoundsMethod method = BoundsMethod::Rows;  ///< never Auto
  std::optional<FactoredPlan> plan;          ///< Elimination: its plan
  std::string reason;                        ///< why, for the notes
};

/// `requested` Auto: whole tables where ProductSweep::pays() for `rows`, else variable elimination
/// where RobustFactoredSweep::plan() has a plan, else row by row. A forced method that cannot run
/// (whole tables that do not fit, an elimination without a plan) is a ConfigError naming
/// compute.bounds_method.
MethodChoice choose_bounds_method(const Abstraction& abstraction, const RowBounds& rows, BoundsMethod requested);

/// For the notes: "the product set over whole tables", "the joint interval MDP row by row", ...
std::string method_text(BoundsMethod method);

}  // namespace amytiss::detail
