#pragma once
// The closed loop of a served controller and the concrete plant, without ROS (docs/cli.md,
// "Simulating the closed loop"): from a continuous state, each step the policy's input for the
// state's cell (Policy::lookup, as the policy server serves it) and one step of the Plant; the
// episode ends when the state leaves the grid, touches an obstacle, leaves the safe set, enters
// the avoid set or the target (SpecSets, the configuration's own sets), or when the horizon is
// over. Monte Carlo runs of it estimate the probability that the continuous-system bounds enclose.
#include <cstddef>
#include <cstdint>
#include <functional>
#include <random>
#include <string>
#include <vector>

#include "amytiss/config.hpp"
#include "amytiss/plant.hpp"
#include "amytiss/policy.hpp"
#include "amytiss/spec_sets.hpp"

namespace amytiss {

/// Steps after which an episode of a stationary policy (horizon: infinite) that is still undecided
/// ends: reach specifications count it as a failure, safety as a success (StepLimit).
constexpr unsigned kUnboundedStepLimit = 10000;
/// The most episodes simulate_cell() runs in one call.
constexpr std::size_t kMaxSimulatedEpisodes = 10000000;

/// How an episode ended: the verdict of the state that decided it, or the horizon (the step
/// limit, for a stationary policy) with the state still undecided.
enum class EpisodeEnd { Target, Avoid, Obstacle, Unsafe, OutsideGrid, HorizonOver, StepLimit };
std::string to_string(EpisodeEnd end);

struct Episode {
  bool success = false;
  EpisodeEnd end = EpisodeEnd::HorizonOver;
  unsigned steps = 0;  ///< plant steps taken before the end
};

/// Called with every state an episode passes through, its step first: the start (step 0), each
/// later state, and the state that ends the episode (state dims values).
using StateObserver = std::function<void(unsigned step, const double* state)>;

class ClosedLoop {
 public:
  /// `config` passed Config::validate() and `policy` was computed from it; the policy must outlive
  /// the loop. `draw`: how the plant draws disturbances (GridPoints: those the bounds cover).
  /// `step_limit`: kUnboundedStepLimit unless a test asks for fewer (stationary policies only).
  ClosedLoop(const Config& config, const Policy& policy, DisturbanceDraw draw = DisturbanceDraw::GridPoints,
             unsigned step_limit = kUnboundedStepLimit);
  /// One episode from `start` (state dims values), its draws from `random`. Const: episodes may
  /// run on several threads, each with its own generator.
  /// With `observer`, it sees every state of the episode.
  Episode run(const std::vector<double>& start, std::mt19937_64& random, const StateObserver& observer = {}) const;
  const Policy& policy() const { return policy_; }
  const SpecSets& sets() const { return sets_; }

 private:
  const Policy& policy_;
  Plant plant_;
  SpecSets sets_;
  bool safety_ = false;
  unsigned step_limit_ = kUnboundedStepLimit;
};

/// The outcome of simulate_cell(): how many episodes succeeded, how they ended.
struct SimulationResult {
  std::size_t episodes = 0, successes = 0;
  std::vector<std::size_t> ends;  ///< episodes per EpisodeEnd, indexed by its value
  double rate() const { return episodes ? double(successes) / double(episodes) : 0.0; }
  /// The binomial standard error of rate(), sqrt(p (1 - p) / N) at p = rate().
  double standard_error() const;
  std::size_t ended(EpisodeEnd end) const { return ends.at(std::size_t(end)); }
  /// Whether the rate is consistent with a lower bound of the true probability: lower <= rate +
  /// `standard_errors` standard errors, the standard error the larger of the rate's and the one a
  /// true value at the bound would have (so that a rate of exactly 0 or 1 is judged by the
  /// bound's spread).
  bool consistent_with_lower(double lower, double standard_errors) const;
  /// The same for an upper bound: rate - `standard_errors` standard errors <= upper.
  bool consistent_with_upper(double upper, double standard_errors) const;
};

/// `episodes` episodes (1..kMaxSimulatedEpisodes; std::invalid_argument otherwise) from start
/// states drawn uniformly in the box of state cell `cell` (its faces, Grid::face). Episode e draws
/// its start and its steps from a generator seeded by `seed` and e alone: the result depends on
/// the seed and the count only, not on how many threads ran them (`threads`, 0: the host's).
SimulationResult simulate_cell(const ClosedLoop& loop, std::size_t cell, std::size_t episodes, std::uint64_t seed,
                               unsigned threads = 0);

/// A point drawn uniformly in the box of state cell `cell` (between its faces in every dimension).
std::vector<double> point_in_cell(const Grid& states, std::size_t cell, std::mt19937_64& random);

/// The seed of episode `episode` of a run with seed `seed` (SplitMix64 of both).
std::uint64_t episode_seed(std::uint64_t seed, std::size_t episode);

}  // namespace amytiss
