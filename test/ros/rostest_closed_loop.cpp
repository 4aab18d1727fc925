// rostest: closed-loop episodes of a steering car through the topics; the success rate is
// consistent with V_0 and every successful episode turned the car.
#include <cmath>
#include <cstdio>
#include <fstream>
#include <string>
#include <mutex>

#include <amytiss/EpisodeSummary.h>

#include "rostest_support.hpp"

namespace {

constexpr unsigned kEpisodes = 40;
constexpr double kSummaryWaitSeconds = 45.0;
constexpr double kStandardErrors = 4.0;
// The plant is the concrete system, the guarantee is for the abstraction (nearest-cell snapping):
// allow this much below V_0 beyond the sampling error.
constexpr double kAbstractionGap = 0.05;
// The target's yaw is 80-100 degrees from the start's 0.
constexpr double kMinimumTurnDegrees = 45.0;

TEST(ClosedLoop, SteeringCarReachesTheTargetConsistentWithV0) {
  ros::NodeHandle handle;
  std::mutex mutex;
  amytiss::EpisodeSummary::ConstPtr summary;
  ros::Subscriber subscriber = handle.subscribe<amytiss::EpisodeSummary>(
      "/amytiss/episode_summary", 1, [&](const amytiss::EpisodeSummary::ConstPtr& message) {
        std::lock_guard<std::mutex> lock(mutex);
        summary = message;
      });
  ASSERT_TRUE(amytiss_test::poll_until(
      [&] {
        std::lock_guard<std::mutex> lock(mutex);
        return summary != nullptr;
      },
      kSummaryWaitSeconds));
  std::lock_guard<std::mutex> lock(mutex);
  std::printf("closed loop: %u/%u episodes reached the target (rate %.3f), predicted V_0 %.4f\n",
              summary->successes, summary->episodes, summary->success_rate, summary->predicted_probability);
  ASSERT_EQ(summary->episodes, kEpisodes);
  ASSERT_EQ(summary->outcomes.size(), kEpisodes);
  EXPECT_EQ(summary->outcomes[0].rfind("episode 1: ", 0), 0u) << summary->outcomes[0];
  EXPECT_GT(summary->successes, kEpisodes / 2);
  const double predicted = summary->predicted_probability;
  EXPECT_GT(predicted, 0.5);
  const double standard_error = std::sqrt(std::max(predicted * (1 - predicted), 0.25 / kEpisodes) / kEpisodes);
  EXPECT_NEAR(summary->success_rate, predicted, kStandardErrors * standard_error + kAbstractionGap)
      << "successes " << summary->successes << "/" << summary->episodes << ", V_0 " << predicted;
  // Outcomes of a car end with " (yaw changed by D degrees, ...)".
  for (const std::string& outcome : summary->outcomes) {
    if (outcome.find("reached the target") == std::string::npos) continue;
    const std::size_t at = outcome.find("yaw changed by ");
    ASSERT_NE(at, std::string::npos) << outcome;
    EXPECT_GE(std::stod(outcome.substr(at + std::string("yaw changed by ").size())), kMinimumTurnDegrees) << outcome;
  }
  std::ifstream csv(summary->csv_file);
  ASSERT_TRUE(csv.good()) << summary->csv_file;
  std::string header;
  std::getline(csv, header);
  EXPECT_EQ(header, "episode,step,x0,x1,x2,x3,x4,u0,u1,probability,success");
}

}  // namespace

int main(int argc, char** argv) { return amytiss_test::run_rostests(argc, argv, "amytiss_closed_loop_test", 1); }
