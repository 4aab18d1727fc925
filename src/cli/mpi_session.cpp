// MPI glue of amytiss_synth: the Communicator over MPI_COMM_WORLD (MPI_Allgatherv of byte
// blocks), and joining MPI only when a launcher started the process.
#include "mpi_session.hpp"

#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <stdexcept>
#include <string>
#include <vector>

#ifdef AMYTISS_WITH_MPI
#include <mpi.h>
#endif

namespace amytiss::cli {
namespace {

#ifdef AMYTISS_WITH_MPI
// Launchers (Open MPI's mpirun, PMIx and PMI of batch schedulers) set one of these.
bool started_by_launcher() {
  for (const char* name : {"OMPI_COMM_WORLD_SIZE", "PMIX_RANK", "PMI_RANK", "PMI_SIZE"})
    if (std::getenv(name)) return true;
  return false;
}

void check_mpi(int code, const char* call) {
  if (code != MPI_SUCCESS)
    throw std::runtime_error(std::string(call) + " failed (MPI error " + std::to_string(code) + ")");
}

class MpiCommunicator : public Communicator {
 public:
  MpiCommunicator() {
    check_mpi(MPI_Comm_rank(MPI_COMM_WORLD, &rank_), "MPI_Comm_rank");
    check_mpi(MPI_Comm_size(MPI_COMM_WORLD, &size_), "MPI_Comm_size");
  }
  int rank() const override { return rank_; }
  int size() const override { return size_; }
  // MPI counts are int: blocks beyond 2^31 - 1 bytes go in rounds of at most that much per rank.
  void allgather_bytes(void* data, const std::vector<std::size_t>& offsets,
                       const std::vector<std::size_t>& counts) override {
    constexpr std::size_t kRound = std::size_t(1) << 30;
    std::vector<std::size_t> done(counts.size(), 0);
    for (;;) {
      std::vector<int> round_counts(counts.size()), round_offsets(counts.size());
      bool any = false;
      for (std::size_t r = 0; r < counts.size(); ++r) {
        round_counts[r] = int(std::min(kRound, counts[r] - done[r]));
        any = any || round_counts[r] > 0;
      }
      if (!any) return;
      // Displacements are int too: address each round relative to the lowest block start.
      char* base = static_cast<char*>(data);
      std::size_t lowest = SIZE_MAX;
      for (std::size_t r = 0; r < counts.size(); ++r)
        if (round_counts[r] > 0) lowest = std::min(lowest, offsets[r] + done[r]);
      std::vector<char*> starts(counts.size());
      for (std::size_t r = 0; r < counts.size(); ++r) starts[r] = base + offsets[r] + done[r];
      if (offsets.back() + done.back() - lowest > std::size_t(INT32_MAX)) {
        // Blocks too far apart for int displacements: one broadcast per rank.
        for (std::size_t r = 0; r < counts.size(); ++r)
          if (round_counts[r] > 0)
            check_mpi(MPI_Bcast(starts[r], round_counts[r], MPI_BYTE, int(r), MPI_COMM_WORLD), "MPI_Bcast");
      } else {
        for (std::size_t r = 0; r < counts.size(); ++r)
          round_offsets[r] = round_counts[r] > 0 ? int(starts[r] - (base + lowest)) : 0;
        check_mpi(MPI_Allgatherv(MPI_IN_PLACE, 0, MPI_DATATYPE_NULL, base + lowest, round_counts.data(),
                                 round_offsets.data(), MPI_BYTE, MPI_COMM_WORLD),
                  "MPI_Allgatherv");
      }
      for (std::size_t r = 0; r < counts.size(); ++r) done[r] += std::size_t(round_counts[r]);
    }
  }
  std::vector<double> allgather_value(double value) override {
    std::vector<double> values(std::size_t(size_), 0.0);
    check_mpi(MPI_Allgather(&value, 1, MPI_DOUBLE, values.data(), 1, MPI_DOUBLE, MPI_COMM_WORLD), "MPI_Allgather");
    return values;
  }

 private:
  int rank_ = 0, size_ = 1;
};
#endif

}  // namespace

MpiSession::MpiSession(int* argc, char*** argv) {
#ifdef AMYTISS_WITH_MPI
  if (!started_by_launcher()) return;
  check_mpi(MPI_Init(argc, argv), "MPI_Init");
  communicator_ = std::make_unique<MpiCommunicator>();
#else
  (void)argc;
  (void)argv;
#endif
}

MpiSession::~MpiSession() {
#ifdef AMYTISS_WITH_MPI
  if (communicator_) MPI_Finalize();
#endif
}

void MpiSession::abort_all(int status) {
#ifdef AMYTISS_WITH_MPI
  if (communicator_ && communicator_->size() > 1) MPI_Abort(MPI_COMM_WORLD, status);
#else
  (void)status;
#endif
}

bool MpiSession::available() {
#ifdef AMYTISS_WITH_MPI
  return true;
#else
  return false;
#endif
}

}  // namespace amytiss::cli
