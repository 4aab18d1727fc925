// The service queue of the policy server: callbacks run on the adding thread up to a number per
// poll of the network thread, then on the overflow queue, and never on both at once.
#include <chrono>
#include <functional>
#include <future>
#include <thread>
#include <vector>

#include <boost/make_shared.hpp>
#include <gtest/gtest.h>
#include <ros/callback_queue.h>

#include "immediate_callback_queue.hpp"

namespace {

constexpr std::size_t kImmediatePerPoll = 3;
constexpr uint64_t kOwner = 7;
// Long enough for a removal that does not wait to have returned; it is expected not to.
constexpr auto kStillWaitingCheck = std::chrono::milliseconds(100);
constexpr auto kCompletionLimit = std::chrono::seconds(10);

class Recorded : public ros::CallbackInterface {
 public:
  explicit Recorded(std::function<void()> body) : body_(std::move(body)) {}
  CallResult call() override {
    body_();
    return Success;
  }

 private:
  std::function<void()> body_;
};

ros::CallbackInterfacePtr recording(std::vector<std::thread::id>& threads) {
  return boost::make_shared<Recorded>([&threads] { threads.push_back(std::this_thread::get_id()); });
}

TEST(ImmediateCallbackQueue, RunsCallbacksOnTheAddingThreadUpToTheLimitPerPollThenHandsThemOver) {
  ros::CallbackQueue overflow;
  amytiss_ros::ImmediateCallbackQueue queue(overflow, kImmediatePerPoll);
  std::vector<std::thread::id> threads;
  for (std::size_t i = 0; i < kImmediatePerPoll; ++i) queue.addCallback(recording(threads), kOwner);
  ASSERT_EQ(threads.size(), kImmediatePerPoll);
  for (const auto& id : threads) EXPECT_EQ(id, std::this_thread::get_id());

  queue.addCallback(recording(threads), kOwner);
  EXPECT_EQ(threads.size(), kImmediatePerPoll) << "the one past the limit waits in the overflow queue";
  EXPECT_EQ(queue.overflow_count(), 1u);
  overflow.callAvailable();
  EXPECT_EQ(threads.size(), kImmediatePerPoll + 1);

  queue.on_poll();
  queue.addCallback(recording(threads), kOwner);
  EXPECT_EQ(threads.size(), kImmediatePerPoll + 2) << "a poll starts a new count";
  EXPECT_EQ(queue.immediate_count(), kImmediatePerPoll + 1);
}

TEST(ImmediateCallbackQueue, WhileAHandedOverCallbackIsPendingEveryCallbackIsHandedOver) {
  ros::CallbackQueue overflow;
  amytiss_ros::ImmediateCallbackQueue queue(overflow, kImmediatePerPoll);
  std::vector<std::thread::id> threads;
  for (std::size_t i = 0; i <= kImmediatePerPoll; ++i) queue.addCallback(recording(threads), kOwner);
  ASSERT_EQ(queue.overflow_count(), 1u);
  queue.on_poll();
  queue.addCallback(recording(threads), kOwner);
  EXPECT_EQ(queue.overflow_count(), 2u) << "one is still pending there, so this one follows it";
  EXPECT_EQ(threads.size(), kImmediatePerPoll);
  overflow.callAvailable();
  EXPECT_EQ(threads.size(), kImmediatePerPoll + 2);
  queue.addCallback(recording(threads), kOwner);
  EXPECT_EQ(queue.overflow_count(), 2u) << "none pending: run here again";
  EXPECT_EQ(threads.size(), kImmediatePerPoll + 3);
}

TEST(ImmediateCallbackQueue, RemovalWaitsForARunningCallback) {
  ros::CallbackQueue overflow;
  amytiss_ros::ImmediateCallbackQueue queue(overflow, kImmediatePerPoll);
  std::promise<void> entered, release;
  std::shared_future<void> released = release.get_future().share();
  std::thread network([&] {
    queue.addCallback(boost::make_shared<Recorded>([&] {
                        entered.set_value();
                        released.wait();
                      }),
                      kOwner);
  });
  ASSERT_EQ(entered.get_future().wait_for(kCompletionLimit), std::future_status::ready);
  std::future<void> removal = std::async(std::launch::async, [&] { queue.removeByID(kOwner); });
  EXPECT_EQ(removal.wait_for(kStillWaitingCheck), std::future_status::timeout)
      << "removal returned while a callback still ran";
  release.set_value();
  EXPECT_EQ(removal.wait_for(kCompletionLimit), std::future_status::ready);
  network.join();
}

TEST(ImmediateCallbackQueue, RemovalDropsHandedOverCallbacks) {
  ros::CallbackQueue overflow;
  amytiss_ros::ImmediateCallbackQueue queue(overflow, kImmediatePerPoll);
  std::vector<std::thread::id> threads;
  for (std::size_t i = 0; i <= kImmediatePerPoll; ++i) queue.addCallback(recording(threads), kOwner);
  ASSERT_EQ(queue.overflow_count(), 1u);
  queue.removeByID(kOwner);
  overflow.callAvailable();
  EXPECT_EQ(threads.size(), kImmediatePerPoll) << "the handed-over callback was removed, not run";
  queue.on_poll();
  queue.addCallback(recording(threads), kOwner);
  EXPECT_EQ(threads.size(), kImmediatePerPoll + 1) << "the removed one no longer counts as pending";
}

}  // namespace
