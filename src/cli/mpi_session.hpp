#pragma once
// The MPI ranks of an amytiss_synth run (docs/scale_out.md). Built with MPI (AMYTISS_WITH_MPI),
// a process that mpirun or a batch scheduler started joins MPI_COMM_WORLD; otherwise, and in a
// build without MPI, the process is alone and communicator() is null.
#include <memory>
#include <string>

#include "amytiss/scale_out.hpp"

namespace amytiss::cli {

class MpiSession {
 public:
  MpiSession(int* argc, char*** argv);
  ~MpiSession();
  MpiSession(const MpiSession&) = delete;
  MpiSession& operator=(const MpiSession&) = delete;

  /// The ranks, or null when this process is alone.
  Communicator* communicator() { return communicator_.get(); }
  int rank() const { return communicator_ ? communicator_->rank() : 0; }
  int size() const { return communicator_ ? communicator_->size() : 1; }
  /// Ends every rank of the run with `status` (MPI_Abort); returns when alone.
  void abort_all(int status);
  /// Whether this build can run under mpirun.
  static bool available();

 private:
  std::unique_ptr<Communicator> communicator_;
};

}  // namespace amytiss::cli
