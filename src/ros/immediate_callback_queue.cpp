#include "immediate_callback_queue.hpp"

#include <mutex>

#include <boost/make_shared.hpp>
#include <ros/poll_manager.h>

namespace amytiss_ros {

namespace {

// A callback handed to the overflow queue, counted in `pending` until it has run or was removed.
class CountedCallback : public ros::CallbackInterface {
 public:
  CountedCallback(ros::CallbackInterfacePtr callback, std::shared_ptr<std::atomic<std::size_t>> pending)
      : callback_(std::move(callback)), pending_(std::move(pending)) {
    ++*pending_;
  }
  // Destroyed after its call returned (its answer written) or when the queue dropped it.
  ~CountedCallback() override { --*pending_; }
  CallResult call() override { return callback_->call(); }
  bool ready() override { return callback_->ready(); }

 private:
  ros::CallbackInterfacePtr callback_;
  std::shared_ptr<std::atomic<std::size_t>> pending_;
};

}  // namespace

ImmediateCallbackQueue::ImmediateCallbackQueue(ros::CallbackQueueInterface& overflow, std::size_t immediate_per_poll)
    : overflow_(overflow),
      immediate_per_poll_(immediate_per_poll),
      overflow_pending_(std::make_shared<std::atomic<std::size_t>>(0)) {
  poll_listener_ = ros::PollManager::instance()->addPollThreadListener([this] { on_poll(); });
}

ImmediateCallbackQueue::~ImmediateCallbackQueue() {
  ros::PollManager::instance()->removePollThreadListener(poll_listener_);
}

void ImmediateCallbackQueue::addCallback(const ros::CallbackInterfacePtr& callback, uint64_t owner_id) {
  // While none is pending there, no spinner thread answers on a connection and only the network
  // thread (this one) adds callbacks: the count cannot rise between this test and the call.
  if (*overflow_pending_ > 0 || added_since_poll_++ >= immediate_per_poll_) {
    ++overflow_count_;
    overflow_.addCallback(boost::make_shared<CountedCallback>(callback, overflow_pending_), owner_id);
    return;
  }
  ++immediate_count_;
  std::shared_lock<std::shared_mutex> lock(running_);
  callback->call();
}

void ImmediateCallbackQueue::removeByID(uint64_t owner_id) {
  overflow_.removeByID(owner_id);
  // Nothing is stored here: only wait for the callbacks running. roscpp drops a service's
  // connections before it calls this, and a service callback added later finds its connection
  // dropped and does not call the service.
  std::unique_lock<std::shared_mutex> lock(running_);
}

}  // namespace amytiss_ros
