#include "host/system_engine.hpp"

#include <algorithm>

#include "amytiss/enclosure.hpp"
#include "amytiss/format.hpp"
#include "host/enclosure_mean_box.hpp"
#include "host/interval_step.hpp"
#include "host/row_bounds.hpp"

namespace amytiss::detail {

Policy run_system_bounds(const Abstraction& a, AmbiguitySet set, StepReporter& reporter) {
  const unsigned threads = set == AmbiguitySet::Joint ? 1u : host_threads();
  reporter.set_device(set == AmbiguitySet::Joint ? "reference"
                                                 : "host (" + std::to_string(threads) + " thread" +
                                                       (threads == 1 ? "" : "s") + ")");
  reporter.reached(Phase::Setup);
  const auto construction_start = SteadyClock::now();
  const SetupPoll poll = [&reporter] { reporter.reached(Phase::Setup); };
  std::vector<CellRole> lower_roles = robust_cell_roles(a.states, a.config.spec, Bound::Lower, poll);
  std::vector<CellRole> upper_roles = robust_cell_roles(a.states, a.config.spec, Bound::Upper, poll);
  const std::string targets = lower_targets_text(lower_roles, a.config.spec.type);
  const bool no_target = std::none_of(lower_roles.begin(), lower_roles.end(),
                                      [](CellRole role) { return role == CellRole::FixedOne; });
  if (!targets.empty())
    reporter.report().notes.push_back(
        {no_target ? NoteSeverity::Warning : NoteSeverity::Info, NoteKind::Transitions, targets});
  std::vector<bool> needed(a.states.size());
  for (std::size_t x = 0; x < needed.size(); ++x)
    needed[x] = lower_roles[x] == CellRole::Free || upper_roles[x] == CellRole::Free;
  const ImageEnclosure enclosure(a.config);
  const RowBounds rows(a.states, a.inputs, a.disturbances, *a.noise,
                       enclosure_mean_box(enclosure, a.states, a.inputs, a.disturbances), needed, threads,
                       bounds_reads(a));
  const double construction_seconds = seconds_since(construction_start);
  reporter.phase(PhaseKind::Construction, "interval bounds", construction_seconds,
                 double(a.pairs()) / std::max(construction_seconds, 1e-9));
  reporter.report().transitions = "interval bounds per dimension: " + format_bytes(double(rows.bytes())) +
                                  " on the host (" + std::to_string(rows.intervals()) + " mass intervals)";
  reporter.reached(Phase::Construction);
  // The backward driver runs the two bounds' steps one after the other: one set of sweep buffers.
  const auto sweep_buffers = std::make_shared<SweepBuffers>();
  IntervalStep lower(a, rows, std::move(lower_roles), Bound::Lower, set, threads, sweep_buffers);
  IntervalStep upper(a, rows, std::move(upper_roles), Bound::Upper, set, threads, sweep_buffers);
  reporter.report().notes.push_back(
      {NoteSeverity::Info, NoteKind::Transitions,
       "continuous-system bounds: image enclosures of every cell, " + std::to_string(rows.intervals()) +
           " per-dimension mass intervals (" + format_bytes(double(rows.bytes())) + "), " + lower.method() +
           " on " + std::to_string(threads) + " host thread" + (threads == 1 ? "" : "s")});
  Policy policy = run_backward_bounds(a, lower, upper, reporter);
  // The steps' time by stage of the variable elimination, both bounds together.
  const auto lower_stages = lower.stage_seconds(), upper_stages = upper.stage_seconds();
  for (std::size_t i = 0; i < lower_stages.size() && i < upper_stages.size(); ++i)
    reporter.phase(PhaseKind::Breakdown, lower_stages[i].first, lower_stages[i].second + upper_stages[i].second);
  return policy;
}

std::string lower_targets_text(const std::vector<CellRole>& lower_roles, SpecType spec) {
  if (spec == SpecType::Safety) return "";
  const auto inside = std::size_t(std::count(lower_roles.begin(), lower_roles.end(), CellRole::FixedOne));
  std::string text = std::to_string(inside) + " of " + std::to_string(lower_roles.size()) +
                     " cells lie wholly inside the target (the lower bound's target cells)";
  if (inside == 0)
    text += ": the lower bound is 0 everywhere; draw the target on the cells' faces, lb + (k +- 1/2) eta";
  return text;
}

}  // namespace amytiss::detail
