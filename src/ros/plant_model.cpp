#include "plant_model.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>

namespace amytiss_ros {

PlantModel::PlantModel(const amytiss::Config& config, std::uint64_t seed)
    : plant_(config, amytiss::DisturbanceDraw::Box), random_(seed) {}

std::vector<double> PlantModel::step(const std::vector<double>& state, const std::vector<double>& input) {
  return plant_.step(state, input, random_);
}

amytiss::SetVerdict classify_state(const amytiss::SpecSets& sets, const std::vector<double>& state) {
  if (state.size() != sets.states().dims()) return amytiss::SetVerdict::OutsideGrid;
  return sets.judge(state.data());
}

std::optional<amytiss::VehicleOutline> vehicle_outline(const amytiss::Config& config) {
  for (const auto& model : amytiss::builtin_models())
    if (model.name == config.model) return model.outline;
  return std::nullopt;
}

std::string vehicle_motion_text(const amytiss::VehicleOutline& outline, const std::vector<double>& first,
                                const std::vector<double>& last) {
  constexpr double kDegreesPerRadian = 180.0 / M_PI;
  char text[160];
  std::snprintf(text, sizeof text, " (yaw changed by %.1f degrees, moved %.2f m along x and %.2f m along y)",
                (last.at(outline.yaw_index) - first.at(outline.yaw_index)) * kDegreesPerRadian,
                last.at(outline.x_index) - first.at(outline.x_index), last.at(outline.y_index) - first.at(outline.y_index));
  return text;
}

namespace {

constexpr double kStandardErrors = 4.0;

// kStandardErrors binomial standard errors of a rate over `episodes` whose true value is p.
double rate_tolerance(double p, unsigned episodes) {
  return episodes ? kStandardErrors * std::sqrt(p * (1 - p) / episodes) : 0.0;
}

}  // namespace

std::string consistency_text(unsigned successes, unsigned episodes, double predicted) {
  const double rate = episodes ? double(successes) / episodes : 0.0;
  const double bound = rate_tolerance(predicted, episodes);
  const double difference = std::abs(rate - predicted);
  char text[200];
  std::snprintf(text, sizeof text, "|rate - V_0| = %.4f, 4 standard errors of V_0 over %u episodes = %.4f: %s",
                difference, episodes, bound, difference <= bound ? "consistent" : "NOT consistent");
  return text;
}

std::string bounds_consistency_text(unsigned successes, unsigned episodes, double lower, double upper) {
  const double rate = episodes ? double(successes) / episodes : 0.0;
  const double low = std::max(0.0, lower - rate_tolerance(lower, episodes));
  const double high = std::min(1.0, upper + rate_tolerance(upper, episodes));
  char text[200];
  std::snprintf(text, sizeof text,
                "rate %.4f against [lower - 4 standard errors, upper + 4 standard errors] = [%.4f, %.4f] over %u "
                "episodes: %s",
                rate, low, high, episodes, low <= rate && rate <= high ? "consistent" : "NOT consistent");
  return text;
}

EpisodeOutcome episode_outcome(amytiss::SpecType spec, amytiss::SetVerdict verdict, unsigned step) {
  if (verdict != amytiss::SetVerdict::Undecided)
    return {verdict == amytiss::SetVerdict::Target, amytiss::to_string(verdict) + " at step " + std::to_string(step)};
  if (spec == amytiss::SpecType::Safety)
    return {true, "stayed safe for all " + std::to_string(step) + " steps (horizon over)"};
  return {false, "horizon over after " + std::to_string(step) + " steps without reaching the target"};
}

}  // namespace amytiss_ros
