#include "io/temporary_file.hpp"

#include <fcntl.h>
#include <signal.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <memory>
#include <streambuf>
#include <vector>

namespace amytiss::detail {
namespace {

constexpr const char* kTemporaryInfix = ".tmp.";
constexpr std::size_t kBufferBytes = 1u << 20;

std::string temporary_name(const std::string& final_path) {
  return final_path + kTemporaryInfix + std::to_string(::getpid());
}

// The process id in "<final name>.tmp.<pid>", or 0 when `name` is not such a name.
pid_t writer_pid(const std::string& name, const std::string& prefix) {
  if (name.size() <= prefix.size() || name.compare(0, prefix.size(), prefix) != 0) return 0;
  const std::string digits = name.substr(prefix.size());
  if (digits.size() > 9 || digits.find_first_not_of("0123456789") != std::string::npos) return 0;
  return pid_t(std::stol(digits));
}

const char* kind_of(mode_t mode) {
  if (S_ISCHR(mode)) return "a character device";
  if (S_ISBLK(mode)) return "a block device";
  if (S_ISFIFO(mode)) return "a FIFO";
  if (S_ISSOCK(mode)) return "a socket";
  return nullptr;
}

}  // namespace

std::string replaceable_path(const std::string& path) {
  struct stat status {};
  // Nothing there or not reachable: creating the temporary file reports why.
  if (::lstat(path.c_str(), &status) != 0) return path;
  if (const char* kind = kind_of(status.st_mode))
    throw FileWriteError("cannot write " + path + ": it is " + kind + ", not a regular file");
  if (!S_ISLNK(status.st_mode)) return path;
  struct stat target {};
  if (::stat(path.c_str(), &target) != 0)
    throw FileWriteError("cannot write " + path + ": it is a symbolic link to a missing file (" +
                         std::strerror(errno) + ")");
  if (const char* kind = kind_of(target.st_mode))
    throw FileWriteError("cannot write " + path + ": it is a symbolic link to " + kind + ", not to a regular file");
  std::unique_ptr<char, decltype(&std::free)> resolved(::realpath(path.c_str(), nullptr), &std::free);
  if (!resolved) throw FileWriteError("cannot write " + path + ": " + std::strerror(errno));
  return resolved.get();
}

std::size_t remove_orphaned_temporaries(const std::string& final_path) {
  namespace fs = std::filesystem;
  const fs::path target(final_path);
  const fs::path folder = target.has_parent_path() ? target.parent_path() : fs::path(".");
  const std::string prefix = target.filename().string() + kTemporaryInfix;
  std::error_code error;
  std::size_t removed = 0;
  for (fs::directory_iterator entry(folder, error), end; !error && entry != end; entry.increment(error)) {
    const pid_t pid = writer_pid(entry->path().filename().string(), prefix);
    if (pid <= 0 || pid == ::getpid()) continue;
    // EPERM means the process exists under another user: its file is not an orphan.
    if (::kill(pid, 0) != 0 && errno == ESRCH && ::unlink(entry->path().c_str()) == 0) ++removed;
  }
  return removed;
}

// A stream buffer over a file descriptor that remembers the errno of the first failed write.
class TemporaryFile::Buffer : public std::streambuf {
 public:
  explicit Buffer(int descriptor) : descriptor_(descriptor), buffer_(kBufferBytes) {
    setp(buffer_.data(), buffer_.data() + buffer_.size());
  }
  int descriptor() const { return descriptor_; }
  int error() const { return error_; }
  void release() { descriptor_ = -1; }

 protected:
  int_type overflow(int_type character) override {
    if (drain() != 0) return traits_type::eof();
    if (!traits_type::eq_int_type(character, traits_type::eof())) {
      *pptr() = traits_type::to_char_type(character);
      pbump(1);
    }
    return traits_type::not_eof(character);
  }
  std::streamsize xsputn(const char* data, std::streamsize count) override {
    if (count > epptr() - pptr()) {
      if (drain() != 0 || !write_all(data, std::size_t(count))) return 0;
      return count;
    }
    std::memcpy(pptr(), data, std::size_t(count));
    pbump(int(count));
    return count;
  }
  int sync() override { return drain(); }

 private:
  int drain() {
    const std::size_t pending = std::size_t(pptr() - pbase());
    setp(buffer_.data(), buffer_.data() + buffer_.size());
    return write_all(buffer_.data(), pending) ? 0 : -1;
  }
  bool write_all(const char* data, std::size_t bytes) {
    if (error_ != 0) return false;
    while (bytes > 0) {
      const ssize_t written = ::write(descriptor_, data, bytes);
      if (written < 0 && errno == EINTR) continue;
      if (written <= 0) {
        error_ = written < 0 ? errno : EIO;
        return false;
      }
      data += written;
      bytes -= std::size_t(written);
    }
    return true;
  }

  int descriptor_;
  int error_ = 0;
  std::vector<char> buffer_;
};

TemporaryFile::TemporaryFile(const std::string& final_path)
    : final_path_(replaceable_path(final_path)),
      temporary_path_(temporary_name(final_path_)),
      cleanup_(temporary_path_) {
  remove_orphaned_temporaries(final_path_);
  const int descriptor = ::open(temporary_path_.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0666);
  if (descriptor < 0) fail("create", errno);
  buffer_ = std::make_unique<Buffer>(descriptor);
  stream_ = std::make_unique<std::ostream>(buffer_.get());
}

TemporaryFile::~TemporaryFile() {
  if (committed_) return;
  // Already failing or abandoned: the close status no longer matters, the file goes.
  if (buffer_ && buffer_->descriptor() >= 0) ::close(buffer_->descriptor());
  ::unlink(temporary_path_.c_str());
}

std::ostream& TemporaryFile::stream() { return *stream_; }

void TemporaryFile::fail(const std::string& action, int error_number) const {
  throw FileWriteError("cannot " + action + " " + temporary_path_ + ": " + std::strerror(error_number));
}

void TemporaryFile::finish() {
  if (finished_) return;
  stream_->flush();
  if (buffer_->error() != 0) fail("write", buffer_->error());
  if (!*stream_) fail("write", EIO);
  // Some file systems (NFS, delayed allocation) report a full disk only here or at close.
  if (::fsync(buffer_->descriptor()) != 0) fail("flush to the disk", errno);
  const int descriptor = buffer_->descriptor();
  buffer_->release();
  if (::close(descriptor) != 0) fail("close", errno);
  finished_ = true;
}

void TemporaryFile::commit() {
  finish();
  if (::rename(temporary_path_.c_str(), final_path_.c_str()) != 0) {
    const int error_number = errno;
    throw FileWriteError("cannot rename " + temporary_path_ + " to " + final_path_ + ": " +
                         std::strerror(error_number));
  }
  committed_ = true;
}

}  // namespace amytiss::detail
