#pragma once
// A file written under a temporary name next to its final path and renamed into place only when
// it is complete, so a reader never sees half a file and a failed write leaves the previous file
// intact. The temporary name is "<final path>.tmp.<pid>". Only regular files are replaced: a
// symbolic link is followed to its target, and a device, a FIFO or a socket is refused.
//
//   TemporaryFile file("out/model.tra");   // removes orphans of dead processes, creates the file
//   file.stream() << ...;                  // buffered; a failed write makes the stream bad
//   file.commit();                         // flush, fsync, close, rename; throws FileWriteError
//
// Until commit() succeeds, the destructor removes the temporary file, and so does a fatal signal
// (FatalSignalCleanup). Every error names the file and the system's reason (strerror).
#include <memory>
#include <ostream>
#include <stdexcept>
#include <string>

#include "io/fatal_signal_cleanup.hpp"

namespace amytiss::detail {

/// A file could not be created, written, flushed, closed or renamed. what() names the file and
/// the reason, e.g. "cannot write out/p.h5.tmp.4242: No space left on device".
class FileWriteError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Removes "<final path>.tmp.<pid>" files whose process no longer exists (kill(pid, 0) fails with
/// ESRCH): the leftovers of a writer killed by SIGKILL or a crash. Best effort: files that cannot
/// be removed stay. Returns the number removed.
std::size_t remove_orphaned_temporaries(const std::string& final_path);

/// The path a write to `path` replaces: `path` itself, or, for a symbolic link, the canonical
/// path of its target, so the link stays and its target is replaced. Throws FileWriteError naming
/// `path` when it is (or links to) a character or block device, a FIFO or a socket, or is a link
/// to a missing file. Anything else (nothing there, a regular file, a directory: the rename
/// fails) is left to the write.
std::string replaceable_path(const std::string& path);

class TemporaryFile {
 public:
  /// Resolves the final path (replaceable_path), removes orphans (remove_orphaned_temporaries),
  /// then creates the temporary file (mode 0666 less the umask). Throws FileWriteError when the
  /// final path is refused or the file cannot be created.
  explicit TemporaryFile(const std::string& final_path);
  ~TemporaryFile();
  TemporaryFile(const TemporaryFile&) = delete;
  TemporaryFile& operator=(const TemporaryFile&) = delete;

  const std::string& final_path() const { return final_path_; }
  const std::string& temporary_path() const { return temporary_path_; }

  /// Buffered output into the temporary file.
  std::ostream& stream();
  /// Writes everything and flushes it to the disk (fsync), then closes the file: the step where
  /// a full disk or an I/O error shows. Throws FileWriteError; idempotent.
  void finish();
  /// finish(), then renames the temporary file to the final path. Throws FileWriteError.
  void commit();

 private:
  class Buffer;
  [[noreturn]] void fail(const std::string& action, int error_number) const;

  std::string final_path_, temporary_path_;
  FatalSignalCleanup cleanup_;
  std::unique_ptr<Buffer> buffer_;
  std::unique_ptr<std::ostream> stream_;
  bool finished_ = false, committed_ = false;
};

}  // namespace amytiss::detail
