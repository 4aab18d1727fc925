#pragma once
// The `refine` section of a configuration (docs/refinement.md).
#include <cstdint>

#include <yaml-cpp/yaml.h>

#include "amytiss/config.hpp"

namespace amytiss::detail {

/// Reads `refine` without judging the values (config/yaml.cpp's rules: the key in every error).
RefineConfig read_refine(const YAML::Node& node);
/// Config::validate()'s checks of `refine` on the fitted state grid: guarantee system, the `at`
/// points inside the grid, gap in (0, 1), max_states 0 or at least the grid's cells, max_rounds
/// 1..100, max_seconds > 0.
void check_refine(const Config& config, const GridSpec& fitted);

}  // namespace amytiss::detail
