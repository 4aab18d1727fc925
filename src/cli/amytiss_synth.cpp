// amytiss_synth: synthesizes a policy from a YAML configuration and writes it as an HDF5 policy
// file. Usage and sample output: docs/cli.md.
#include <cstdio>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "amytiss/abstraction.hpp"
#include "amytiss/config.hpp"
#include "amytiss/engine.hpp"
#include "amytiss/errors.hpp"
#include "amytiss/model_export.hpp"
#include "amytiss/policy.hpp"
#include "amytiss/policy_file.hpp"
#include "amytiss/refinement.hpp"
#include "amytiss/stopwatch.hpp"
#include "mpi_session.hpp"
#include "options.hpp"
#include "printing.hpp"
#include "simulation.hpp"

namespace {

using namespace amytiss;
using namespace amytiss::cli;

std::vector<std::string> split_list(const std::string& text) {
  std::vector<std::string> items;
  std::stringstream stream(text);
  for (std::string item; std::getline(stream, item, ',');) items.push_back(item);
  return items;
}

// The configuration file with the command line's overrides, validated once (on the result).
Config load_with_overrides(const Options& options) {
  ComputeOverrides overrides;
  overrides.key_prefix = "--";
  overrides.device = options.device;
  overrides.transitions = options.transitions;
  overrides.sweep = options.sweep;
  overrides.bounds_method = options.bounds_method;
  overrides.platform = options.platform;
  if (!options.devices.empty()) overrides.devices = split_list(options.devices);
  overrides.guarantee = options.guarantee;
  if (options.refine_gap > 0) {
    overrides.refine = RefineConfig{};
    overrides.refine->at = {options.at};
    overrides.refine->gap = options.refine_gap;
  }
  return load_config_file(options.config_path, overrides);
}

// --at names a state of the grid: checked before anything is computed.
void check_state_option(const Options& options, const Grid& states) {
  if (options.at.empty()) return;
  if (options.at.size() != states.dims())
    throw UsageError("--at: got " + std::to_string(options.at.size()) + " values, expected " +
                     std::to_string(states.dims()) + ", one per state dimension (x0 to x" +
                     std::to_string(states.dims() - 1) + ")");
  if (!states.cell_of(options.at.data()))
    throw UsageError("--at: the state " + format_values(options.at) +
                     " lies outside the grid (" +
                     (states.all_uniform() ? std::string("states.lb - eta/2 to states.ub + eta/2")
                                           : "the box " + covered_box_text(states)) + ")");
}

std::string output_path(const Options& options, const Config& config) {
  return options.output.empty() ? config.name + ".h5" : options.output;
}

// --output too is checked before anything is computed: a device or a FIFO there is refused.
void check_output_option(const Options& options, const Config& config) {
  if (options.dry_run || !options.export_format.empty()) return;
  try {
    check_policy_file_path(output_path(options, config));
  } catch (const PolicyFileError& error) {
    throw UsageError(std::string("--output: ") + error.what() +
                     "; policy files are written only to regular files (example: --output policy.h5)");
  }
}

void print_problem(const Options& options, const Config& config, const Abstraction& abstraction) {
  std::printf("configuration: %s (%s, %s), hash %s\n", config.name.c_str(), options.config_path.c_str(),
              to_string(config.spec.type).c_str(), config_hash(config).c_str());
  print_sizes(abstraction);
  print_memory_estimate(abstraction);
  print_error_budget(abstraction);
}

int export_abstraction(const Options& options, const Abstraction& abstraction) {
  const ExportFormat format = options.export_format == "prism" ? ExportFormat::Prism : ExportFormat::Drn;
  const ExportSummary summary =
      export_model(abstraction, format, options.export_directory, options.export_max_transitions);
  std::printf("exported %s: %zu states, %zu choices, %zu transitions\n", options.export_format.c_str(),
              summary.states, summary.choices, summary.transitions);
  for (const auto& file : summary.files) std::printf("wrote %s\n", file.c_str());
  return 0;
}

void print_request(const Config& config, const cli::MpiSession& mpi) {
  std::printf("device: %s, transitions: %s\n", to_string(config.compute.device).c_str(),
              to_string(config.compute.transitions).c_str());
  if (!config.compute.devices.empty()) {
    std::string devices;
    for (const std::string& entry : config.compute.devices) devices += (devices.empty() ? "" : ", ") + entry;
    std::printf("devices: %s\n", devices.c_str());
  }
  if (mpi.size() > 1) std::printf("MPI: %d ranks\n", mpi.size());
  std::fflush(stdout);
}

// Synthesizes, writes the policy file (rank 0) and prints the notes, times and values.
int synthesize_and_write(const Options& options, const Config& config, const Abstraction& abstraction,
                         SynthesisOptions synthesis_options, double setup_seconds, cli::MpiSession& mpi) {
  synthesis_options.profile = options.profile;
  const bool quiet = options.quiet;
  synthesis_options.progress = [quiet](const Progress& progress) { return print_progress(progress, quiet); };
  SynthesisReport report;
  const auto synthesis_start = SteadyClock::now();
  // With refine the policy comes from the served round's grid, not the one printed above.
  std::optional<RefinedSynthesis> refined;
  if (config.refine) refined = synthesize_refined(config, synthesis_options, &report, &abstraction);
  const Policy policy = refined ? std::move(refined->policy) : synthesize(abstraction, synthesis_options, &report);
  const Abstraction& served = refined ? refined->abstraction : abstraction;
  const double synthesis_wall_seconds = seconds_since(synthesis_start);
  for (const auto& note : report.notes)
    std::printf("note: %s%s\n", note.severity == NoteSeverity::Warning ? "warning: " : "", note.text.c_str());
  std::printf("computed by %s, transitions %s\n", report.device.c_str(), report.transitions.c_str());

  // Collective: every rank has finished its part before rank 0 writes the one file.
  print_rank_times(synthesis_wall_seconds, report, mpi.communicator());
  const std::string output = output_path(options, config);
  const auto write_start = SteadyClock::now();
  if (mpi.rank() == 0) write_policy_file(output, policy, config);
  const double write_seconds = seconds_since(write_start);

  std::printf("wall time:\n");
  std::printf("  %-24s %s\n", "config + abstraction", format_seconds(setup_seconds).c_str());
  print_phase_times(report);
  std::printf("  %-24s %s\n", refined ? "refine, every round" : "synthesize() total",
              format_seconds(synthesis_wall_seconds).c_str());
  std::printf("  %-24s %s\n", "file write", format_seconds(write_seconds).c_str());
  if (options.profile) print_profile(report);
  print_refinement(policy);
  print_value_summary(policy);
  if (!options.at.empty()) print_values_at(policy, options.at);
  if (options.simulate && mpi.rank() == 0) print_simulation(config, policy, options.at, options.simulate, options.seed);
  if (mpi.rank() == 0) print_apriori_error(served);
  if (options.compare_reference) {
    const double engine_compute_seconds = report.phases.empty() ? synthesis_wall_seconds : compute_seconds(report);
    compare_with_reference(served, policy, synthesis_wall_seconds, engine_compute_seconds, quiet);
  }
  if (mpi.rank() == 0) std::printf("wrote %s\n", output.c_str());
  return 0;
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
  const auto setup_start = SteadyClock::now();
  const Config config = load_with_overrides(options);
  check_output_option(options, config);
  // With refine, the first round's abstraction: printed, planned and handed to the rounds.
  const Abstraction abstraction = Abstraction::from_config(config.refine ? first_round_config(config) : config);
  const double setup_seconds = seconds_since(setup_start);
  check_state_option(options, abstraction.states);
  print_problem(options, config, abstraction);
  if (!options.export_format.empty()) return export_abstraction(options, abstraction);
  print_request(config, mpi);
  // Each rank would decide its own rounds (the seconds' budget): one process refines.
  if (config.refine && mpi.size() > 1)
    throw UsageError("refine runs in one process: run amytiss_synth without mpirun (the bounds use the host's cores)");

  SynthesisOptions synthesis_options;
  synthesis_options.compute = config.compute;
  synthesis_options.communicator = mpi.communicator();
  if (options.dry_run) {
    for (const std::string& line : describe_synthesis(abstraction, synthesis_options))
      std::printf("plan: %s\n", line.c_str());
    if (config.refine) std::printf("plan: %s\n", describe_refine(*config.refine, abstraction.states.size()).c_str());
    std::printf("dry run: nothing computed, no file written\n");
    return 0;
  }
  return synthesize_and_write(options, config, abstraction, synthesis_options, setup_seconds, mpi);
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
  } catch (const ExportTooLarge& error) {
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
