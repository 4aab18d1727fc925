#pragma once
// Export of the finite abstraction (guarantee: abstraction, the transition probabilities from the
// cells' centre points) for independent checking (docs/export.md): PRISM's explicit
// files (model.tra, model.sta, model.lab) or Storm's DRN (model.drn), with a README.md in the
// folder saying how the files map to the specification.
//
// States: 0..N-1 are the state grid's cells (flat index, row-major), N is the sink: one absorbing
// state that receives, in every row, the mass that leaves the grid or is cut by the truncation
// (so every row sums to 1). With disturbances, the adversary's turn is a state of its own: cell x
// chooses input u (choice index = flat input index) and moves with probability 1 to the state
// (x, u), index N + 1 + r*U + u (r: rank of x among the Free cells, U: number of inputs), whose
// choices are the disturbances w (choice index = flat disturbance index) with the abstraction's
// transition rows. Without disturbances, choice u of cell x is that row directly. Cells with a
// fixed role (target, avoid, unsafe) and the sink have one choice: a self-loop.
// Labels: init (every cell), target and avoid (reachability, reach-avoid) or unsafe (safety:
// cells outside the safe set), sink, and adversary (the (x, u) states).
#include <cstddef>
#include <stdexcept>
#include <string>
#include <vector>

#include "amytiss/abstraction.hpp"

namespace amytiss {

enum class ExportFormat { Prism, Drn };

/// The model is larger than the limit the caller allows.
class ExportTooLarge : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct ExportSummary {
  std::size_t states = 0;       ///< cells + sink + adversary states
  std::size_t choices = 0;      ///< over all states
  std::size_t transitions = 0;  ///< non-zero probabilities written
  std::vector<std::string> files;
};

/// Transitions the export would write at most: every row's window cells plus its sink entry,
/// the adversary moves and the self-loops. Cheap (windows only, no masses).
std::size_t export_transition_bound(const Abstraction& abstraction);

/// Writes the model into `directory` (created if missing): every file under a temporary name, all
/// renamed once all are on the disk, so a failure leaves no partial export and a previous one
/// intact. Throws ConfigError (key `guarantee`) for a configuration with guarantee: system (the
/// export is the abstraction of the cells' centre points, whose values are not that guarantee's
/// bounds), ExportTooLarge when export_transition_bound() exceeds `max_transitions`,
/// std::runtime_error when a file cannot be written (naming the file and the system's reason).
ExportSummary export_model(const Abstraction& abstraction, ExportFormat format, const std::string& directory,
                           std::size_t max_transitions);

}  // namespace amytiss
