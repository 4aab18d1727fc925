#include "bounds/system_engine.hpp"

#include <algorithm>

#include "amytiss/enclosure.hpp"
#include "amytiss/format.hpp"
#include "bounds/lattice.hpp"
#include "bounds/mean_box.hpp"
#include "bounds/method.hpp"
#include "bounds/robust_iteration.hpp"
#include "bounds/robust_step.hpp"
#include "bounds/row_bounds.hpp"
#include "common/host_memory.hpp"

namespace amytiss::detail {

Policy run_system_bounds(const Abstraction& a, BoundsMethod method, bool serial, StepReporter& reporter) {
  const unsigned threads = bounds_threads(serial);
  reporter.set_device(serial ? "reference"
                             : "host (" + std::to_string(threads) + " thread" + (threads == 1 ? "" : "s") + ")");
  reporter.reached(Phase::Setup);
  const auto construction_start = SteadyClock::now();
  const SetupPoll poll = [&reporter] { reporter.reached(Phase::Setup); };
  std::vector<CellRole> lower_roles = robust_cell_roles(a.states, a.config.spec, Bound::Lower, poll);
  std::vector<CellRole> upper_roles = robust_cell_roles(a.states, a.config.spec, Bound::Upper, poll);
  const RolesText kept = lower_roles_text(a.states, a.config.spec, lower_roles);
  if (!kept.text.empty())
    reporter.report().notes.push_back(
        {kept.warning ? NoteSeverity::Warning : NoteSeverity::Info, NoteKind::Transitions, kept.text});
  std::vector<bool> needed(a.states.size());
  for (std::size_t x = 0; x < needed.size(); ++x)
    needed[x] = lower_roles[x] == CellRole::Free || upper_roles[x] == CellRole::Free;
  const ImageEnclosure enclosure(a.config);
  const RowBounds rows(a.states, a.inputs, a.disturbances, *a.noise,
                       enclosure_mean_box(enclosure, a.states, a.inputs, a.disturbances), needed, threads,
                       bounds_reads(a));
  const std::string lattice = lattice_text(*a.noise, rows);
  if (!lattice.empty()) reporter.report().notes.push_back({NoteSeverity::Info, NoteKind::Transitions, lattice});
  const double construction_seconds = seconds_since(construction_start);
  reporter.phase(PhaseKind::Construction, "interval bounds", construction_seconds,
                 double(a.pairs()) / std::max(construction_seconds, 1e-9));
  reporter.report().transitions = "interval bounds per dimension: " + format_bytes(double(rows.bytes())) +
                                  " on the host (" + std::to_string(rows.intervals()) + " mass intervals)";
  reporter.reached(Phase::Construction);
  // The construction's tables are freed; without this they stay resident beside the method's buffers.
  release_free_heap();
  // The backward driver runs the two bounds' steps one after the other: one set of sweep buffers.
  const auto sweep_buffers = std::make_shared<SweepBuffers>();
  const MethodChoice choice = choose_bounds_method(a, rows, method);
  RobustStep lower(a, rows, std::move(lower_roles), Bound::Lower, choice, threads, sweep_buffers);
  RobustStep upper(a, rows, std::move(upper_roles), Bound::Upper, choice, threads, sweep_buffers);
  reporter.report().notes.push_back(
      {NoteSeverity::Info, NoteKind::Transitions,
       "continuous-system bounds: image enclosures of every cell, " + std::to_string(rows.intervals()) +
           " per-dimension mass intervals (" + format_bytes(double(rows.bytes())) + "), " + lower.method() +
           " on " + std::to_string(threads) + " host thread" + (threads == 1 ? "" : "s")});
  const UnboundedSolver unbounded = [&](const UnboundedRun& run, SynthesisReport& report) {
    return solve_unbounded_bounds(a, lower, lower.roles(), upper, upper.roles(), run, report);
  };
  const ValueSequence upper_sequence{upper, upper.roles()};
  Policy policy = run_backward(a, {lower, lower.roles()}, &upper_sequence, unbounded, reporter);
  // The steps' time by stage of the variable elimination, both bounds together.
  const auto lower_stages = lower.stage_seconds(), upper_stages = upper.stage_seconds();
  for (std::size_t i = 0; i < lower_stages.size() && i < upper_stages.size(); ++i)
    reporter.phase(PhaseKind::Breakdown, lower_stages[i].first, lower_stages[i].second + upper_stages[i].second);
  return policy;
}

namespace {

std::size_t count_role(const std::vector<CellRole>& roles, CellRole role) {
  return std::size_t(std::count(roles.begin(), roles.end(), role));
}

// Why the lower bound keeps no cell: none inside the set itself, or every one inside it avoided
// (by spec.avoid, else by the footprint). Only for that case: it redoes the roles without them.
std::string no_cell_reason(const Grid& states, const SpecConfig& spec, CellRole kept) {
  const bool safety = spec.type == SpecType::Safety;
  SpecConfig bare = spec;
  bare.avoid.reset();
  bare.obstacles.reset();
  bare.footprint.reset();
  const std::size_t inside = count_role(robust_cell_roles(states, bare, Bound::Lower), kept);
  if (inside == 0)
    return std::string("; draw the ") + (safety ? "safe set" : "target") + " on the cells' faces, lb + (k +- 1/2) eta";
  const std::string cells = std::to_string(inside) + " cell" + (inside == 1 ? "" : "s");
  if (!safety && spec.avoid) {
    bare.avoid = spec.avoid;
    if (count_role(robust_cell_roles(states, bare, Bound::Lower), kept) == 0)
      return "; the " + cells + " wholly inside the target all meet spec.avoid";
  }
  return "; the " + cells + " wholly inside the " + (safety ? "safe set" : "target") +
         " are all avoided: the footprint may touch an obstacle (spec.obstacles) at some pose of each";
}

}  // namespace

std::string lattice_text(const NoiseModel& noise, const RowBounds& rows) {
  std::string on, off;
  for (std::size_t d = 0; d < noise.dims(); ++d) {
    if (!noise_free(noise, d)) continue;
    std::string& list = rows.lattice(d) ? on : off;
    list += (list.empty() ? "" : ", ") + std::to_string(d);
  }
  std::string text;
  if (!on.empty())
    text = "noise-free state dimension(s) " + on +
           " move on the cells' lattice: point masses [1, 1] on the cell each row sends them to (the bounds hold "
           "for states more than n * 2^-36 eta inside their cells along them, n the steps behind the value)";
  if (!off.empty())
    text += (text.empty() ? "" : "; ") + std::string("noise-free state dimension(s) ") + off +
            " leave a cell's image over more than one cell somewhere: mass [0, 1] on each cell a mean box touches";
  return text;
}

RolesText lower_roles_text(const Grid& states, const SpecConfig& spec, const std::vector<CellRole>& lower_roles) {
  const bool safety = spec.type == SpecType::Safety;
  const CellRole kept = safety ? CellRole::Free : CellRole::FixedOne;
  const std::size_t count = count_role(lower_roles, kept);
  if (safety && count > 0) return {};
  RolesText out;
  out.text = std::to_string(count) + " of " + std::to_string(lower_roles.size()) +
             (safety ? " cells lie wholly inside the safe set (the lower bound's safe cells)"
                     : " cells lie wholly inside the target (the lower bound's target cells)");
  if (count > 0) return out;
  out.warning = true;
  out.text += ": the lower bound is 0 everywhere" + no_cell_reason(states, spec, kept);
  return out;
}

unsigned bounds_threads(bool serial) { return serial ? 1u : host_threads(); }

}  // namespace amytiss::detail
