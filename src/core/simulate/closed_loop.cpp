#include "amytiss/closed_loop.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "common/parallel_for.hpp"

namespace amytiss {
namespace {

constexpr std::size_t kEpisodeEnds = std::size_t(EpisodeEnd::StepLimit) + 1;

EpisodeEnd end_of(SetVerdict verdict) {
  switch (verdict) {
    case SetVerdict::Target: return EpisodeEnd::Target;
    case SetVerdict::Avoid: return EpisodeEnd::Avoid;
    case SetVerdict::Obstacle: return EpisodeEnd::Obstacle;
    case SetVerdict::Unsafe: return EpisodeEnd::Unsafe;
    case SetVerdict::OutsideGrid:
    default: return EpisodeEnd::OutsideGrid;
  }
}

}  // namespace

std::vector<double> point_in_cell(const Grid& states, std::size_t cell, std::mt19937_64& random) {
  std::vector<std::size_t> multi(states.dims());
  states.multi_index(cell, multi.data());
  std::vector<double> point(states.dims());
  for (std::size_t d = 0; d < states.dims(); ++d) {
    const auto k = std::int64_t(multi[d]);
    point[d] = std::uniform_real_distribution<double>(states.face(d, k), states.face(d, k + 1))(random);
  }
  return point;
}

namespace {

// sqrt(p (1 - p) / n): the standard error of a rate over n trials whose true value is p.
double binomial_spread(double p, std::size_t n) {
  return n ? std::sqrt(std::max(0.0, p * (1 - p)) / double(n)) : 0.0;
}

}  // namespace

std::string to_string(EpisodeEnd end) {
  switch (end) {
    case EpisodeEnd::Target: return "reached the target";
    case EpisodeEnd::Avoid: return "entered the avoid set";
    case EpisodeEnd::Obstacle: return "touched an obstacle";
    case EpisodeEnd::Unsafe: return "left the safe set";
    case EpisodeEnd::OutsideGrid: return "left the grid";
    case EpisodeEnd::HorizonOver: return "horizon over";
    case EpisodeEnd::StepLimit:
    default: return "step limit";
  }
}

ClosedLoop::ClosedLoop(const Config& config, const Policy& policy, DisturbanceDraw draw, unsigned step_limit)
    : policy_(policy),
      plant_(config, draw),
      sets_(config),
      safety_(config.spec.type == SpecType::Safety),
      step_limit_(step_limit) {
  if (policy.states.dims() != plant_.state_dims() || policy.inputs.dims() != plant_.input_dims())
    throw std::invalid_argument("ClosedLoop: the policy's grids (" + std::to_string(policy.states.dims()) +
                                " state, " + std::to_string(policy.inputs.dims()) +
                                " input dimensions) are not the configuration's");
}

Episode ClosedLoop::run(const std::vector<double>& start, std::mt19937_64& random, const StateObserver& observer) const {
  std::vector<double> state = start, next(state.size()), input(policy_.inputs.dims());
  for (unsigned step = 0;; ++step) {
    if (observer) observer(step, state.data());
    const SetVerdict verdict = sets_.judge(state.data());
    if (verdict != SetVerdict::Undecided) return {verdict == SetVerdict::Target, end_of(verdict), step};
    if (policy_.stationary ? step >= step_limit_ : step >= policy_.horizon)
      return {safety_, policy_.stationary ? EpisodeEnd::StepLimit : EpisodeEnd::HorizonOver, step};
    double value = 0.0;
    const LookupStatus status =
        policy_.lookup(state.data(), state.size(), policy_.stationary ? 0 : step, input.data(), &value);
    // The state lies in the grid (judge() said so) and the step before the horizon.
    if (status != LookupStatus::Ok)
      throw std::logic_error("ClosedLoop: " + policy_.describe(status, state.data(), state.size(), step));
    plant_.step(state.data(), input.data(), next.data(), random);
    state.swap(next);
  }
}

double SimulationResult::standard_error() const { return binomial_spread(rate(), episodes); }

bool SimulationResult::consistent_with_lower(double lower, double standard_errors) const {
  const double spread = std::max(standard_error(), binomial_spread(lower, episodes));
  return lower <= rate() + standard_errors * spread;
}

bool SimulationResult::consistent_with_upper(double upper, double standard_errors) const {
  const double spread = std::max(standard_error(), binomial_spread(upper, episodes));
  return rate() - standard_errors * spread <= upper;
}

std::uint64_t episode_seed(std::uint64_t seed, std::size_t episode) {
  // SplitMix64 (Steele, Lea and Flood, 2014) of the seed advanced by the episode: neighbouring
  // episodes get unrelated generator states.
  std::uint64_t z = seed + (std::uint64_t(episode) + 1) * 0x9e3779b97f4a7c15ULL;
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

SimulationResult simulate_cell(const ClosedLoop& loop, std::size_t cell, std::size_t episodes, std::uint64_t seed,
                               unsigned threads) {
  if (episodes == 0 || episodes > kMaxSimulatedEpisodes)
    throw std::invalid_argument("simulate_cell: got " + std::to_string(episodes) + " episodes, expected 1 to " +
                                std::to_string(kMaxSimulatedEpisodes));
  const Grid& states = loop.policy().states;
  if (cell >= states.size())
    throw std::invalid_argument("simulate_cell: cell " + std::to_string(cell) + " is not one of the grid's " +
                                std::to_string(states.size()));
  const unsigned parts = threads ? threads : detail::host_threads();
  std::vector<std::vector<std::size_t>> part_ends(parts, std::vector<std::size_t>(kEpisodeEnds, 0));
  std::vector<std::size_t> part_successes(parts, 0);
  detail::parallel_for(episodes, parts, [&](unsigned part, std::size_t first, std::size_t last) {
    for (std::size_t e = first; e < last; ++e) {
      std::mt19937_64 random(episode_seed(seed, e));
      const Episode episode = loop.run(point_in_cell(states, cell, random), random);
      part_successes[part] += episode.success;
      part_ends[part][std::size_t(episode.end)] += 1;
    }
  });
  SimulationResult result;
  result.episodes = episodes;
  result.ends.assign(kEpisodeEnds, 0);
  for (unsigned part = 0; part < parts; ++part) {
    result.successes += part_successes[part];
    for (std::size_t k = 0; k < kEpisodeEnds; ++k) result.ends[k] += part_ends[part][k];
  }
  return result;
}

}  // namespace amytiss
