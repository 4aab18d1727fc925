// The rounds of `refine` (docs/refinement.md): one synthesis per round through the one entry point
// synthesize(), the gap measured at the `at` states, the next grid from split_choice.hpp.
#include "amytiss/refinement.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <optional>
#include <stdexcept>

#include "amytiss/engine.hpp"
#include "amytiss/errors.hpp"
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

// A round's seconds grow as its cells to a power: finer cells also widen each row's window in
// noise cells. The power is the last two rounds' (clamped), kDefaultTimePower after one round.
constexpr double kDefaultTimePower = 2.0;
constexpr double kLeastTimePower = 1.0, kMostTimePower = 3.0;

double next_round_seconds(const std::vector<RefinementRound>& before, const RefinementRound& round,
                          std::uint64_t next_cells) {
  double power = kDefaultTimePower;
  if (!before.empty() && before.back().states < round.states && before.back().seconds > 0 && round.seconds > 0)
    power = std::clamp(std::log(round.seconds / before.back().seconds) /
                           std::log(double(round.states) / double(before.back().states)),
                       kLeastTimePower, kMostTimePower);
  return round.seconds * std::pow(double(next_cells) / double(round.states), power);
}

// Why no further round runs after this one, or empty. `next` is the split choice for the next
// round, `before` the rounds before this one.
std::string stop_reason(const RefineConfig& refine, const RefinementRound& round,
                        const std::vector<RefinementRound>& before, const SplitChoice* next, double elapsed) {
  const std::size_t rounds_done = before.size() + 1;
  if (round.gap <= refine.gap)
    return "gap " + probability_text(round.gap) + " <= " + format_number(refine.gap) + " reached";
  if (rounds_done >= refine.max_rounds)
    return "max_rounds " + std::to_string(refine.max_rounds) + " done, gap " + probability_text(round.gap) + " left";
  if (next->splits == 0) return next->why_none + ", gap " + probability_text(round.gap) + " left";
  const double estimate = next_round_seconds(before, round, next->cells);
  if (elapsed + estimate > refine.max_seconds)
    return "max_seconds " + format_number(refine.max_seconds) + ": the next round (" + std::to_string(next->cells) +
           " cells, about " + format_significant(estimate) + " s) would end after it, gap " + probability_text(round.gap) +
           " left";
  return {};
}

struct RoundOutcome {
  Abstraction abstraction;
  Policy policy;
  SynthesisReport report;
};

// One round's abstraction and synthesis; nullopt when a round after the first outruns
// max_seconds, or its progress estimates it will: it is cancelled (through its progress) and the
// rounds before it stand.
std::optional<RoundOutcome> run_round(const Config& config, const GridSpec& states, const SynthesisOptions& options,
                                      std::size_t index, SteadyClock::time_point start, const Abstraction* built) {
  const RefineConfig& refine = *config.refine;
  const ProgressCallback numbered = round_progress(options.progress, unsigned(index + 1), refine.max_rounds);
  bool over_budget = false;
  SynthesisOptions round_options = options;
  round_options.progress = [&](const Progress& progress) {
    // Cancelled once past the budget, or once its own estimate of the time left says it will be.
    const double ends_after = seconds_since(start) + std::max(0.0, progress.remaining_s);
    if (index > 0 && ends_after > refine.max_seconds) {
      over_budget = true;
      return false;
    }
    return numbered ? numbered(progress) : true;
  };
  try {
    RoundOutcome outcome;
    if (built) {
      outcome.abstraction = *built;
    } else {
      const Config configuration = round_config(config, states);
      configuration.validate();
      outcome.abstraction = Abstraction::from_config(configuration, round_options.progress);
    }
    outcome.policy = synthesize(outcome.abstraction, round_options, &outcome.report);
    return outcome;
  } catch (const Cancelled&) {
    if (!over_budget) throw;
    return std::nullopt;
  }
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

Config first_round_config(const Config& config) { return round_config(config, fitted_states(config)); }

RefinedSynthesis synthesize_refined(const Config& config, const SynthesisOptions& options, SynthesisReport* report,
                                    const Abstraction* first_round) {
  if (!config.refine) throw std::logic_error("synthesize_refined: the configuration has no refine section");
  const RefineConfig& refine = *config.refine;
  SynthesisReport local;
  SynthesisReport& out = report ? *report : local;
  const auto start = SteadyClock::now();
  GridSpec states = fitted_states(config);
  if (first_round && first_round->states.size() != Grid(states).size())
    throw std::logic_error("synthesize_refined: the first round's abstraction is not first_round_config()'s");
  const std::uint64_t cells_budget = max_cells(refine, Grid(states).size());
  Refinement refinement;
  refinement.at = refine.at;
  std::optional<RefinedSynthesis> served;
  std::vector<EngineNote> round_notes;
  for (std::size_t index = 0;; ++index) {
    const auto round_start = SteadyClock::now();
    std::optional<RoundOutcome> outcome =
        run_round(config, states, options, index, start, index == 0 ? first_round : nullptr);
    if (!outcome) {
      refinement.stop = "max_seconds " + format_number(refine.max_seconds) + ": round " + std::to_string(index + 1) +
                        " cancelled after " + format_significant(seconds_since(round_start)) + " s";
      break;
    }
    Abstraction& abstraction = outcome->abstraction;
    Policy& policy = outcome->policy;
    SynthesisReport& round_report = outcome->report;
    RefinementRound round = measure(policy, refine);
    std::optional<SplitChoice> next;
    if (round.gap > refine.gap && index + 1 < refine.max_rounds) {
      const auto gap = detail::attribute_gap(abstraction, policy, refine.at, detail::kAttributionEpisodes, index + 1);
      next = detail::choose_splits(states, *abstraction.noise, gap, cells_budget);
    }
    round.seconds = seconds_since(round_start);
    const std::string stop =
        stop_reason(refine, round, refinement.rounds, next ? &*next : nullptr, seconds_since(start));
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
