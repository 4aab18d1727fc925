// amytiss_synth: synthesizes a policy from a YAML configuration and writes it as an HDF5 policy
// file. Usage and sample output: docs/cli.md.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include "amytiss/abstraction.hpp"
#include "amytiss/config.hpp"
#include "amytiss/engine.hpp"
#include "amytiss/enum_names.hpp"
#include "amytiss/errors.hpp"
#include "amytiss/format.hpp"
#include "amytiss/policy.hpp"
#include "amytiss/policy_file.hpp"
#include "mpi_session.hpp"

namespace {

using namespace amytiss;
using Clock = std::chrono::steady_clock;

constexpr const char* kUsage =
    "usage: amytiss_synth --config FILE [options]\n"
    "\n"
    "Synthesizes a controller (policy) for the configuration's specification and writes it as\n"
    "an HDF5 policy file (docs/policy_file.md).\n"
    "\n"
    "options:\n"
    "  --config FILE                      YAML configuration (docs/configuration.md)\n"
    "  --device auto|cpu|gpu|reference    overrides compute.device\n"
    "  --transitions auto|stored|on_the_fly  overrides compute.transitions\n"
    "  --sweep auto|dense|factored        overrides compute.sweep (docs/engine.md)\n"
    "  --platform NAME|INDEX              OpenCL platform/device: 0-based index or name substring\n"
    "  --devices all|LIST                 overrides compute.devices: several devices, comma-separated\n"
    "                                     (gpu:0,gpu:1; cpu:0/1 splits the CPU device; docs/scale_out.md)\n"
    "  --dry-run                          print the work split over devices and ranks, compute nothing\n"
    "  --output FILE                      policy file to write (default: <name>.h5 here)\n"
    "  --profile                          per-phase timing, rates and memory table\n"
    "  --compare-reference                also run the serial reference engine and compare V_0\n"
    "  --list-devices                     list the OpenCL devices and exit\n"
    "  --quiet                            no progress lines\n"
    "  --help                             this text\n"
    "\n"
    "Under mpirun (a build with MPI) the ranks split the synthesis; rank 0 prints and writes the file.\n"
    "\n"
    "exit status: 0 success, 2 bad input (configuration or options), 1 other failures\n";

// Bad command-line input; reported like a configuration error (exit status 2).
class UsageError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct Options {
  std::string config_path;
  std::string device;       // empty: the configuration's
  std::string transitions;  // empty: the configuration's
  std::string sweep;        // empty: the configuration's
  std::string platform;
  std::string devices;      // empty: the configuration's
  std::string output;
  bool dry_run = false;
  bool profile = false;
  bool compare_reference = false;
  bool list_devices = false;
  bool quiet = false;
  bool help = false;
};

Options parse_options(int argc, char** argv) {
  Options options;
  const std::vector<std::string> args(argv + 1, argv + argc);
  for (std::size_t i = 0; i < args.size(); ++i) {
    const std::string& arg = args[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= args.size()) throw UsageError(arg + " needs a value (see --help)");
      return args[++i];
    };
    if (arg == "--config") options.config_path = value();
    else if (arg == "--device") options.device = value();
    else if (arg == "--transitions") options.transitions = value();
    else if (arg == "--sweep") options.sweep = value();
    else if (arg == "--platform") options.platform = value();
    else if (arg == "--devices") options.devices = value();
    else if (arg == "--dry-run") options.dry_run = true;
    else if (arg == "--output" || arg == "-o") options.output = value();
    else if (arg == "--profile") options.profile = true;
    else if (arg == "--compare-reference") options.compare_reference = true;
    else if (arg == "--list-devices") options.list_devices = true;
    else if (arg == "--quiet" || arg == "-q") options.quiet = true;
    else if (arg == "--help" || arg == "-h") options.help = true;
    else throw UsageError("unknown option '" + arg + "' (see --help)");
  }
  if (!options.help && !options.list_devices && options.config_path.empty())
    throw UsageError("--config FILE is required (example: --config config/robot_safety.yaml)");
  return options;
}

template <typename Enum>
Enum parse_enum_option(const std::string& option, const std::string& text) {
  if (const auto value = enum_from_name<Enum>(text)) return *value;
  throw UsageError(option + ": got '" + text + "', expected one of " + enum_name_list<Enum>());
}

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

std::string format_seconds(double seconds) {
  char text[32];
  std::snprintf(text, sizeof text, seconds < 10 ? "%.3f s" : "%.1f s", seconds);
  return text;
}

std::string counts_text(const Grid& grid) {
  if (grid.dims() == 0) return "";
  std::string text = " (";
  for (std::size_t dim = 0; dim < grid.dims(); ++dim)
    text += (dim ? " x " : "") + std::to_string(grid.count(dim));
  return text + ")";
}

void print_sizes(const Abstraction& abstraction) {
  std::printf("grid: states %zu%s, inputs %zu%s, disturbances %zu%s\n",
              abstraction.states.size(), counts_text(abstraction.states).c_str(),
              abstraction.inputs.size(), counts_text(abstraction.inputs).c_str(),
              abstraction.disturbances.size(), counts_text(abstraction.disturbances).c_str());
  std::printf("state-input pairs: %zu, state-input-disturbance triples: %zu, horizon: %u\n",
              abstraction.pairs(), abstraction.triples(), abstraction.horizon);
}

// The engine's estimate (docs/engine.md): policy arrays as in the file, stored transitions as
// the OpenCL engine stores them.
void print_memory_estimate(const Abstraction& abstraction) {
  const MemoryEstimate estimate = estimate_memory(abstraction);
  std::printf("estimated memory: policy arrays %s, stored transitions %s (%.0f bytes per triple)\n",
              format_bytes(estimate.policy_bytes).c_str(), format_bytes(estimate.stored_transition_bytes).c_str(),
              estimate.bytes_per_triple);
}

bool print_progress(const Progress& progress, bool quiet) {
  if (quiet || progress.phase != Phase::Synthesis) return true;
  std::printf("  step %u/%u  %5.1f%%  on %s, elapsed %s", progress.steps_done,
              progress.steps_total, progress.percent(), progress.device.c_str(),
              format_seconds(progress.elapsed_s).c_str());
  if (progress.remaining_s >= 0)
    std::printf(", remaining %s", format_seconds(progress.remaining_s).c_str());
  std::printf("\n");
  std::fflush(stdout);
  return true;
}

bool is_step_phase(const PhaseReport& phase) { return phase.name.rfind("step", 0) == 0; }

// Construction + synthesis, without device set-up and kernel build (the "compute time").
double compute_seconds(const SynthesisReport& report) {
  double total = 0;
  for (const auto& phase : report.phases)
    if (!phase.breakdown && phase.name != "device setup" && phase.name != "kernel build") total += phase.seconds;
  return total;
}

// Without --profile the time steps are summed into one line.
void print_phase_times(const SynthesisReport& report) {
  double step_seconds = 0;
  std::size_t steps = 0;
  for (const auto& phase : report.phases) {
    if (phase.breakdown) continue;
    if (is_step_phase(phase)) {
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

// Every kernel finishes before its phase's clock stops (profile), so the rates are the device's.
void print_profile(const SynthesisReport& report) {
  const double peak = report.peak_multiply_adds_per_second;
  std::printf("profile (%s):\n", report.device.c_str());
  if (peak > 0)
    std::printf("  double multiply-add peak %.0f GMAC/s: %s\n", peak / 1e9, report.peak_basis.c_str());
  std::printf("  %-28s %10s %14s %14s %9s %7s %11s\n", "phase", "seconds", "pairs/s", "multiply-adds", "GMAC/s",
              "% peak", "GB/s (ops)");
  auto print_row = [&](const std::string& name, double seconds, double pairs_per_second, double multiply_adds,
                       double bytes) {
    const double rate = seconds > 0 ? multiply_adds / seconds : 0.0;
    std::printf("  %-28s %10.4f %14.4g %14.4g %9.3f %7.2f %11.2f\n", name.c_str(), seconds, pairs_per_second,
                multiply_adds, rate / 1e9, peak > 0 ? 100.0 * rate / peak : 0.0,
                seconds > 0 ? bytes / seconds / 1e9 : 0.0);
  };
  double total_seconds = 0, total_multiply_adds = 0, total_bytes = 0;
  for (const auto& phase : report.phases) {
    if (!phase.breakdown) {
      total_seconds += phase.seconds;
      total_multiply_adds += phase.multiply_adds;
      total_bytes += phase.bytes;
    }
    print_row((phase.breakdown ? "  " : "") + phase.name, phase.seconds, phase.pairs_per_second,
              phase.multiply_adds, phase.bytes);
  }
  print_row("total", total_seconds, 0, total_multiply_adds, total_bytes);
  std::printf("  device memory: %s, host peak (VmHWM): %s\n",
              format_bytes(double(report.device_bytes)).c_str(),
              format_bytes(double(std::max(report.host_peak_bytes, peak_resident_bytes()))).c_str());
}

void print_value_summary(const Policy& policy) {
  const ValueSummary summary = summarize_initial_values(policy);
  std::printf("V_0 over %zu free cells: min %.6f, mean %.6f, max %.6f; %zu cells with V_0 >= 0.5\n",
              summary.free_cells, summary.min, summary.mean, summary.max,
              summary.cells_at_least_half);
}

void compare_with_reference(const Abstraction& abstraction, const Policy& policy,
                            double engine_seconds, double engine_compute_seconds, bool quiet) {
  std::printf("reference engine (for comparison):\n");
  const auto start = Clock::now();
  SynthesisReport reference_report;
  const Policy reference = synthesize_reference(
      abstraction, [quiet](const Progress& progress) { return print_progress(progress, quiet); },
      &reference_report);
  const double reference_seconds = seconds_since(start);
  double max_difference = 0;
  for (std::size_t cell = 0; cell < policy.states.size(); ++cell)
    max_difference =
        std::max(max_difference, std::fabs(policy.value(0, cell) - reference.value(0, cell)));
  std::printf("  reference time %s; engine %s end to end, %s compute\n",
              format_seconds(reference_seconds).c_str(), format_seconds(engine_seconds).c_str(),
              format_seconds(engine_compute_seconds).c_str());
  std::printf("  speed-up %.1fx end to end, %.1fx compute\n",
              engine_seconds > 0 ? reference_seconds / engine_seconds : 0.0,
              engine_compute_seconds > 0 ? reference_seconds / engine_compute_seconds : 0.0);
  std::printf("  max |dV_0| (engine - reference): %.3g\n", max_difference);
}

std::vector<std::string> split_list(const std::string& text) {
  std::vector<std::string> items;
  std::stringstream stream(text);
  for (std::string item; std::getline(stream, item, ',');) items.push_back(item);
  return items;
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

int run(const Options& options, cli::MpiSession& mpi) {
  if (options.help) {
    std::fputs(kUsage, stdout);
    return 0;
  }
  if (options.list_devices) {
    const auto devices = list_opencl_devices();
    if (devices.empty()) std::printf("no OpenCL devices found\n");
    for (const auto& line : devices) std::printf("%s\n", line.c_str());
    return 0;
  }

  const auto setup_start = Clock::now();
  Config config = load_config_file(options.config_path);
  if (!options.device.empty()) config.compute.device = parse_enum_option<DeviceKind>("--device", options.device);
  if (!options.transitions.empty())
    config.compute.transitions = parse_enum_option<TransitionStorage>("--transitions", options.transitions);
  if (!options.sweep.empty()) config.compute.sweep = parse_enum_option<SweepChoice>("--sweep", options.sweep);
  if (!options.platform.empty()) config.compute.platform = options.platform;
  if (!options.devices.empty()) {
    config.compute.devices = split_list(options.devices);
    config.validate();
  }
  const Abstraction abstraction = Abstraction::from_config(config);
  const double setup_seconds = seconds_since(setup_start);

  std::printf("configuration: %s (%s, %s), hash %s\n", config.name.c_str(),
              options.config_path.c_str(), to_string(config.spec.type).c_str(),
              config_hash(config).c_str());
  print_sizes(abstraction);
  print_memory_estimate(abstraction);
  std::printf("device: %s, transitions: %s\n", to_string(config.compute.device).c_str(),
              to_string(config.compute.transitions).c_str());
  if (!config.compute.devices.empty()) {
    std::string devices;
    for (const std::string& entry : config.compute.devices) devices += (devices.empty() ? "" : ", ") + entry;
    std::printf("devices: %s\n", devices.c_str());
  }
  if (mpi.size() > 1) std::printf("MPI: %d ranks\n", mpi.size());
  std::fflush(stdout);

  SynthesisOptions synthesis_options;
  synthesis_options.compute = config.compute;
  synthesis_options.communicator = mpi.communicator();
  if (options.dry_run) {
    for (const std::string& line : describe_scale_out(abstraction, synthesis_options))
      std::printf("plan: %s\n", line.c_str());
    std::printf("dry run: nothing computed, no file written\n");
    return 0;
  }
  synthesis_options.profile = options.profile;
  const bool quiet = options.quiet;
  synthesis_options.progress = [quiet](const Progress& progress) {
    return print_progress(progress, quiet);
  };
  SynthesisReport report;
  const auto synthesis_start = Clock::now();
  const Policy policy = synthesize(abstraction, synthesis_options, &report);
  const double synthesis_wall_seconds = seconds_since(synthesis_start);
  for (const auto& note : report.notes)
    std::printf("note: %s%s\n", note.severity == NoteSeverity::Warning ? "warning: " : "", note.text.c_str());
  std::printf("computed by %s, transitions %s\n", report.device.c_str(),
              report.transitions.c_str());

  // Collective: every rank has finished its part before rank 0 writes the one file.
  print_rank_times(synthesis_wall_seconds, report, mpi.communicator());
  const std::string output = options.output.empty() ? config.name + ".h5" : options.output;
  const auto write_start = Clock::now();
  if (mpi.rank() == 0) write_policy_file(output, policy, config);
  const double write_seconds = seconds_since(write_start);

  std::printf("wall time:\n");
  std::printf("  %-24s %s\n", "config + abstraction", format_seconds(setup_seconds).c_str());
  print_phase_times(report);
  std::printf("  %-24s %s\n", "synthesize() total", format_seconds(synthesis_wall_seconds).c_str());
  std::printf("  %-24s %s\n", "file write", format_seconds(write_seconds).c_str());
  if (options.profile) print_profile(report);
  print_value_summary(policy);
  if (options.compare_reference) {
    const double engine_compute_seconds =
        report.phases.empty() ? synthesis_wall_seconds : compute_seconds(report);
    compare_with_reference(abstraction, policy, synthesis_wall_seconds, engine_compute_seconds,
                           quiet);
  }
  if (mpi.rank() == 0) std::printf("wrote %s\n", output.c_str());
  return 0;
}

// Runs the CLI; on failure prints the error (naming the rank under MPI) and returns the status.
int run_reporting(int argc, char** argv, cli::MpiSession& mpi) {
  const std::string where =
      mpi.size() > 1 ? "rank " + std::to_string(mpi.rank()) + " of " + std::to_string(mpi.size()) + ": " : "";
  auto report = [&](const std::exception& error, int status) {
    std::fflush(stdout);
    std::fprintf(stderr, "error: %s%s\n", where.c_str(), error.what());
    std::fflush(stderr);
    return status;
  };
  try {
    // Ranks other than 0 compute their part silently; errors still go to stderr.
    if (mpi.rank() > 0 && !std::freopen("/dev/null", "w", stdout)) throw std::runtime_error("cannot silence stdout");
    return run(parse_options(argc, argv), mpi);
  } catch (const UsageError& error) {
    return report(error, 2);
  } catch (const ConfigError& error) {
    return report(error, 2);
  } catch (const ParseError& error) {
    return report(error, 2);
  } catch (const std::exception& error) {
    return report(error, 1);
  }
}

}  // namespace

int main(int argc, char** argv) {
  try {
    cli::MpiSession mpi(&argc, &argv);
    const int status = run_reporting(argc, argv, mpi);
    // One failing rank ends them all: the others would wait for it in the next exchange.
    if (status != 0) mpi.abort_all(status);
    return status;
  } catch (const std::exception& error) {
    std::fprintf(stderr, "error: %s\n", error.what());
    return 1;
  }
}
