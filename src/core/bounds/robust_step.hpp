#pragma once
// The robust Bellman step of the interval MDP (docs/semantics.md, "Interval transition bounds"):
//   out(x) = max_u min_w  min (Lower) / max (Upper) over the row's ambiguity set of E[in(x')]
// on Free cells, fixed cells holding their role's value; the step every engine of continuous-
// system bounds runs through the backward driver, on the host's cores.
#include <atomic>
#include <cstdint>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "amytiss/abstraction.hpp"
#include "solve/bellman_step.hpp"
#include "bounds/omax/robust_expectation.hpp"
#include "bounds/product/whole_tables.hpp"
#include "bounds/product/elimination.hpp"
#include "bounds/cell_roles.hpp"
#include "bounds/method.hpp"
#include "bounds/row_bounds.hpp"

namespace amytiss::detail {

class RobustStep : public BellmanStep {
 public:
  /// At most this many entries (8 bytes each) in the caches of the product set's stages.
  static constexpr std::size_t kMaxStageCacheEntries = std::size_t(1) << 24;
  /// `roles`: the bound's cell roles (robust_cell_roles()); `rows` must hold every Free cell's rows.
  /// `sweep_buffers`: shared with the steps over the same rows that never run at the same time as
  /// this one (ProductSweep); null: its own.
  /// `choice`: the method (choose_bounds_method()), the same for both bounds.
  RobustStep(const Abstraction& abstraction, const RowBounds& rows, std::vector<CellRole> roles, Bound bound,
             const MethodChoice& choice, unsigned threads, std::shared_ptr<SweepBuffers> sweep_buffers = nullptr);
  void apply(const double* in, double* out, std::uint32_t* chosen) override;
  /// The step of one stationary controller (certification): out(x) = min_w of the bound's
  /// expectation with input controller[x]; fixed cells hold their role's value.
  void evaluate(const double* in, double* out, const std::uint32_t* controller) override;
  /// The O-maximisation's outward rounding keeps the sequences apart by at most this.
  double resolution() const override { return 1e-12; }
  const std::vector<CellRole>& roles() const { return roles_; }
  BoundsMethod bounds_method() const { return choice_.method; }
  /// How the step computes the rows' bounds, for the notes: the method, why, and the variable
  /// elimination's order.
  std::string method() const;
  /// The variable elimination's stages, a pair as one ("stage 0 (x'1, all steps)", "stages 1-2
  /// (x'0 x'2, all steps)"), with their seconds over every step so far; empty without it.
  std::vector<std::pair<std::string, double>> stage_seconds() const;

 private:
  double expectation(std::size_t row, const double* in, ProductScratch& scratch) const;
  // Min over disturbances of the rows' bounds: from the variable elimination's Q (after its
  // prepare()) where there is one, else row by row.
  double worst_case(std::size_t cell, std::size_t input, const double* in, ProductScratch& scratch) const;
  // At least worst_case() (sweep only): min over disturbances of ProductSweep::upper_estimate().
  double estimate(std::size_t cell, std::size_t input) const;
  // The cell's best worst case over the inputs, and the input that gives it into `chosen`;
  // `estimates`: scratch.
  double choose(std::size_t cell, const double* in, ProductScratch& scratch, std::vector<double>& estimates,
                std::uint32_t& chosen) const;
  // What a step over `in` needs before its rows: the factored sweep's Q, or the sweep's tables
  // and emptied stage caches.
  void prepare(const double* in);
  void reset_stage_caches();
  void use_stage_caches(ProductScratch& scratch) const;
  const Abstraction& a_;
  const RowBounds& rows_;
  std::vector<CellRole> roles_;
  Bound bound_;
  MethodChoice choice_;
  unsigned threads_;
  // The product set's stages per (window line, suffix class), shared by the rows of one step
  // (ProductScratch::caches); per dimension, empty where it would not pay.
  std::vector<std::unique_ptr<std::atomic<double>[]>> stage_caches_;
  std::vector<std::size_t> stage_cache_entries_;
  // The product set over whole tables where it pays (bounds/product/whole_tables.hpp); then no caches.
  std::unique_ptr<ProductSweep> sweep_;
  // Else the product set by variable elimination where the factored sweep has a plan
  // (bounds/product/elimination.hpp); then no caches either.
  std::unique_ptr<RobustFactoredSweep> factored_;
  static constexpr std::uint32_t kNoChoice = ~std::uint32_t(0);
  std::vector<std::uint32_t> last_choice_;  // per cell, the input apply() chose last (sweep only)
  std::vector<std::uint32_t> visit_order_;  // the order apply() visits the cells in (sweep only)
};

}  // namespace amytiss::detail
