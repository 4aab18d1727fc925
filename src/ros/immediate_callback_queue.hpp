#pragma once
// A roscpp callback queue that runs a service's callbacks as they are added, on the adding thread,
// instead of handing each to a spinner thread. The adding thread is roscpp's network (poll)
// thread, which has just read the request: the call is answered there without a switch to a
// spinner thread and back. Only for a service whose callback is short and never blocks (the
// node's network I/O waits while it runs).
//
// Fairness: roscpp's network thread keeps reading a connection as long as requests are waiting
// on it, so a client that sends its next request as soon as it has an answer could be served on
// and on while the other connections wait. After `immediate_per_poll` callbacks without a return
// of the network thread to its poll, a callback goes to `overflow` (a spinner's queue), which
// stops the reading of its connection until a spinner has answered it.
//
// Safety: roscpp's network thread answering on a connection while a spinner thread finishes
// writing an answer on the same connection can deadlock (they take the connection's write lock
// and its socket's lock in opposite orders). So once a callback went to `overflow`, every
// callback goes there until none of them is waiting or running.
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <shared_mutex>

#include <boost/signals2/connection.hpp>
#include <ros/callback_queue_interface.h>

namespace amytiss_ros {

class ImmediateCallbackQueue : public ros::CallbackQueueInterface {
 public:
  /// Call after ros::start() (a node handle exists); `overflow` must outlive this queue.
  ImmediateCallbackQueue(ros::CallbackQueueInterface& overflow, std::size_t immediate_per_poll);
  ~ImmediateCallbackQueue() override;
  ImmediateCallbackQueue(const ImmediateCallbackQueue&) = delete;
  ImmediateCallbackQueue& operator=(const ImmediateCallbackQueue&) = delete;

  /// Runs `callback` now, on this thread, or adds it to the overflow queue (see above).
  void addCallback(const ros::CallbackInterfacePtr& callback, uint64_t owner_id) override;
  /// Removes the owner's callbacks from the overflow queue and returns once none of them runs
  /// (roscpp calls it when a service is shut down). Not from a callback of this queue.
  void removeByID(uint64_t owner_id) override;

  /// The network thread is about to poll its sockets (the constructor connects this to roscpp).
  void on_poll() { added_since_poll_ = 0; }

  /// Callbacks run here so far, and those handed to the overflow queue (diagnostics, tests).
  std::size_t immediate_count() const { return immediate_count_; }
  std::size_t overflow_count() const { return overflow_count_; }

 private:
  ros::CallbackQueueInterface& overflow_;
  const std::size_t immediate_per_poll_;
  std::atomic<std::size_t> added_since_poll_{0};
  std::shared_ptr<std::atomic<std::size_t>> overflow_pending_;  // waiting or running there
  std::atomic<std::size_t> immediate_count_{0}, overflow_count_{0};
  boost::signals2::connection poll_listener_;
  std::shared_mutex running_;  // held shared by each callback running here
};

}  // namespace amytiss_ros
