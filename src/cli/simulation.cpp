#include "simulation.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "printing.hpp"

namespace amytiss::cli {
namespace {

// "0.009706 (2.7 standard errors)", or without the ratio when the rate has no spread.
std::string gap_text(double gap, double standard_error) {
  char text[96];
  if (standard_error > 0)
    std::snprintf(text, sizeof text, "%+.6f (%.1f standard errors)", gap, gap / standard_error);
  else
    std::snprintf(text, sizeof text, "%+.6f", gap);
  return text;
}

std::string ends_text(const SimulationResult& result) {
  std::string text;
  for (std::size_t k = 0; k < result.ends.size(); ++k) {
    if (!result.ends[k]) continue;
    text += (text.empty() ? "" : ", ") + to_string(EpisodeEnd(k)) + " " + std::to_string(result.ends[k]);
  }
  return text;
}

void print_comparison(const Policy& policy, const SimulationResult& result, double lower, double upper,
                      bool disturbed) {
  const double rate = result.rate(), error = result.standard_error();
  if (policy.guarantee != Guarantee::System) {
    std::printf("simulation: V_0 %.6f (the %s, of the cell): rate - V_0 = %s\n", lower, kAbstractionValueLabel,
                gap_text(rate - lower, error).c_str());
    return;
  }
  const bool lower_ok = result.consistent_with_lower(lower, kConsistencyStandardErrors);
  std::printf("simulation: certified lower bound %.6f (this policy): rate - lower = %s\n", lower,
              gap_text(rate - lower, error).c_str());
  if (disturbed) {
    std::printf("simulation: upper bound %.6f (any controller, against the worst disturbance; these episodes draw "
                "random disturbances, which may do better): upper - rate = %s\n",
                upper, gap_text(upper - rate, error).c_str());
    std::printf("simulation: %s with the lower bound within %.0f standard errors\n",
                lower_ok ? "consistent" : "NOT consistent", kConsistencyStandardErrors);
    return;
  }
  const bool upper_ok = result.consistent_with_upper(upper, kConsistencyStandardErrors);
  std::printf("simulation: upper bound %.6f (any controller): upper - rate = %s\n", upper,
              gap_text(upper - rate, error).c_str());
  std::printf("simulation: %s with both bounds within %.0f standard errors\n",
              lower_ok && upper_ok ? "consistent" : "NOT consistent", kConsistencyStandardErrors);
}

}  // namespace

void print_simulation(const Config& config, const Policy& policy, const std::vector<double>& state,
                      std::size_t episodes, std::uint64_t seed) {
  const auto cell = policy.states.cell_of(state.data());
  if (!cell) throw std::logic_error("print_simulation: the state " + format_values(state) + " lies outside the grid");
  const bool disturbed = config.disturbances.has_value();
  const ClosedLoop loop(config, policy, DisturbanceDraw::GridPoints);
  std::printf("simulation: %zu episodes of the continuous closed loop from uniform points of the cell of %s (seed "
              "%llu%s)\n",
              episodes, format_values(state).c_str(), static_cast<unsigned long long>(seed),
              disturbed ? "; disturbances uniform among the disturbance grid's points" : "");
  std::fflush(stdout);
  const SimulationResult result = simulate_cell(loop, *cell, episodes, seed);
  std::printf("simulation: success rate %zu/%zu = %.6f, standard error %.6f (sqrt(p (1 - p) / N))\n",
              result.successes, result.episodes, result.rate(), result.standard_error());
  if (policy.stationary)
    std::printf("simulation: stationary policy: an episode still undecided after %u steps ends there (%s)\n",
                kUnboundedStepLimit,
                config.spec.type == SpecType::Safety ? "counted as a success" : "counted as a failure");
  std::vector<double> input(policy.inputs.dims());
  double lower = 0.0, upper = 0.0;
  if (policy.lookup(state.data(), state.size(), 0, input.data(), &lower, &upper) != LookupStatus::Ok)
    throw std::logic_error("print_simulation: " + policy.describe(LookupStatus::OutsideGrid, state.data(),
                                                                  state.size(), 0));
  print_comparison(policy, result, lower, upper, disturbed);
  std::printf("simulation: ends: %s\n", ends_text(result).c_str());
}

}  // namespace amytiss::cli
