// Temporary files and their removal on fatal signals: commit and abandon, the signal handlers'
// cases (default, for every terminating signal: remove and die; the program's own handler:
// called, nothing removed; ignored: stays ignored; SIGXFSZ: the write fails instead), the
// dispositions restored afterwards, orphans.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>

#include "io/temporary_file.hpp"

#include "child_process.hpp"
#include "test_support.hpp"

namespace amytiss {
namespace {

namespace fs = std::filesystem;
using detail::FileWriteError;
using detail::TemporaryFile;
using test_support::run_in_child;

class TemporaryFileTest : public ::testing::Test {
 protected:
  void SetUp() override { directory_ = test_support::fresh_test_directory("amytiss_temporary_file_"); }
  void TearDown() override { fs::remove_all(directory_); }
  std::string path(const std::string& name) const { return (directory_ / name).string(); }
  bool empty() const { return fs::is_empty(directory_); }

  fs::path directory_;
};

std::string text_of(const std::string& file) {
  std::ifstream stream(file);
  return std::string(std::istreambuf_iterator<char>(stream), {});
}

TEST_F(TemporaryFileTest, CommitRenamesAndAbandoningRemoves) {
  {
    TemporaryFile file(path("out.txt"));
    EXPECT_EQ(path("out.txt") + ".tmp." + std::to_string(::getpid()), file.temporary_path());
    file.stream() << "complete";
    EXPECT_TRUE(fs::exists(file.temporary_path()));
    file.commit();
    EXPECT_FALSE(fs::exists(file.temporary_path()));
  }
  EXPECT_EQ("complete", text_of(path("out.txt")));
  {
    TemporaryFile file(path("out.txt"));
    file.stream() << "abandoned";
  }
  EXPECT_EQ("complete", text_of(path("out.txt")));
  EXPECT_EQ(1, std::distance(fs::directory_iterator(directory_), fs::directory_iterator()));
}

// rename() would replace whatever is at the final path: a FIFO (or a device node, as root) would
// become a file, and a symbolic link a file beside its target.
TEST_F(TemporaryFileTest, OnlyRegularFilesAreReplacedAndALinkIsFollowedToItsTarget) {
  ASSERT_EQ(0, ::mkfifo(path("fifo").c_str(), 0600));
  try {
    TemporaryFile file(path("fifo"));
    ADD_FAILURE() << "a FIFO is replaced";
  } catch (const FileWriteError& error) {
    EXPECT_EQ("cannot write " + path("fifo") + ": it is a FIFO, not a regular file", std::string(error.what()));
  }
  EXPECT_TRUE(fs::is_fifo(fs::symlink_status(path("fifo"))));
  EXPECT_EQ(1, std::distance(fs::directory_iterator(directory_), fs::directory_iterator()));

  std::ofstream(path("target.txt")) << "older";
  fs::create_symlink("target.txt", path("link.txt"));
  {
    TemporaryFile file(path("link.txt"));
    EXPECT_EQ(fs::canonical(path("target.txt")).string(), file.final_path());
    file.stream() << "newer";
    file.commit();
  }
  EXPECT_TRUE(fs::is_symlink(fs::symlink_status(path("link.txt"))));
  EXPECT_EQ("newer", text_of(path("target.txt")));
}

TEST_F(TemporaryFileTest, AMissingFolderIsReportedWithItsReason) {
  try {
    TemporaryFile file(path("absent/out.txt"));
    ADD_FAILURE() << "created a file in a missing folder";
  } catch (const FileWriteError& error) {
    EXPECT_NE(std::string::npos, std::string(error.what()).find(std::strerror(ENOENT))) << error.what();
  }
}

TEST_F(TemporaryFileTest, SigtermRemovesTheFileAndEndsTheProcess) {
  const auto outcome = run_in_child([&] {
    ::signal(SIGTERM, SIG_DFL);
    TemporaryFile file(path("out.txt"));
    file.stream() << "partial" << std::flush;
    ::raise(SIGTERM);
    return std::string("survived SIGTERM");
  });
  EXPECT_TRUE(outcome.killed_by(SIGTERM)) << outcome.describe();
  EXPECT_TRUE(empty());
}

// Every catchable signal whose default action ends the process, but SIGXFSZ (below): a partial
// file of 64 KiB is removed and the process still ends by that signal.
TEST_F(TemporaryFileTest, EveryTerminatingSignalRemovesTheFileAndEndsTheProcess) {
  for (const int signal_number : {SIGHUP, SIGINT, SIGQUIT, SIGTERM, SIGUSR1, SIGUSR2, SIGALRM, SIGPIPE, SIGXCPU,
                                  SIGVTALRM, SIGPROF, SIGPOLL, SIGPWR}) {
    SCOPED_TRACE(::strsignal(signal_number));
    const auto outcome = run_in_child([&] {
      const rlimit no_core{0, 0};  // SIGQUIT and SIGXCPU dump core by default
      ::setrlimit(RLIMIT_CORE, &no_core);
      ::signal(signal_number, SIG_DFL);
      TemporaryFile file(path("p.h5"));
      file.stream() << std::string(64 * 1024, 'x') << std::flush;
      ::raise(signal_number);
      return std::string("survived the signal");
    });
    EXPECT_TRUE(outcome.killed_by(signal_number)) << outcome.describe();
    EXPECT_TRUE(empty());
  }
}

TEST_F(TemporaryFileTest, AFileSizeLimitIsAnErrorNotTheEndOfTheProcess) {
  constexpr rlim_t kLimit = 4096;
  const auto outcome = run_in_child([&] {
    ::signal(SIGXFSZ, SIG_DFL);  // by default, writing past the limit ends the process
    const rlimit limit{kLimit, kLimit};
    ::setrlimit(RLIMIT_FSIZE, &limit);
    try {
      TemporaryFile file(path("out.txt"));
      file.stream() << std::string(2 * kLimit, 'x');
      file.commit();
    } catch (const FileWriteError& error) {
      return std::string(error.what());
    }
    return std::string("written past the limit");
  });
  EXPECT_TRUE(outcome.exited_normally()) << outcome.describe();
  EXPECT_NE(std::string::npos, outcome.message.find(std::strerror(EFBIG))) << outcome.message;
  EXPECT_TRUE(empty());
}

int own_handler_calls = 0;
void own_handler(int) { ++own_handler_calls; }

TEST_F(TemporaryFileTest, TheProgramsOwnHandlerRunsAndRemovesNothing) {
  const auto outcome = run_in_child([&] {
    ::signal(SIGINT, own_handler);
    ::signal(SIGHUP, SIG_IGN);
    TemporaryFile file(path("out.txt"));
    ::raise(SIGINT);
    ::raise(SIGHUP);
    const bool kept = fs::exists(file.temporary_path());
    file.commit();
    return "handler calls " + std::to_string(own_handler_calls) + ", temporary kept " + (kept ? "yes" : "no");
  });
  EXPECT_TRUE(outcome.exited_normally()) << outcome.describe();
  EXPECT_EQ("handler calls 1, temporary kept yes", outcome.message);
  EXPECT_TRUE(fs::exists(path("out.txt")));
}

TEST_F(TemporaryFileTest, TheDispositionsAreRestoredAfterTheLastFile) {
  const auto outcome = run_in_child([&] {
    ::signal(SIGTERM, own_handler);
    {
      TemporaryFile first(path("a.txt")), second(path("b.txt"));
    }
    struct sigaction now {};
    ::sigaction(SIGTERM, nullptr, &now);
    return std::string(now.sa_handler == own_handler ? "restored" : "not restored");
  });
  EXPECT_EQ("restored", outcome.message) << outcome.describe();
}

TEST_F(TemporaryFileTest, OrphansOfDeadProcessesAreRemovedOthersKept) {
  const pid_t dead = test_support::pid_of_an_ended_process();
  const std::string names[] = {"out.txt.tmp." + std::to_string(dead), "out.txt.tmp.notapid",
                               "out.txt.tmp." + std::to_string(::getpid()), "other.txt.tmp." + std::to_string(dead)};
  for (const std::string& name : names) std::ofstream(path(name)) << "x";
  EXPECT_EQ(1u, detail::remove_orphaned_temporaries(path("out.txt")));
  EXPECT_FALSE(fs::exists(path("out.txt.tmp." + std::to_string(dead))));
  EXPECT_EQ(3, std::distance(fs::directory_iterator(directory_), fs::directory_iterator()));
}

}  // namespace
}  // namespace amytiss
