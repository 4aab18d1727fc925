// The rounds of `refine` (docs/refinement.md): one synthesis per round through the one entry point
// synthesize(), the gap measured at the `at` states, the next grid from split_choice.hpp.
#include "amytiss/refinement.hpp"

#include <cmath>
#include <cstdio>
#include <limits>
#include <optional>
#include <stdexcept>

#include "amytiss/engine.hpp"
#include "amytiss/format.hpp"
#include "amytiss/grid.hpp"
#include "amytiss/grid_rules.hpp"
#include "amytiss/stopwatch.hpp"
#include "refine/split_choice.hpp"

namespace amytiss {
namespace {

using detail::SplitChoice;

std::uint64_t max_cells(const RefineConfig& refine, std::size_t first_cells) {
  if (refine.max_states != 0) return refine.max_states;
  return std::uint64_t(first_cells) * RefineConfig::kDefaultStatesFactor;
}

// The bounds at step 0 at each `at` state and the round's gap (the largest there; without `at`,
// the free cells' mean).
RefinementRound measure(const Policy& policy, const RefineConfig& refine) {
  RefinementRound round;
  round.states = policy.states.size();
  if (refine.at.empty()) {
    round.gap = summarize_bounds(policy).gap.mean;
    return round;
  }
  for (const auto& point : refine.at) {
    const std::optional<std::size_t> cell = policy.states.cell_of(point.data());
    if (!cell) throw std::logic_error("refine: an `at` state lies outside the grid (validate() refuses it)");
    round.lower.push_back(policy.value(0, *cell));
    round.upper.push_back(policy.upper_value(0, *cell));
    round.gap = std::max(round.gap, round.upper.back() - round.lower.back());
  }
  return round;
}

// Probabilities in the notes: six decimals, as the CLI prints bounds.
std::string probability_text(double value) {
  char text[32];
  std::snprintf(text, sizeof text, "%.6f", value);
  return text;
}

std::string round_text(std::size_t index, const RefinementRound& round, bool with_at) {
  std::string text = "refinement round " + std::to_string(index + 1) + ": " + std::to_string(round.states) +
                     " cells, gap " + probability_text(round.gap) + (with_at ? " at the at states" : " (free cells' mean)");
  for (std::size_t i = 0; i < round.lower.size(); ++i)
    text += (i ? "; " : " (lower, upper: ") + probability_text(round.lower[i]) + ", " + probability_text(round.upper[i]) +
            (i + 1 == round.lower.size() ? ")" : "");
  return text + ", " + format_significant(round.seconds) + " s";
}

ProgressCallback round_progress(const ProgressCallback& progress, unsigned round, unsigned rounds) {
  if (!progress) return {};
  return [progress, round, rounds](const Progress& step) {
    Progress numbered = step;
    numbered.round = round;
    numbered.max_rounds = rounds;
    return progress(numbered);
  };
}

// Why no further round runs after this one, or empty. `next` is the split choice for the next round.
std::string stop_reason(const RefineConfig& refine, const RefinementRound& round, std::size_t rounds_done,
                        const SplitChoice* next, double elapsed, double round_seconds) {
  if (round.gap <= refine.gap)
    return "gap " + probability_text(round.gap) + " <= " + format_number(refine.gap) + " reached";
  if (rounds_done >= refine.max_rounds)
    return "max_rounds " + std::to_string(refine.max_rounds) + " done, gap " + probability_text(round.gap) + " left";
  if (next->splits == 0) return next->why_none + ", gap " + probability_text(round.gap) + " left";
  // A round's time grows about with its cells.
  const double estimate = round_seconds * double(next->cells) / double(round.states);
  if (elapsed + estimate > refine.max_seconds)
    return "max_seconds " + format_number(refine.max_seconds) + ": the next round (" + std::to_string(next->cells) +
           " cells, about " + format_significant(estimate) + " s) would end after it, gap " + probability_text(round.gap) +
           " left";
  return {};
}

}  // namespace

std::string describe_refine(const RefineConfig& refine, std::size_t first_cells) {
  const std::string where = refine.at.empty() ? "the free cells' mean gap"
                                              : "the gap at " + std::to_string(refine.at.size()) + " at state" +
                                                    (refine.at.size() == 1 ? "" : "s");
  return "refine: until " + where + " is at most " + format_number(refine.gap) + "; at most " +
         std::to_string(refine.max_rounds) + " rounds, " + std::to_string(max_cells(refine, first_cells)) +
         " cells, " + format_number(refine.max_seconds) + " s; the plan above is the first round's";
}

Config round_config(const Config& config, const GridSpec& states) {
  Config round = config;
  round.states = states;
  round.fit_sets = false;
  round.refine.reset();
  return round;
}

RefinedSynthesis synthesize_refined(const Config& config, const SynthesisOptions& options, SynthesisReport* report) {
  if (!config.refine) throw std::logic_error("synthesize_refined: the configuration has no refine section");
  const RefineConfig& refine = *config.refine;
  SynthesisReport local;
  SynthesisReport& out = report ? *report : local;
  const auto start = SteadyClock::now();
  GridSpec states = fitted_states(config);
  const std::uint64_t cells_budget = max_cells(refine, Grid(states).size());
  Refinement refinement;
  refinement.at = refine.at;
  std::optional<RefinedSynthesis> served;
  std::vector<EngineNote> round_notes;
  for (std::size_t index = 0;; ++index) {
    const auto round_start = SteadyClock::now();
    SynthesisOptions round_options = options;
    round_options.progress = round_progress(options.progress, unsigned(index + 1), refine.max_rounds);
    const Config round_configuration = round_config(config, states);
    round_configuration.validate();
    Abstraction abstraction = Abstraction::from_config(round_configuration, round_options.progress);
    SynthesisReport round_report;
    Policy policy = synthesize(abstraction, round_options, &round_report);
    RefinementRound round = measure(policy, refine);
    std::optional<SplitChoice> next;
    if (round.gap > refine.gap && index + 1 < refine.max_rounds) {
      const auto gap = detail::attribute_gap(abstraction, policy, refine.at, detail::kAttributionEpisodes, index + 1);
      next = detail::choose_splits(states, policy.states, *abstraction.noise, gap, cells_budget);
    }
    round.seconds = seconds_since(round_start);
    const std::string stop =
        stop_reason(refine, round, index + 1, next ? &*next : nullptr, seconds_since(start), round.seconds);
    round_notes.push_back({NoteSeverity::Info, NoteKind::Refinement, round_text(index, round, !refine.at.empty())});
    const bool best = !served || round.gap <= refinement.rounds[refinement.served_round].gap;
    refinement.rounds.push_back(round);
    if (best) {
      refinement.served_round = index;
      out = std::move(round_report);
      served = RefinedSynthesis{std::move(abstraction), std::move(policy)};
    }
    if (!stop.empty()) {
      refinement.stop = stop;
      break;
    }
    states = next->states;
  }
  const RefinementRound& chosen = refinement.rounds[refinement.served_round];
  const bool met = chosen.gap <= refine.gap;
  round_notes.push_back({met ? NoteSeverity::Info : NoteSeverity::Warning, NoteKind::Refinement,
                         "refinement: " + refinement.stop + "; serving round " +
                             std::to_string(refinement.served_round + 1) + " of " +
                             std::to_string(refinement.rounds.size()) + " (" + std::to_string(chosen.states) +
                             " cells, gap " + probability_text(chosen.gap) + ")"});
  out.notes.insert(out.notes.end(), round_notes.begin(), round_notes.end());
  served->policy.refinement = std::move(refinement);
  served->policy.config_hash = config_hash(config);
  return std::move(*served);
}

}  // namespace amytiss
