#pragma once
// What the bounds engine (guarantee: system) takes of the host's memory at its peak, from the
// sizes alone, before anything is allocated (docs/engine.md, "The plan"): the row bounds' index,
// their mass intervals and the construction's tables, then the method's buffers. Where a size
// depends on the row bounds themselves (how many rows share a mean box), it counts them from the
// mean boxes alone (up to a budget; beyond, the most the sizes allow), and `auto` counts the
// method it will take (beyond the budget, the dearest of those it may take).
#include <string>

#include "amytiss/abstraction.hpp"

namespace amytiss::detail {

struct BoundsMemory {
  double cells_bytes = 0;   ///< per cell: both bounds' roles and the upper bound's inputs
  double rows_bytes = 0;    ///< the row bounds: index, suffix classes and mass intervals
  double build_bytes = 0;   ///< the row bounds' construction: the workers' tables of distinct keys
  double method_bytes = 0;  ///< the method's buffers (stage tables, tensors and Q, or caches)
  std::string method;       ///< the method counted
  /// What the buffers counted leave out: small temporaries and the heap's fragmentation (the
  /// tested shapes measure 3 to 5% above the count).
  static constexpr double kUncountedFactor = 1.25;
  /// The peak: the construction's tables are gone (given back to the system) before the method's
  /// buffers are taken.
  double peak() const {
    return kUncountedFactor * (cells_bytes + rows_bytes + (build_bytes > method_bytes ? build_bytes : method_bytes));
  }
};

/// For `method` (auto: the dearest that auto may choose) on `threads` workers.
BoundsMemory estimate_bounds_memory(const Abstraction& abstraction, BoundsMethod method, unsigned threads);

}  // namespace amytiss::detail
