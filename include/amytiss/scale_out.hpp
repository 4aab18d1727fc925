#pragma once
// Several processes (MPI ranks) synthesizing one problem together (docs/scale_out.md). The core
// does not link MPI: the program that starts the ranks passes an implementation of Communicator
// in SynthesisOptions (amytiss_synth does, when built with MPI).
#include <cstddef>
#include <vector>

namespace amytiss {

/// The processes of one synthesis. Every call is collective: every rank makes the same calls in
/// the same order.
class Communicator {
 public:
  virtual ~Communicator() = default;
  virtual int rank() const = 0;  ///< 0-based
  virtual int size() const = 0;  ///< number of ranks, >= 1
  /// Rank r's bytes [offsets[r], offsets[r] + counts[r]) of `data` are copied into every rank's
  /// `data` at the same place (blocks disjoint, one per rank in rank order).
  virtual void allgather_bytes(void* data, const std::vector<std::size_t>& offsets,
                               const std::vector<std::size_t>& counts) = 0;
  /// Every rank's `value`, in rank order.
  virtual std::vector<double> allgather_value(double value) = 0;
};

/// One rank (no other process): the communicator of an ordinary run.
class SoloCommunicator : public Communicator {
 public:
  int rank() const override { return 0; }
  int size() const override { return 1; }
  void allgather_bytes(void*, const std::vector<std::size_t>&, const std::vector<std::size_t>&) override {}
  std::vector<double> allgather_value(double value) override { return {value}; }
};

}  // namespace amytiss
