#pragma once
// The factored sweep's mass tables (internal): one per post dimension, indexed by the tuple of
// the components that dimension reads.
#include <cstddef>
#include <cstdint>
#include <vector>

#include "amytiss/abstraction.hpp"
#include "factored/factored_plan.hpp"

namespace amytiss::detail {

/// Kept masses of one post dimension for every tuple of the variables it reads.
struct MassTable {
  std::vector<std::size_t> variables;  ///< S_i, tuple digits major to minor
  std::size_t width = 0;               ///< slots per tuple
  std::vector<std::uint32_t> first;    ///< per tuple: first kept cell
  std::vector<std::uint32_t> count;    ///< per tuple: kept cells (0: all mass leaves the grid)
  std::vector<double> masses;          ///< per tuple: width slots, mass of cell first + c at c
};

/// Exact (double) kept masses, as the reference engine computes them: the post coordinate from
/// the dynamics, its clipped truncation window, the noise's cell masses.
std::vector<MassTable> factored_mass_tables(const Abstraction& abstraction, const FactoredPlan& plan);

}  // namespace amytiss::detail
