#pragma once
// What the bounds engine (guarantee: system) takes of the host's memory at its peak, from the
// sizes alone, before anything is allocated (docs/engine.md, "The plan"): the row bounds' index,
// their mass intervals and the construction's tables, then the method's buffers. Where a size
// depends on the row bounds themselves (how many rows share a mean box), it counts the most the
// sizes allow; `auto` counts the dearest of the methods it may choose.
#include <string>

#include "amytiss/abstraction.hpp"

namespace amytiss::detail {

struct BoundsMemory {
  double cells_bytes = 0;   ///< per cell: both bounds' roles and the upper bound's inputs
  double rows_bytes = 0;    ///< the row bounds: index, suffix classes and mass intervals
  double build_bytes = 0;   ///< the row bounds' construction: the workers' tables of distinct keys
  double method_bytes = 0;  ///< the method's buffers (stage tables, tensors and Q, or caches)
  std::string method;       ///< the method counted
  /// The peak: the construction's tables are gone before the method's buffers are taken.
  double peak() const { return cells_bytes + rows_bytes + (build_bytes > method_bytes ? build_bytes : method_bytes); }
};

/// For `method` (auto: the dearest that auto may choose) on `threads` workers.
BoundsMemory estimate_bounds_memory(const Abstraction& abstraction, BoundsMethod method, unsigned threads);

}  // namespace amytiss::detail
