#pragma once
// The finite MDP abstraction of a configuration: grids, dynamics, noise and the cell roles of the
// specification. Every engine takes this and returns a Policy.
//
// Safety, reachability and reach-avoid share one recursion. Each state cell has a role:
//   Free:      V_k(x) = max_u min_w sum_{x'} T(x'|x,u,w) V_{k+1}(x')
//   FixedOne:  V_k(x) = 1 for all k      (reach: the target G)
//   FixedZero: V_k(x) = 0 for all k      (avoid set A; safety: cells outside S)
// Terminal values V_{T_d}: safety 1 on Free cells; reach(-avoid) 0 on Free cells. Mass leaving
// the grid counts 0. This is exactly the paper's definitions (docs/semantics.md; for reach-avoid, G counts 1
// and A counts 0 inside the sum, and V = 1 on G, 0 on A).
#include <cstdint>
#include <memory>
#include <vector>

#include "amytiss/config.hpp"
#include "amytiss/footprint.hpp"
#include "amytiss/grid.hpp"
#include "amytiss/model.hpp"
#include "amytiss/noise.hpp"
#include "amytiss/synthesis_types.hpp"

namespace amytiss {

enum class CellRole : std::uint8_t { Free = 0, FixedZero = 1, FixedOne = 2 };

struct Abstraction {
  Config config;
  Grid states;
  Grid inputs;        ///< zero dimensions (one point) for an autonomous system
  Grid disturbances;  ///< zero dimensions (one point) without disturbances
  std::shared_ptr<const Dynamics> dynamics;
  std::shared_ptr<const NoiseModel> noise;
  std::vector<CellRole> roles;  ///< per state cell (flat index)
  SpecType spec = SpecType::Safety;
  unsigned horizon = 0;  ///< T_d; 1 for an unbounded specification (one stationary step)
  bool unbounded = false;  ///< horizon: infinite (interval iteration, stationary policy)
  double tolerance = 0;    ///< unbounded: stop when upper - lower <= tolerance everywhere

  /// Builds from a configuration that passed Config::validate() (config_from_yaml and
  /// load_config_file validate; this does not judge it again). Throws std::logic_error when an
  /// invariant validate() guarantees does not hold (a bug of the caller). The footprint's test of
  /// the cells reports Phase::Setup to `progress` about every kPollSeconds; when it returns false,
  /// throws Cancelled.
  static Abstraction from_config(const Config& config, const ProgressCallback& progress = {});
  /// Builds from a validated configuration and given dynamics (tests: lambda dynamics) without
  /// make_dynamics(). Throws std::logic_error when what it uses (grids, noise, sets, horizon, the
  /// dynamics' dimensions) breaks an invariant of a validated configuration. `progress` as above.
  static Abstraction from_parts(const Config& config, std::shared_ptr<const Dynamics> dynamics,
                                const ProgressCallback& progress = {});

  /// V_{T_d} of a cell with the given role.
  double terminal_value(CellRole role) const;
  /// Number of (state, input) pairs and (state, input, disturbance) triples.
  std::size_t pairs() const { return states.size() * inputs.size(); }
  std::size_t triples() const { return pairs() * disturbances.size(); }
};

/// Roles of the state cells for a specification (a cell is in a set when its point lies in one of
/// the set's closed boxes). Safety: outside `safe` -> FixedZero (no `safe`: all Free). Reachability: target ->
/// FixedOne. Reach-avoid: avoid -> FixedZero, target -> FixedOne; a cell in both (a configuration
/// error that validate() rejects) is FixedZero: avoid is applied first and wins.
/// Throws std::logic_error for a missing target, a set without boxes or a box of the wrong
/// dimension (validate() refuses them). `poll`: as obstacle_cells() calls it.
std::vector<CellRole> cell_roles(const Grid& states, const SpecConfig& spec, const SetupPoll& poll = {});

}  // namespace amytiss
