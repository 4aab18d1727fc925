// rostest: the policy server's service and closed-loop topics against the core policy.
#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <condition_variable>
#include <cstring>
#include <fstream>
#include <limits>
#include <mutex>
#include <random>
#include <thread>

#include <amytiss/GetInput.h>
#include <amytiss/InputCommand.h>
#include <amytiss/StateStamped.h>
#include <diagnostic_msgs/DiagnosticArray.h>

#include "amytiss/policy_file.hpp"
#include "rostest_nodes.hpp"
#include "rostest_support.hpp"
#include "tcpros_service_client.hpp"

// A request written byte by byte, to send what no well-formed client would.
struct RawRequest {
  std::vector<std::uint8_t> bytes;
};

namespace ros::serialization {
template <>
struct Serializer<RawRequest> {
  template <typename Stream>
  static void write(Stream& stream, const RawRequest& request) {
    std::memcpy(stream.advance(std::uint32_t(request.bytes.size())), request.bytes.data(), request.bytes.size());
  }
  static std::uint32_t serializedLength(const RawRequest& request) { return std::uint32_t(request.bytes.size()); }
};
}  // namespace ros::serialization

namespace {

constexpr int kSampledStates = 300;
constexpr unsigned kRandomSeed = 20240601;
// Clients that call without pause, each on its own connection, and how long they keep at it at
// least: longer than the server's default synthesizer_timeout_s (3 s), after which statuses it
// did not read would make it report the synthesizer stopped.
constexpr int kBusyClients = 4;
constexpr double kBusySeconds = 4.0;
constexpr std::size_t kAnswersPerBusyClient = 100;
// Decoding the oversized request would allocate 4 GiB; the server may grow by far less than that.
constexpr long kOversizedGrowthLimitKiB = 512L * 1024;

// The peak virtual memory of a process (VmPeak in /proc/<pid>/status), in KiB; -1 if unreadable.
long peak_memory_kib(int pid) {
  std::ifstream status("/proc/" + std::to_string(pid) + "/status");
  for (std::string line; std::getline(status, line);)
    if (line.rfind("VmPeak:", 0) == 0) return std::stol(line.substr(7));
  return -1;
}

class ServiceTest : public ::testing::Test {
 protected:
  void SetUp() override {
    ASSERT_TRUE(ros::service::waitForService("/amytiss/get_input", ros::Duration(amytiss_test::kServiceWaitSeconds)));
    // One persistent connection (see rostest_fixture.hpp).
    client_ = handle_.serviceClient<amytiss::GetInput>("/amytiss/get_input", /*persistent=*/true);
    ASSERT_TRUE(status_.wait_for([](const amytiss::PolicyStatus& s) { return s.ready; },
                                 amytiss_test::kPolicyWaitSeconds))
        << "no ready policy; last status: " << status_.latest().message;
    policy_file_ = status_.latest().policy_file;
    loaded_ = amytiss::read_policy_file(policy_file_);
    // The server loads the file after the status arrives: wait until it answers.
    ASSERT_TRUE(amytiss_test::poll_until([&] { return call({-4.0, -4.0}, 0).success; }, amytiss_test::kPolicyWaitSeconds));
  }
  // The policy file is this run's own (service.test names it with $(anon ...)): removed at the end.
  static void TearDownTestSuite() { std::remove(policy_file_.c_str()); }
  amytiss::GetInput::Response call(const std::vector<double>& state, unsigned step) {
    amytiss::GetInput service;
    service.request.state = state;
    service.request.time_step = step;
    EXPECT_TRUE(client_.call(service)) << "the service call itself failed";
    return service.response;
  }

  ros::NodeHandle handle_;
  amytiss_test::StatusWatcher status_{handle_};
  ros::ServiceClient client_;
  amytiss::LoadedPolicy loaded_;
  static std::string policy_file_;
};

std::string ServiceTest::policy_file_;

TEST_F(ServiceTest, AnswersEqualTheCorePolicyForSampledStates) {
  const amytiss::Policy& policy = loaded_.policy;
  // service.test keeps the default guarantee (exact values of the abstract model: one number per
  // cell and step), service_system.test asks for continuous-system bounds (two).
  const std::string guarantee = amytiss::to_string(policy.guarantee);
  std::string expected_guarantee;
  ASSERT_TRUE(ros::NodeHandle("~").getParam("expected_guarantee", expected_guarantee));
  ASSERT_EQ(guarantee, expected_guarantee);
  bool any_gap = false;
  EXPECT_EQ(status_.latest().guarantee, guarantee);
  std::mt19937 random(kRandomSeed);
  std::vector<double> expected_input(policy.inputs.dims());
  for (int sample = 0; sample < kSampledStates; ++sample) {
    std::vector<double> state(policy.states.dims());
    for (std::size_t d = 0; d < state.size(); ++d) {
      const double low = policy.states.lb()[d] - 0.49 * policy.states.eta()[d];
      const double high = policy.states.last_point()[d] + 0.49 * policy.states.eta()[d];
      state[d] = std::uniform_real_distribution<double>(low, high)(random);
    }
    const unsigned step = std::uniform_int_distribution<unsigned>(0, policy.horizon - 1)(random);
    double expected_probability = -1, expected_upper = -1;
    ASSERT_EQ(policy.lookup(state.data(), state.size(), step, expected_input.data(), &expected_probability,
                            &expected_upper),
              amytiss::LookupStatus::Ok);
    const amytiss::GetInput::Response response = call(state, step);
    ASSERT_TRUE(response.success) << response.message;
    EXPECT_EQ(response.input, expected_input);
    EXPECT_EQ(response.probability, expected_probability);
    EXPECT_EQ(response.probability_upper, expected_upper);
    EXPECT_LE(response.probability, response.probability_upper);
    EXPECT_EQ(response.guarantee, guarantee);
    any_gap = any_gap || response.probability_upper > response.probability;
  }
  // Bounds of the continuous system are apart somewhere; the abstraction's are one number.
  EXPECT_EQ(any_gap, policy.guarantee == amytiss::Guarantee::System);
}

TEST_F(ServiceTest, EveryMalformedRequestIsAnsweredWithAMessageAndTheServerStaysUp) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  const unsigned horizon = loaded_.policy.horizon;
  const struct {
    std::vector<double> state;
    unsigned step;
    const char* expected_word;
  } cases[] = {{{}, 0, "expected 2"},          {{1.0}, 0, "expected 2"},      {{1.0, 2.0, 3.0}, 0, "expected 2"},
               {{nan, 0.0}, 0, "finite"},      {{0.0, inf}, 0, "finite"},     {{-inf, 0.0}, 0, "finite"},
               {{40.0, 0.0}, 0, "outside"},    {{0.0, -5.26}, 0, "outside"},  {{0.0, 0.0}, horizon, "horizon"},
               {{0.0, 0.0}, 4000000000u, "horizon"}};
  for (const auto& c : cases) {
    const amytiss::GetInput::Response response = call(c.state, c.step);
    EXPECT_FALSE(response.success);
    EXPECT_TRUE(response.input.empty());
    EXPECT_NE(response.message.find(c.expected_word), std::string::npos) << response.message;
  }
  EXPECT_TRUE(client_.exists());
  EXPECT_TRUE(call({-4.0, -4.0}, 0).success);
}

TEST_F(ServiceTest, ARequestClaimingMoreStateValuesThanItCarriesIsAnsweredWithoutTheAllocation) {
  const int server = amytiss_ros::node_pid("/amytiss/policy_server");
  ASSERT_GT(server, 0);
  const long peak_before = peak_memory_kib(server);
  ASSERT_GT(peak_before, 0);
  // 16 bytes: a state length of 2^29 (4 GiB of doubles if decoded), 8 bytes, a time step.
  RawRequest oversized{std::vector<std::uint8_t>(16, 0)};
  const std::uint32_t claimed = 1u << 29;
  std::memcpy(oversized.bytes.data(), &claimed, sizeof claimed);
  ros::ServiceClient raw_client = handle_.serviceClient<amytiss::GetInput>("/amytiss/get_input");
  amytiss::GetInput::Response response;
  ASSERT_TRUE(raw_client.call(oversized, response, ros::service_traits::md5sum<amytiss::GetInput>()))
      << "the server must answer, not fail the call";
  EXPECT_FALSE(response.success);
  EXPECT_NE(response.message.find("claims 536870912 values"), std::string::npos) << response.message;
  EXPECT_LT(peak_memory_kib(server) - peak_before, kOversizedGrowthLimitKiB);
  EXPECT_TRUE(call({-4.0, -4.0}, 0).success) << "the server stays up";
}

TEST_F(ServiceTest, TheLoadTestsTcprosClientGetsWhatRoscppsClientGets) {
  amytiss_tools::TcprosServiceClient tcpros("/amytiss/get_input",
                                            amytiss_tools::service_md5sum<amytiss::GetInput>());
  const amytiss::Policy& policy = loaded_.policy;
  std::mt19937 random(kRandomSeed);
  for (int sample = 0; sample < kSampledStates; ++sample) {
    amytiss::GetInput service;
    service.request.state.resize(policy.states.dims());
    for (std::size_t d = 0; d < policy.states.dims(); ++d)
      service.request.state[d] = std::uniform_real_distribution<double>(
          policy.states.lb()[d] - 0.49 * policy.states.eta()[d],
          policy.states.last_point()[d] + 0.49 * policy.states.eta()[d])(random);
    service.request.time_step = std::uniform_int_distribution<unsigned>(0, policy.horizon - 1)(random);
    ASSERT_TRUE(tcpros.call(service)) << tcpros.error();
    const amytiss::GetInput::Response expected = call(service.request.state, service.request.time_step);
    ASSERT_TRUE(service.response.success) << service.response.message;
    EXPECT_EQ(service.response.input, expected.input);
    EXPECT_EQ(service.response.probability, expected.probability);
    EXPECT_EQ(service.response.probability_upper, expected.probability_upper);
  }
  // A malformed request is answered (success false, with the reason) on the same connection.
  amytiss::GetInput malformed;
  malformed.request.state = {1.0};
  ASSERT_TRUE(tcpros.call(malformed)) << tcpros.error();
  EXPECT_FALSE(malformed.response.success);
  EXPECT_NE(malformed.response.message.find("expected 2"), std::string::npos) << malformed.response.message;
  // What cannot connect says why.
  try {
    amytiss_tools::TcprosServiceClient("/amytiss/no_such_service", amytiss_tools::service_md5sum<amytiss::GetInput>());
    ADD_FAILURE() << "connected to a service that does not exist";
  } catch (const std::runtime_error& error) {
    EXPECT_NE(std::string(error.what()).find("knows no service"), std::string::npos) << error.what();
  }
  try {
    amytiss_tools::TcprosServiceClient("/amytiss/get_input", "0123456789abcdef0123456789abcdef");
    ADD_FAILURE() << "the server accepted a client of another service type";
  } catch (const std::runtime_error& error) {
    EXPECT_NE(std::string(error.what()).find("refused"), std::string::npos) << error.what();
  }
}

TEST_F(ServiceTest, StatesOnTheTopicAreAnsweredOnTheCommandTopic) {
  std::mutex mutex;
  std::condition_variable arrived;
  std::vector<amytiss::InputCommand> commands;
  ros::Subscriber subscriber = handle_.subscribe<amytiss::InputCommand>(
      "/amytiss/command", 10, [&](const amytiss::InputCommand::ConstPtr& command) {
        std::lock_guard<std::mutex> lock(mutex);
        commands.push_back(*command);
        arrived.notify_all();
      });
  ros::Publisher publisher = handle_.advertise<amytiss::StateStamped>("/amytiss/state", 10);
  ASSERT_TRUE(amytiss_test::poll_until(
      [&] { return publisher.getNumSubscribers() > 0 && subscriber.getNumPublishers() > 0; },
      amytiss_test::kServiceWaitSeconds));
  amytiss::StateStamped good, bad;
  good.header.stamp = ros::Time(100, 1);
  good.state = {-4.0, -4.0};
  good.time_step = 2;
  bad.header.stamp = ros::Time(100, 2);
  bad.state = {-4.0, std::numeric_limits<double>::quiet_NaN()};
  bad.time_step = 2;
  publisher.publish(good);
  publisher.publish(bad);
  std::unique_lock<std::mutex> lock(mutex);
  ASSERT_TRUE(arrived.wait_for(lock, std::chrono::seconds(10), [&] { return commands.size() >= 2; }));
  std::vector<double> expected(loaded_.policy.inputs.dims());
  double probability = -1;
  ASSERT_EQ(loaded_.policy.lookup(good.state.data(), 2, 2, expected.data(), &probability), amytiss::LookupStatus::Ok);
  EXPECT_EQ(commands[0].header.stamp, good.header.stamp);
  EXPECT_TRUE(commands[0].valid);
  EXPECT_EQ(commands[0].time_step, 2u);
  EXPECT_EQ(commands[0].input, expected);
  EXPECT_EQ(commands[0].probability, probability);
  EXPECT_EQ(commands[1].header.stamp, bad.header.stamp);
  EXPECT_FALSE(commands[1].valid);
  EXPECT_TRUE(commands[1].input.empty());
  EXPECT_NE(commands[1].message.find("finite"), std::string::npos) << commands[1].message;
}

TEST_F(ServiceTest, UnderCallsWithoutPauseEveryClientIsAnsweredAndStatesTimersAndStatusesAreServed) {
  std::atomic<bool> stop{false};
  std::array<std::atomic<std::size_t>, kBusyClients> answers{}, failures{};
  std::vector<std::thread> clients;
  for (int c = 0; c < kBusyClients; ++c)
    clients.emplace_back([&, c] {
      ros::ServiceClient client = handle_.serviceClient<amytiss::GetInput>("/amytiss/get_input", /*persistent=*/true);
      amytiss::GetInput service;
      service.request.state = {-4.0, -4.0};
      while (!stop) {
        if (client.call(service) && service.response.success)
          ++answers[c];
        else
          ++failures[c];
      }
    });
  std::mutex mutex;
  std::size_t commands = 0;
  std::string network_thread_calls;  // the server's diagnostics value, as published
  ros::Subscriber command_subscriber = handle_.subscribe<amytiss::InputCommand>(
      "/amytiss/command", 10, [&](const amytiss::InputCommand::ConstPtr& command) {
        std::lock_guard<std::mutex> lock(mutex);
        commands += command->valid ? 1 : 0;
      });
  ros::Subscriber diagnostics_subscriber = handle_.subscribe<diagnostic_msgs::DiagnosticArray>(
      "/diagnostics", 10, [&](const diagnostic_msgs::DiagnosticArray::ConstPtr& array) {
        std::lock_guard<std::mutex> lock(mutex);
        for (const auto& status : array->status)
          for (const auto& pair : status.values)
            if (pair.key == "get_input calls answered on the network thread") network_thread_calls = pair.value;
      });
  ros::Publisher state_publisher = handle_.advertise<amytiss::StateStamped>("/amytiss/state", 10);
  amytiss::StateStamped state;
  state.state = {-4.0, -4.0};
  const ros::WallTime busy_until = ros::WallTime::now() + ros::WallDuration(kBusySeconds);
  const bool served = amytiss_test::poll_until(
      [&] {
        state_publisher.publish(state);
        std::lock_guard<std::mutex> lock(mutex);
        const bool every_client_answered = std::all_of(
            answers.begin(), answers.end(), [](const auto& count) { return count >= kAnswersPerBusyClient; });
        return ros::WallTime::now() > busy_until && every_client_answered && commands > 0 &&
               !network_thread_calls.empty() && network_thread_calls != "0";
      },
      kBusySeconds + amytiss_test::kServiceWaitSeconds);
  // While the others still call: the answer carries no notice (the statuses kept arriving).
  const amytiss::GetInput::Response during = call({-4.0, -4.0}, 0);
  stop = true;
  for (auto& client : clients) client.join();
  std::lock_guard<std::mutex> lock(mutex);
  EXPECT_TRUE(served) << "commands " << commands << ", network-thread calls '" << network_thread_calls << "'";
  for (int c = 0; c < kBusyClients; ++c) {
    EXPECT_GE(answers[c].load(), kAnswersPerBusyClient) << "client " << c;
    EXPECT_EQ(failures[c].load(), 0u) << "client " << c;
  }
  EXPECT_TRUE(during.success);
  EXPECT_EQ(during.message, "");
}

}  // namespace

int main(int argc, char** argv) { return amytiss_test::run_rostests(argc, argv, "amytiss_service_test", 2); }
