#pragma once
// Removal of temporary files when a signal ends the process while they are being written.
//
// While at least one file is registered, handlers are installed for every signal whose default
// action ends the process and that is not raised by a fault of the program itself: SIGHUP,
// SIGINT, SIGQUIT, SIGTERM, SIGXFSZ, SIGUSR1, SIGUSR2, SIGALRM, SIGPIPE, SIGXCPU, SIGVTALRM,
// SIGPROF, SIGPOLL and SIGPWR (not SIGSEGV, SIGBUS, SIGFPE, SIGILL, SIGTRAP, SIGABRT, SIGSYS, nor
// the real-time signals). A signal whose previous disposition was the default (the process ends)
// unlinks every registered file and is raised again with the default disposition, so the process
// ends as it would have; a signal the program handles itself goes to its handler and removes
// nothing (the program goes on and the writer cleans up); an ignored signal stays ignored.
// SIGXFSZ with the default disposition is the exception: it is ignored, so a write past the file
// size limit fails with EFBIG and is reported like a full disk instead of ending the process. The
// previous dispositions are restored when the last file is unregistered. SIGKILL cannot be
// caught: TemporaryFile removes the orphans of dead processes instead.
#include <cstddef>
#include <string>

namespace amytiss::detail {

/// Registers one path for the lifetime of the object. At most kMaxFiles paths (of at most
/// kMaxPathBytes - 1 bytes) are registered at once; beyond that, or for a longer path, the
/// constructor throws std::length_error.
class FatalSignalCleanup {
 public:
  static constexpr std::size_t kMaxFiles = 32;
  static constexpr std::size_t kMaxPathBytes = 4096;

  explicit FatalSignalCleanup(const std::string& path);
  ~FatalSignalCleanup();
  FatalSignalCleanup(const FatalSignalCleanup&) = delete;
  FatalSignalCleanup& operator=(const FatalSignalCleanup&) = delete;

 private:
  std::size_t slot_;
};

}  // namespace amytiss::detail
