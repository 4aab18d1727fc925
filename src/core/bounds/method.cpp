#include "bounds/method.hpp"

#include "amytiss/errors.hpp"
#include "bounds/product/elimination.hpp"
#include "bounds/product/whole_tables.hpp"

namespace amytiss::detail {
namespace {

[[noreturn]] void refuse(BoundsMethod method, const std::string& why) {
  throw ConfigError("compute.bounds_method", "'" + to_string(method) + "' cannot run here: " + why +
                                                 "; expected a method that can, e.g. bounds_method: auto");
}

}  // namespace

MethodChoice choose_bounds_method(const Abstraction& a, const RowBounds& rows, BoundsMethod requested) {
  MethodChoice choice;
  if (requested != BoundsMethod::Auto) {
    if (requested == BoundsMethod::WholeTables && !ProductSweep::fits(a.states, rows))
      refuse(requested, "its tables need more than " + std::to_string(ProductSweep::kMaxTableEntries) + " entries");
    if (requested == BoundsMethod::Elimination) {
      std::string no_plan;
      choice.plan = RobustFactoredSweep::plan(a, &no_plan);
      if (!choice.plan) refuse(requested, no_plan);
    }
    choice.method = requested;
    choice.reason = "forced by compute.bounds_method";
    return choice;
  }
  if (ProductSweep::pays(a.states, rows, a.triples())) {
    choice.method = BoundsMethod::WholeTables;
    choice.reason = "auto: its tables fit and pay";
    return choice;
  }
  std::string no_plan;
  choice.plan = RobustFactoredSweep::plan(a, &no_plan);
  choice.method = choice.plan ? BoundsMethod::Elimination : BoundsMethod::Rows;
  choice.reason = choice.plan ? "auto: the whole tables do not pay" : "auto: no variable elimination: " + no_plan;
  return choice;
}

std::string method_text(BoundsMethod method) {
  switch (method) {
    case BoundsMethod::WholeTables: return "the product set over whole tables";
    case BoundsMethod::Elimination: return "the product set by variable elimination";
    case BoundsMethod::Rows: return "the product set row by row";
    case BoundsMethod::Joint: return "the joint interval MDP row by row";
    case BoundsMethod::Auto: break;
  }
  return "auto";
}

}  // namespace amytiss::detail
