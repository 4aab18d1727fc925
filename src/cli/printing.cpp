#include "printing.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "amytiss/apriori_error.hpp"
#include "amytiss/engine.hpp"
#include "amytiss/enum_names.hpp"
#include "amytiss/format.hpp"
#include "amytiss/roofline.hpp"
#include "amytiss/stopwatch.hpp"

namespace amytiss::cli {
namespace {

std::string counts_text(const Grid& grid) {
  if (grid.dims() == 0) return "";
  std::string text = " (";
  for (std::size_t dim = 0; dim < grid.dims(); ++dim)
    text += (dim ? " x " : "") + std::to_string(grid.count(dim));
  return text + ")";
}

}  // namespace

std::string covered_box_text(const Grid& grid) {
  std::string text;
  for (std::size_t dim = 0; dim < grid.dims(); ++dim)
    text += (dim ? " x [" : "[") + format_number(grid.covered_low(dim)) + ", " + format_number(grid.covered_high(dim)) + "]";
  return text;
}

std::string format_seconds(double seconds) {
  char text[32];
  std::snprintf(text, sizeof text, seconds < 10 ? "%.3f s" : "%.1f s", seconds);
  return text;
}

void print_sizes(const Abstraction& abstraction) {
  std::printf("grid: states %zu%s, inputs %zu%s, disturbances %zu%s\n",
              abstraction.states.size(), counts_text(abstraction.states).c_str(),
              abstraction.inputs.size(), counts_text(abstraction.inputs).c_str(),
              abstraction.disturbances.size(), counts_text(abstraction.disturbances).c_str());
  // A grid with faces: where its cells are, which the counts alone no longer say.
  if (!abstraction.states.all_uniform()) {
    std::string faced;
    for (std::size_t dim = 0; dim < abstraction.states.dims(); ++dim)
      if (!abstraction.states.uniform(dim)) faced += (faced.empty() ? "" : ", ") + std::to_string(dim);
    std::printf("state grid covers %s (cells given by their faces in dimension %s)\n",
                covered_box_text(abstraction.states).c_str(), faced.c_str());
  }
  std::printf("state-input pairs: %zu, state-input-disturbance triples: %zu, horizon: %u\n",
              abstraction.pairs(), abstraction.triples(), abstraction.horizon);
}

// The engine's estimate (docs/engine.md): policy arrays as in the file, stored transitions as
// the OpenCL engine stores them; the continuous-system bounds store none but their row bounds
// and the method's buffers take host memory.
void print_memory_estimate(const Abstraction& abstraction) {
  const MemoryEstimate estimate = estimate_memory(abstraction);
  if (abstraction.config.guarantee == Guarantee::System) {
    std::printf("estimated memory: policy arrays %s (lower and upper bounds), bounds engine %s (row bounds and "
                "method %s), host %s in all, no stored transitions\n",
                format_bytes(estimate.policy_bytes).c_str(), format_bytes(estimate.bounds_bytes).c_str(),
                estimate.bounds_method.c_str(), format_bytes(estimate.host_bytes).c_str());
    return;
  }
  std::printf("estimated memory: policy arrays %s, stored transitions %s (%.0f bytes per triple)\n",
              format_bytes(estimate.policy_bytes).c_str(), format_bytes(estimate.stored_transition_bytes).c_str(),
              estimate.bytes_per_triple);
}

// What the abstraction may lose or add per transition: truncation only ever drops mass (values
// stay lower bounds); a custom density's quadrature may err either way, at most T times its bound
// in V_0 (docs/semantics.md).
void print_error_budget(const Abstraction& abstraction) {
  const NoiseModel& noise = *abstraction.noise;
  std::printf("noise: %s %s, truncation %s: cut mass <= %.3g per transition", to_string(noise.type()).c_str(),
              to_string(noise.distribution()).c_str(), to_string(abstraction.config.noise.truncation).c_str(),
              noise.cut_mass_bound());
  if (noise.quadrature_error_bound() > 0)
    std::printf(", quadrature error <= %.3g per transition (|dV_0| <= %.3g over the horizon)",
                noise.quadrature_error_bound(), noise.quadrature_error_bound() * double(abstraction.horizon));
  if (!noise.separable()) std::printf(", box mass tolerance %.3g", noise.box_mass_tolerance());
  std::printf("\n");
}

bool print_progress(const Progress& progress, bool quiet) {
  const bool step_done = progress.phase == Phase::Synthesis || (progress.phase == Phase::Done && progress.steps_total);
  if (quiet || !step_done) return true;
  if (progress.steps_total == 0) {  // unbounded: interval iterations, no fixed count; every 100th
    if (progress.steps_done % 100 != 0) return true;
    if (progress.max_rounds) std::printf("  round %u/%u", progress.round, progress.max_rounds);
    std::printf("  iteration %u on %s, elapsed %s\n", progress.steps_done, progress.device.c_str(),
                format_seconds(progress.elapsed_s).c_str());
    std::fflush(stdout);
    return true;
  }
  if (progress.max_rounds) std::printf("  round %u/%u", progress.round, progress.max_rounds);
  std::printf("  step %u/%u  %5.1f%%  on %s, elapsed %s", progress.steps_done,
              progress.steps_total, progress.percent(), progress.device.c_str(),
              format_seconds(progress.elapsed_s).c_str());
  if (progress.remaining_s >= 0)
    std::printf(", remaining %s", format_seconds(progress.remaining_s).c_str());
  std::printf("\n");
  std::fflush(stdout);
  return true;
}

double compute_seconds(const SynthesisReport& report) {
  double total = 0;
  for (const auto& phase : report.phases)
    if (!phase.is_breakdown() && !phase.is_setup()) total += phase.seconds;
  return total;
}

// Without --profile the time steps are summed into one line.
void print_phase_times(const SynthesisReport& report) {
  double step_seconds = 0;
  std::size_t steps = 0;
  for (const auto& phase : report.phases) {
    if (phase.is_breakdown()) continue;
    if (phase.kind == PhaseKind::Step) {
      step_seconds += phase.seconds;
      ++steps;
    } else {
      std::printf("  %-24s %s\n", phase.name.c_str(), format_seconds(phase.seconds).c_str());
    }
  }
  if (steps > 0)
    std::printf("  %-24s %s\n", ("synthesis (" + std::to_string(steps) + " steps)").c_str(),
                format_seconds(step_seconds).c_str());
}

namespace {

// The time steps share one intensity: they are one row, their times summed; each breakdown
// (kernel, stage) is a row of its own.
void print_roofline(const SynthesisReport& report) {
  const RooflineDevice device{report.peak_multiply_adds_per_second, report.measured_bandwidth_bytes_per_second,
                              report.measured_cache_bytes_per_second};
  if (device.peak <= 0 || device.bandwidth <= 0) return;
  std::printf("  bandwidth %.1f GB/s measured: %s\n", device.bandwidth / 1e9, report.bandwidth_basis.c_str());
  if (device.cache_bandwidth > 0)
    std::printf("  cache bandwidth %.1f GB/s measured: %s\n", device.cache_bandwidth / 1e9, report.cache_basis.c_str());
  std::printf("roofline (peak %.0f GMAC/s; memory %.1f GB/s over the bytes a phase must move, its tensors once; "
              "cache %.1f GB/s over the operands its kernels load; the lowest roof bounds it):\n",
              device.peak / 1e9, device.bandwidth / 1e9, device.cache_bandwidth / 1e9);
  std::printf("  %-33s %10s %10s %12s %8s %12s %8s\n", "phase", "MAC/B mem", "MAC/B ops", "roof GMAC/s", "bound",
              "GMAC/s", "% roof");
  auto print_row = [&](const std::string& name, const RooflineWork& work) {
    if (work.multiply_adds <= 0 || work.operand_bytes <= 0 || work.seconds <= 0) return;
    const RooflinePoint point = roofline_point(device, work);
    std::printf("  %-33s %10.4g %10.4g %12.3f %8s %12.3f %8.1f\n", name.c_str(), point.memory_intensity,
                point.operand_intensity, point.roof / 1e9, to_string(point.bound).c_str(), point.achieved / 1e9,
                100.0 * point.fraction_of_roof);
  };
  RooflineWork steps_work;
  std::size_t steps = 0;
  for (const auto& phase : report.phases) {
    if (phase.kind != PhaseKind::Step) continue;
    steps_work.multiply_adds += phase.multiply_adds;
    steps_work.operand_bytes += phase.bytes;
    steps_work.memory_bytes += phase.memory_bytes;
    steps_work.seconds += phase.seconds;
    ++steps;
  }
  print_row("time steps (" + std::to_string(steps) + ")", steps_work);
  for (const auto& phase : report.phases)
    if (phase.kind != PhaseKind::Step && !phase.is_setup())
      print_row((phase.is_breakdown() ? "  " : "") + phase.name,
                {phase.multiply_adds, phase.bytes, phase.memory_bytes, phase.seconds});
}

}  // namespace

// Every kernel finishes before its phase's clock stops (profile), so the rates are the device's.
void print_profile(const SynthesisReport& report) {
  const double peak = report.peak_multiply_adds_per_second;
  std::printf("profile (%s):\n", report.device.c_str());
  if (peak > 0)
    std::printf("  double multiply-add peak %.0f GMAC/s: %s\n", peak / 1e9, report.peak_basis.c_str());
  std::printf("  %-33s %10s %14s %14s %9s %7s %11s\n", "phase", "seconds", "pairs/s", "multiply-adds", "GMAC/s",
              "% peak", "GB/s (ops)");
  auto print_row = [&](const std::string& name, double seconds, double pairs_per_second, double multiply_adds,
                       double bytes) {
    const double rate = seconds > 0 ? multiply_adds / seconds : 0.0;
    std::printf("  %-33s %10.4f %14.4g %14.4g %9.3f %7.2f %11.2f\n", name.c_str(), seconds, pairs_per_second,
                multiply_adds, rate / 1e9, peak > 0 ? 100.0 * rate / peak : 0.0,
                seconds > 0 ? bytes / seconds / 1e9 : 0.0);
  };
  double total_seconds = 0, total_multiply_adds = 0, total_bytes = 0;
  for (const auto& phase : report.phases) {
    if (!phase.is_breakdown()) {
      total_seconds += phase.seconds;
      total_multiply_adds += phase.multiply_adds;
      total_bytes += phase.bytes;
    }
    print_row((phase.is_breakdown() ? "  " : "") + phase.name, phase.seconds, phase.pairs_per_second,
              phase.multiply_adds, phase.bytes);
  }
  print_row("total", total_seconds, 0, total_multiply_adds, total_bytes);
  std::printf("  device memory: %s, host peak (VmHWM): %s\n",
              format_bytes(double(report.device_bytes)).c_str(),
              format_bytes(double(std::max(report.host_peak_bytes, peak_resident_bytes()))).c_str());
  print_roofline(report);
}

void print_value_summary(const Policy& policy) {
  const ValueSummary summary = summarize_initial_values(policy);
  std::printf("V_0 over %zu free cells: min %.6f, mean %.6f, max %.6f; %zu cells with V_0 >= 0.5%s\n",
              summary.free_cells, summary.min, summary.mean, summary.max, summary.cells_at_least_half,
              policy.guarantee == Guarantee::System ? "" : (std::string(" (") + kAbstractionValueLabel + ")").c_str());
  const BoundsSummary bounds = summarize_bounds(policy);
  auto range = [](const RangeSummary& r) {
    char text[96];
    std::snprintf(text, sizeof text, "min %.6f, mean %.6f, max %.6f", r.min, r.mean, r.max);
    return std::string(text);
  };
  if (policy.guarantee == Guarantee::System) {
    // The probability for the continuous system from every state of a cell lies between the bounds.
    std::printf("continuous-system bounds over %zu free cells:\n", bounds.free_cells);
    std::printf("  lower (V_0, this policy) %s\n", range(bounds.lower).c_str());
    std::printf("  upper (any controller)   %s\n", range(bounds.upper).c_str());
    std::printf("  gap (upper - lower)      %s\n", range(bounds.gap).c_str());
  }
  if (!policy.stationary) return;
  // Unbounded: V_0 above is the certified lower bound; the upper bound and the gap beside it.
  std::printf("unbounded: V_0 is the stationary policy's certified lower bound; upper bound mean %.6f, max %.6f; "
              "largest gap %.3g after %u interval iterations\n",
              bounds.upper.mean, bounds.upper.max, policy.gap, policy.iterations);
}

std::string format_values(const std::vector<double>& values) {
  std::string text = "[";
  for (std::size_t i = 0; i < values.size(); ++i) text += (i ? ", " : "") + format_number(values[i]);
  return text + "]";
}

void print_values_at(const Policy& policy, const std::vector<double>& state) {
  std::vector<double> input(policy.inputs.dims());
  double lower = 0.0, upper = 0.0;
  const LookupStatus status = policy.lookup(state.data(), state.size(), 0, input.data(), &lower, &upper);
  if (status != LookupStatus::Ok) throw std::logic_error(policy.describe(status, state.data(), state.size(), 0));
  const std::string where = "at " + format_values(state);
  const std::string with_input = input.empty() ? "" : ", input " + format_values(input);
  if (policy.guarantee == Guarantee::System)
    std::printf("%s: certified lower bound %.6f (this policy), upper bound %.6f (any controller)%s\n", where.c_str(),
                lower, upper, with_input.c_str());
  else
    std::printf("%s: V_0 %.6f (the %s, of its cell)%s\n", where.c_str(), lower, kAbstractionValueLabel,
                with_input.c_str());
}

void print_refinement(const Policy& policy) {
  const Refinement& refinement = policy.refinement;
  if (refinement.rounds.empty()) return;
  std::printf("refinement (%zu rounds):\n", refinement.rounds.size());
  for (std::size_t r = 0; r < refinement.rounds.size(); ++r) {
    const RefinementRound& round = refinement.rounds[r];
    std::printf("  round %zu: %llu cells, gap %.6f, %s", r + 1, static_cast<unsigned long long>(round.states), round.gap,
                format_seconds(round.seconds).c_str());
    for (std::size_t i = 0; i < round.lower.size(); ++i)
      std::printf("%s%.6f, %.6f", i ? "; " : ", lower, upper at the at states: ", round.lower[i], round.upper[i]);
    std::printf("%s\n", r == refinement.served_round ? "  <- served" : "");
  }
  std::printf("  stopped: %s\n", refinement.stop.c_str());
}

// The paper's bound is one interval Jacobian per box of cells, input and disturbance: at most
// this many keep it to about a second on the shipped examples (an RK4 model's Jacobian takes a
// quarter of a millisecond); more cells per box only loosen it.
constexpr std::size_t kAprioriJacobianBudget = 20000;

void print_apriori_error(const Abstraction& abstraction) {
  std::printf("%s\n", describe_apriori_error(apriori_error(abstraction, kAprioriJacobianBudget)).c_str());
}

void compare_with_reference(const Abstraction& abstraction, const Policy& policy,
                            double engine_seconds, double engine_compute_seconds, bool quiet) {
  std::printf("reference engine (for comparison):\n");
  const auto start = SteadyClock::now();
  SynthesisReport reference_report;
  const Policy reference = synthesize_reference(
      abstraction, [quiet](const Progress& progress) { return print_progress(progress, quiet); },
      &reference_report);
  const double reference_seconds = seconds_since(start);
  double max_difference = 0, max_upper_difference = 0;
  for (std::size_t cell = 0; cell < policy.states.size(); ++cell) {
    max_difference = std::max(max_difference, std::fabs(policy.value(0, cell) - reference.value(0, cell)));
    max_upper_difference =
        std::max(max_upper_difference, std::fabs(policy.upper_value(0, cell) - reference.upper_value(0, cell)));
  }
  std::printf("  reference time %s; engine %s end to end, %s compute\n",
              format_seconds(reference_seconds).c_str(), format_seconds(engine_seconds).c_str(),
              format_seconds(engine_compute_seconds).c_str());
  std::printf("  speed-up %.1fx end to end, %.1fx compute\n",
              engine_seconds > 0 ? reference_seconds / engine_seconds : 0.0,
              engine_compute_seconds > 0 ? reference_seconds / engine_compute_seconds : 0.0);
  if (policy.upper_values.empty()) {
    std::printf("  max |dV_0| (engine - reference): %.3g\n", max_difference);
    return;
  }
  // Both runs bound the same probability; how far apart their bounds may be is the engines' own
  // affair (docs/semantics.md), so the differences are reported, not judged.
  std::printf("  max |d lower V_0| (engine - reference): %.3g\n", max_difference);
  if (reference.upper_values.empty())
    std::printf("  upper bound: the reference computed none (guarantee %s)\n", to_string(reference.guarantee).c_str());
  else
    std::printf("  max |d upper V_0| (engine - reference): %.3g\n", max_upper_difference);
}


// Each rank's synthesis time and the share of it spent exchanging parts (rank 0 prints).
void print_rank_times(double synthesis_seconds, const SynthesisReport& report, Communicator* communicator) {
  SoloCommunicator solo;
  Communicator& ranks = communicator ? *communicator : solo;
  const std::vector<double> seconds = ranks.allgather_value(synthesis_seconds);
  const std::vector<double> exchange = ranks.allgather_value(report.exchange_seconds);
  if (report.exchange_bytes_per_step <= 0) return;
  std::printf("scale-out: %s exchanged per step\n", format_bytes(report.exchange_bytes_per_step).c_str());
  for (std::size_t r = 0; r < seconds.size(); ++r)
    std::printf("  rank %zu: synthesize() %s, exchange %s (%.1f%%)\n", r, format_seconds(seconds[r]).c_str(),
                format_seconds(exchange[r]).c_str(), seconds[r] > 0 ? 100.0 * exchange[r] / seconds[r] : 0.0);
}


}  // namespace amytiss::cli
