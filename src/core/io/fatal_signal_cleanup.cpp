#include "io/fatal_signal_cleanup.hpp"

#include <signal.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <atomic>
#include <cstring>
#include <mutex>
#include <stdexcept>

namespace amytiss::detail {
namespace {

// Not the signals a fault of the program raises (SIGSEGV, SIGBUS, ...): after a crash its state
// cannot be trusted, and the next write to the path removes the orphan.
constexpr std::array<int, 14> kSignals{SIGHUP,  SIGINT,  SIGQUIT, SIGTERM,   SIGXFSZ, SIGUSR1, SIGUSR2,
                                       SIGALRM, SIGPIPE, SIGXCPU, SIGVTALRM, SIGPROF, SIGPOLL, SIGPWR};

enum SlotState : int { kFree = 0, kClaimed = 1, kReady = 2 };

// Fixed storage the handler can read without allocating or locking: a path is copied in while the
// slot is claimed and only then marked ready.
struct Slot {
  std::atomic<int> state{kFree};
  char path[FatalSignalCleanup::kMaxPathBytes] = {};
};

Slot slots[FatalSignalCleanup::kMaxFiles];
struct sigaction previous_actions[kSignals.size()];
std::mutex install_mutex;
std::size_t registered = 0;  // guarded by install_mutex

static_assert(std::atomic<int>::is_always_lock_free, "the handler reads the slots lock-free");

const struct sigaction* previous_action(int signal_number) {
  for (std::size_t i = 0; i < kSignals.size(); ++i)
    if (kSignals[i] == signal_number) return &previous_actions[i];
  return nullptr;
}

void remove_registered_files() {
  for (Slot& slot : slots)
    if (slot.state.load(std::memory_order_acquire) == kReady) ::unlink(slot.path);
}

// Async-signal-safe: only unlink, sigaction, sigprocmask and raise.
void on_fatal_signal(int signal_number, siginfo_t* info, void* context) {
  const int saved_errno = errno;
  const struct sigaction* previous = previous_action(signal_number);
  if (previous && (previous->sa_flags & SA_SIGINFO)) {
    previous->sa_sigaction(signal_number, info, context);
  } else if (previous && previous->sa_handler == SIG_IGN) {
    // Ignored before: stays ignored.
  } else if (signal_number == SIGXFSZ) {
    // A write past the file size limit: ignored, so the write fails with EFBIG and the writer
    // reports "File too large" and removes its file, instead of the process dumping core.
  } else if (previous && previous->sa_handler != SIG_DFL) {
    previous->sa_handler(signal_number);
  } else {
    remove_registered_files();
    struct sigaction default_action {};
    default_action.sa_handler = SIG_DFL;
    sigemptyset(&default_action.sa_mask);
    ::sigaction(signal_number, &default_action, nullptr);
    sigset_t just_this;
    sigemptyset(&just_this);
    sigaddset(&just_this, signal_number);
    ::sigprocmask(SIG_UNBLOCK, &just_this, nullptr);
    ::raise(signal_number);
  }
  errno = saved_errno;
}

void install_handlers() {
  struct sigaction action {};
  action.sa_sigaction = on_fatal_signal;
  action.sa_flags = SA_SIGINFO | SA_RESTART;
  sigemptyset(&action.sa_mask);
  for (int signal_number : kSignals) sigaddset(&action.sa_mask, signal_number);
  for (std::size_t i = 0; i < kSignals.size(); ++i) ::sigaction(kSignals[i], &action, &previous_actions[i]);
}

void restore_handlers() {
  for (std::size_t i = 0; i < kSignals.size(); ++i) ::sigaction(kSignals[i], &previous_actions[i], nullptr);
}

}  // namespace

FatalSignalCleanup::FatalSignalCleanup(const std::string& path) : slot_(kMaxFiles) {
  if (path.size() >= kMaxPathBytes)
    throw std::length_error("path of " + std::to_string(path.size()) + " bytes is too long to register (limit " +
                            std::to_string(kMaxPathBytes - 1) + ")");
  for (std::size_t i = 0; i < kMaxFiles && slot_ == kMaxFiles; ++i) {
    int expected = kFree;
    if (slots[i].state.compare_exchange_strong(expected, kClaimed)) slot_ = i;
  }
  if (slot_ == kMaxFiles)
    throw std::length_error("more than " + std::to_string(kMaxFiles) + " temporary files are open at once");
  std::memcpy(slots[slot_].path, path.c_str(), path.size() + 1);
  slots[slot_].state.store(kReady, std::memory_order_release);
  std::lock_guard<std::mutex> lock(install_mutex);
  if (registered++ == 0) install_handlers();
}

FatalSignalCleanup::~FatalSignalCleanup() {
  slots[slot_].state.store(kClaimed, std::memory_order_release);
  {
    std::lock_guard<std::mutex> lock(install_mutex);
    if (--registered == 0) restore_handlers();
  }
  slots[slot_].state.store(kFree, std::memory_order_release);
}

}  // namespace amytiss::detail
