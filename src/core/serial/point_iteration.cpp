// Interval iteration for unbounded specifications. Why it is sound (docs/semantics.md,
// "Unbounded horizon"): the lower sequence starts below the value and the upper one above it, and
// the Bellman operator is monotone with the value as a fixed point, so both stay on their side;
// end-component corrections only use sets in which one player can keep the play, which bound
// the value by the best exit; the stored policy's own value is iterated from below on the host.
#include "serial/point_iteration.hpp"

#include <algorithm>
#include <chrono>

#include "amytiss/stopwatch.hpp"
#include "amytiss/format.hpp"
#include "amytiss/errors.hpp"
#include "serial/game_graph.hpp"
#include "serial/target_cell_inputs.hpp"
#include "solve/interval_iteration.hpp"

namespace amytiss::detail {
namespace {

using Clock = SteadyClock;

constexpr unsigned kMaxIterations = 100000;
// End components are looked for (on the host) every this many iterations.
constexpr unsigned kCorrectionPeriod = 8;
// Actions within this of a player's best count as its choices when end components are looked
// for; only convergence depends on it, never soundness (any end component gives a valid bound).
constexpr double kOptimalSlack = 1e-12;
// The iteration aims at half the tolerance, leaving the other half to the certified policy.
constexpr double kIterationShareOfTolerance = 0.5;
// Optimistic upper bounds (reachability): first tried at this iteration, then at twice the
// iterations after each failed try, once the lower bound moved by at most kSettledShare of the
// iteration's target in the last iteration; the guess lies kGuessShare of the target above it.
constexpr unsigned kFirstOptimisticTry = 256;
constexpr double kSettledShare = 0.01;
constexpr double kGuessShare = 0.5;
// The certification's step limit: kCertificationStepsBase + kCertificationStepsPerIteration * the
// iterations (its lower bound rises at least as fast as the iteration's did).
constexpr unsigned kCertificationStepsBase = 100;
constexpr unsigned kCertificationStepsPerIteration = 2;
// Relative error allowed for the host's sums of non-negative mass * value terms (the masses'
// own rounding and the summation's) when a guess is verified.
constexpr double kMassRelativeError = 1e-12;

// The state of the iteration between Bellman steps.
struct Iteration {
  const Abstraction& a;
  GameSupports& supports;
  ReferenceStep& host;
  std::vector<char> candidate;       // cells of end components (with every action allowed)
  std::vector<double>& lower;
  std::vector<double>& upper;
  std::vector<std::uint32_t> ec_input;     // safety: the input that keeps the play in its component
  std::vector<double> ec_value;            // the value the correction gave that cell (-1: none)

  // Reachability: U' = min(U, L + epsilon) bounds the value from above when T(U') <= U' (the
  // value is the least fixed point of T, below every pre-fixed point). Checked row by row on the
  // host as sum_x' T(x'|row) (U'(x') - U'(x)) - (mass off the grid) U'(x) <= 0, the positive and
  // the negative terms summed apart, so that rows whose mass stays among cells of the same guess
  // (near end components, where plain iteration crawls) pass exactly; for every input some
  // disturbance's row must pass.
  bool optimistic_upper(double epsilon) {
    const std::size_t n = a.states.size();
    std::vector<double> guess(n), above(n, 0.0), below(n, 0.0), ones(n, 1.0);
    for (std::size_t x = 0; x < n; ++x) guess[x] = std::min(upper[x], lower[x] + epsilon);
    const double absolute_error = a.noise->quadrature_error_bound();
    auto row_passes = [&](std::size_t rank, std::size_t u, std::size_t w) {
      const std::size_t r = supports.row(rank, u, w), x = supports.free_cell(rank);
      if (supports.empty(r)) return true;  // all its mass leaves the grid
      bool any_above = false;
      supports.for_each_cell(r, [&](std::size_t cell) {
        above[cell] = std::max(0.0, guess[cell] - guess[x]);
        below[cell] = std::max(0.0, guess[x] - guess[cell]);
        any_above = any_above || above[cell] > 0;
      });
      bool passes = !any_above;
      if (!passes) {
        const double lost = std::max(0.0, 1.0 - host.expected(x, u, w, ones.data()) - kMassRelativeError);
        const double rise = host.expected(x, u, w, above.data());
        const double fall = host.expected(x, u, w, below.data()) + lost * guess[x];
        // Each of the three sums may be off by the row's absolute mass error.
        const double row_error = absolute_error + a.noise->box_mass_tolerance() * double(supports.box_cells(r));
        passes = rise * (1 + kMassRelativeError) + 3 * row_error <= fall * (1 - kMassRelativeError);
      }
      supports.for_each_cell(r, [&](std::size_t cell) { above[cell] = below[cell] = 0.0; });
      return passes;
    };
    for (std::size_t rank = 0; rank < supports.free_cells(); ++rank) {
      if (guess[supports.free_cell(rank)] >= 1.0) continue;  // T never exceeds 1
      for (std::size_t u = 0; u < supports.inputs(); ++u) {
        bool passes = false;
        for (std::size_t w = 0; w < supports.disturbances() && !passes; ++w) passes = row_passes(rank, u, w);
        if (!passes) return false;
      }
    }
    for (std::size_t x = 0; x < n; ++x) upper[x] = std::min(upper[x], guess[x]);
    return true;
  }

  // Reachability: an end component the adversary can keep the play in (using its choices that
  // are optimal for the lower bound) is worth at most the controller's best way out.
  bool deflate_upper() {
    const std::size_t n = a.states.size();
    std::vector<std::vector<double>> q(n);
    for (std::size_t rank = 0; rank < supports.free_cells(); ++rank) {
      const std::size_t x = supports.free_cell(rank);
      if (!candidate[x]) continue;
      q[x].resize(supports.inputs() * supports.disturbances());
      for (std::size_t u = 0; u < supports.inputs(); ++u)
        for (std::size_t w = 0; w < supports.disturbances(); ++w)
          q[x][u * supports.disturbances() + w] = host.expected(x, u, w, lower.data());
    }
    const std::size_t W = supports.disturbances();
    auto all_inputs = [](std::size_t, std::size_t) { return true; };
    auto optimal_disturbance = [&](std::size_t x, std::size_t u, std::size_t w) {
      const double* row = &q[x][u * W];
      return row[w] <= *std::min_element(row, row + W) + kOptimalSlack;
    };
    const std::vector<std::int64_t> component = end_components(supports, n, candidate, all_inputs, optimal_disturbance);
    std::vector<double> best_exit;
    for (std::size_t rank = 0; rank < supports.free_cells(); ++rank) {
      const std::size_t x = supports.free_cell(rank);
      if (component[x] < 0) continue;
      if (best_exit.size() <= std::size_t(component[x])) best_exit.resize(std::size_t(component[x]) + 1, 0.0);
      for (std::size_t u = 0; u < supports.inputs(); ++u) {
        bool stays = false;
        for (std::size_t w = 0; w < W && !stays; ++w)
          stays = optimal_disturbance(x, u, w) && row_stays(supports, component, rank, u, w);
        if (!stays) best_exit[component[x]] = std::max(best_exit[component[x]], host.input_value(x, u, upper.data()));
      }
    }
    bool changed = false;
    for (std::size_t x = 0; x < n; ++x)
      if (component[x] >= 0 && best_exit[component[x]] < upper[x]) {
        upper[x] = best_exit[component[x]];
        changed = true;
      }
    return changed;
  }

  // Safety: an end component the controller can keep the play in (with its inputs optimal for
  // the upper bound) is worth at least the disturbance's worst way out (1 without one).
  bool inflate_lower() {
    const std::size_t n = a.states.size();
    std::vector<std::vector<double>> q(n);
    for (std::size_t rank = 0; rank < supports.free_cells(); ++rank) {
      const std::size_t x = supports.free_cell(rank);
      if (!candidate[x]) continue;
      q[x].resize(supports.inputs());
      for (std::size_t u = 0; u < supports.inputs(); ++u) q[x][u] = host.input_value(x, u, upper.data());
    }
    auto optimal_input = [&](std::size_t x, std::size_t u) {
      return q[x][u] >= *std::max_element(q[x].begin(), q[x].end()) - kOptimalSlack;
    };
    auto all_rows = [](std::size_t, std::size_t, std::size_t) { return true; };
    const std::vector<std::int64_t> component = end_components(supports, n, candidate, optimal_input, all_rows);
    std::vector<double> worst_exit;
    for (std::size_t rank = 0; rank < supports.free_cells(); ++rank) {
      const std::size_t x = supports.free_cell(rank);
      if (component[x] < 0) continue;
      if (worst_exit.size() <= std::size_t(component[x])) worst_exit.resize(std::size_t(component[x]) + 1, 1.0);
      bool input_found = false;
      for (std::size_t u = 0; u < supports.inputs(); ++u) {
        if (!optimal_input(x, u)) continue;
        std::vector<char> stays(supports.disturbances());
        bool any = false;
        for (std::size_t w = 0; w < supports.disturbances(); ++w)
          any |= stays[w] = row_stays(supports, component, rank, u, w);
        if (!any) continue;
        if (!input_found) ec_input[x] = std::uint32_t(u), input_found = true;
        for (std::size_t w = 0; w < supports.disturbances(); ++w)
          if (!stays[w])
            worst_exit[component[x]] = std::min(worst_exit[component[x]], host.expected(x, u, w, lower.data()));
      }
    }
    bool changed = false;
    for (std::size_t x = 0; x < n; ++x)
      if (component[x] >= 0 && worst_exit[component[x]] > lower[x]) {
        lower[x] = ec_value[x] = worst_exit[component[x]];
        changed = true;
      }
    return changed;
  }
};

// What the graph analysis settled before the iteration: the lower bounds it starts from, and for
// safety the cells that can stay safe surely with their inputs.
struct GraphStart {
  std::vector<double> initial_lower;
  std::vector<char> sure_safe;
  std::vector<std::uint32_t> sure_input;
  std::size_t component_cells = 0;
};

// Attractors: the value is exactly 0 outside the controller's positive attractor of the target,
// and exactly 1 where it can stay safe surely; then the end components among the undecided cells.
GraphStart analyse_graph(const Abstraction& a, GameSupports& supports, Iteration& it, SynthesisReport& report) {
  const std::size_t n = a.states.size();
  const auto start = Clock::now();
  GraphStart graph;
  graph.sure_safe.assign(n, 0);
  for (std::size_t x = 0; x < n; ++x) {
    it.lower[x] = a.roles[x] == CellRole::FixedOne ? 1.0 : 0.0;
    it.upper[x] = a.roles[x] == CellRole::FixedZero ? 0.0 : 1.0;
  }
  if (a.spec != SpecType::Safety) {
    const std::vector<char> attractor = positive_attractor(a, supports);
    for (std::size_t x = 0; x < n; ++x) {
      if (!attractor[x]) it.upper[x] = 0.0;
      it.candidate[x] = attractor[x] && a.roles[x] == CellRole::Free;
    }
  } else {
    graph.sure_safe = sure_safe_set(a, supports, graph.sure_input);
    for (std::size_t x = 0; x < n; ++x) {
      if (graph.sure_safe[x]) it.lower[x] = 1.0;
      it.candidate[x] = !graph.sure_safe[x] && a.roles[x] == CellRole::Free;
    }
  }
  graph.initial_lower = it.lower;
  auto every_input = [](std::size_t, std::size_t) { return true; };
  auto every_row = [](std::size_t, std::size_t, std::size_t) { return true; };
  const std::vector<std::int64_t> any_component = end_components(supports, n, it.candidate, every_input, every_row);
  for (std::size_t x = 0; x < n; ++x) {
    it.candidate[x] = any_component[x] >= 0;
    graph.component_cells += it.candidate[x];
  }
  report.phases.push_back({"graph analysis", seconds_since(start), 0, 0});
  report.notes.push_back(
      {NoteSeverity::Info, NoteKind::Convergence,
       graph.component_cells == 0
           ? std::string("unbounded: no end components among the undecided cells (the play leaves "
                         "them with probability 1): plain interval iteration")
           : "unbounded: " + std::to_string(graph.component_cells) +
                 " cells in end components, corrected on the host every " + std::to_string(kCorrectionPeriod) +
                 " iterations"});
  return graph;
}

// The point MDP's end-component corrections (every kCorrectionPeriod iterations) and, for
// reachability, its optimistic upper bounds, between the loop's iterations.
class EndComponentCorrections : public IterationCorrections {
 public:
  EndComponentCorrections(Iteration& it, bool reach, std::size_t component_cells, double target)
      : it_(it), reach_(reach), component_cells_(component_cells), target_(target) {}
  bool correct(unsigned iterations, double lower_change, std::vector<double>&, std::vector<double>&) override {
    bool changed = false;
    if (component_cells_ > 0 && iterations % kCorrectionPeriod == 0)
      changed = reach_ ? it_.deflate_upper() : it_.inflate_lower();
    if (reach_ && iterations >= next_optimistic_try_ && lower_change <= kSettledShare * target_) {
      next_optimistic_try_ = 2 * iterations;
      if (it_.optimistic_upper(kGuessShare * target_)) optimistic_at_ = iterations, changed = true;
    }
    return changed;
  }
  bool stall_is_final(unsigned iterations) const override {
    return component_cells_ == 0 || iterations % kCorrectionPeriod == 0;
  }
  unsigned optimistic_at() const { return optimistic_at_; }

 private:
  Iteration& it_;
  bool reach_;
  std::size_t component_cells_;
  double target_;
  unsigned next_optimistic_try_ = kFirstOptimisticTry, optimistic_at_ = 0;
};

IterationOptions point_options(const Abstraction& a) {
  IterationOptions options;
  options.max_iterations = kMaxIterations;
  options.target_gap = kIterationShareOfTolerance * a.tolerance;
  options.move_threshold = 0;
  options.input_rule = InputRule::OnGrowth;
  options.certification_steps_base = kCertificationStepsBase;
  options.certification_steps_per_iteration = kCertificationStepsPerIteration;
  options.certification_gap = a.tolerance;
  return options;
}

}  // namespace

Policy solve_unbounded(const Abstraction& a, BellmanStep& step, ReferenceStep& host, const UnboundedRun& run,
                       SynthesisReport& report) {
  const std::size_t n = a.states.size();
  const IterationOptions options = point_options(a);
  GameSupports supports(a);
  IterationState state;
  state.lower.assign(n, 0.0);
  state.upper.assign(n, 0.0);
  state.controller.assign(n, 0);
  Iteration it{a, supports, host, std::vector<char>(n, 0), state.lower, state.upper,
               std::vector<std::uint32_t>(n, 0), std::vector<double>(n, -1.0)};
  const GraphStart graph = analyse_graph(a, supports, it, report);

  const auto start = Clock::now();
  EndComponentCorrections corrections(it, a.spec != SpecType::Safety, graph.component_cells, options.target_gap);
  iterate(step, step, state, options, &corrections, run.on_iteration);
  if (state.status == IterationStatus::Cancelled) throw Cancelled();
  report.phases.push_back({"interval iteration (" + std::to_string(state.iterations) + " iterations)",
                           seconds_since(start), 0, step.multiply_adds() * 2.0 * state.iterations});
  if (corrections.optimistic_at() > 0)
    report.notes.push_back({NoteSeverity::Info, NoteKind::Convergence,
                            "unbounded: an optimistic upper bound (the lower bound + " +
                                format_significant(kGuessShare * options.target_gap) +
                                ") was verified (T(U) <= U) at iteration " +
                                std::to_string(corrections.optimistic_at())});

  // The stationary policy: greedy for the lower bound, the sure input where safety is sure, the
  // component's input where a correction set the lower bound.
  for (std::size_t x = 0; x < n; ++x) {
    if (graph.sure_safe[x]) state.controller[x] = graph.sure_input[x];
    else if (it.ec_value[x] >= 0 && state.lower[x] <= it.ec_value[x]) state.controller[x] = it.ec_input[x];
  }
  const auto certification_start = Clock::now();
  const Certificate certificate =
      certify(host, state.controller, graph.initial_lower, state.upper, state.iterations, options);
  report.phases.push_back({"policy certification (" + std::to_string(certificate.steps) + " steps)",
                           seconds_since(certification_start), 0, 0});
  report.notes.push_back(convergence_note("unbounded: " + std::to_string(state.iterations) +
                                              " iterations, upper - lower <= " + format_significant(state.gap) +
                                              " for the optimal value; the stationary policy ",
                                          certificate.gap, a.tolerance));
  return stationary_policy(a, a.roles, certificate, state.upper, state.controller, state.iterations,
                           run.device_label);
}

Policy run_abstraction_backward(const Abstraction& a, BellmanStep& step, StepReporter& reporter) {
  const UnboundedSolver unbounded = [&](const UnboundedRun& run, SynthesisReport& report) {
    ReferenceStep host(a);
    return solve_unbounded(a, step, host, run, report);
  };
  Policy policy = run_backward(a, {step, a.roles}, nullptr, unbounded, reporter);
  const TargetCellInputs targets = choose_target_cell_inputs(a, policy);
  if (targets.seconds > 0)
    reporter.phase(PhaseKind::Other, "target cells' inputs (" + std::to_string(targets.cells) + " cells, host)",
                   targets.seconds, 0, 0, 0, 0);
  return policy;
}

}  // namespace amytiss::detail
