// Load test of /amytiss/get_input: N threads x M calls with random valid states (uniform over
// the served policy's grid, random time step below the horizon); prints calls/s, latency
// percentiles and failures. Run by scripts/bench_service, which starts the nodes.
//   bench_service THREADS CALLS_PER_THREAD [SEED]
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include <amytiss/GetInput.h>
#include <amytiss/PolicyStatus.h>
#include <ros/ros.h>
#include <ros/topic.h>

#include "amytiss/policy_file.hpp"

namespace {

constexpr double kReadyWaitSeconds = 600.0;  // the synthesis of the benchmark's configuration
constexpr double kAnswerPollSeconds = 0.05;

struct ThreadResult {
  std::vector<double> latencies_us;
  std::size_t failures = 0;
};

// One client thread on its own persistent connection.
ThreadResult run_client(const amytiss::Policy& policy, std::size_t calls, unsigned seed) {
  ros::NodeHandle handle;
  ros::ServiceClient client = handle.serviceClient<amytiss::GetInput>("/amytiss/get_input", true);
  std::mt19937_64 random(seed);
  std::vector<std::uniform_real_distribution<double>> coordinates;
  for (std::size_t dim = 0; dim < policy.states.dims(); ++dim) {
    const double half = policy.states.eta()[dim] / 2;
    // Strictly inside the outermost cells, so every state is valid.
    coordinates.emplace_back(policy.states.lb()[dim] - half * 0.99,
                             policy.states.lb()[dim] + (policy.states.count(dim) - 1) * policy.states.eta()[dim] +
                                 half * 0.99);
  }
  std::uniform_int_distribution<unsigned> steps(0, policy.horizon - 1);
  ThreadResult result;
  result.latencies_us.reserve(calls);
  amytiss::GetInput service;
  service.request.state.resize(policy.states.dims());
  for (std::size_t call = 0; call < calls; ++call) {
    for (std::size_t dim = 0; dim < coordinates.size(); ++dim) service.request.state[dim] = coordinates[dim](random);
    service.request.time_step = steps(random);
    const auto start = std::chrono::steady_clock::now();
    const bool called = client.call(service);
    const auto end = std::chrono::steady_clock::now();
    result.latencies_us.push_back(std::chrono::duration<double, std::micro>(end - start).count());
    if (!called || !service.response.success) {
      ++result.failures;
      if (!called) client = handle.serviceClient<amytiss::GetInput>("/amytiss/get_input", true);
    }
  }
  return result;
}

// Whether the server answers a valid state (the first cell at step 0) with success before
// `deadline`, asking every kAnswerPollSeconds.
bool server_answers(ros::NodeHandle& handle, const amytiss::Policy& policy, const ros::WallTime& deadline) {
  ros::ServiceClient client = handle.serviceClient<amytiss::GetInput>("/amytiss/get_input");
  amytiss::GetInput service;
  service.request.state = policy.states.point(0);
  service.request.time_step = 0;
  while (ros::ok() && ros::WallTime::now() < deadline) {
    if (client.call(service) && service.response.success) return true;
    ros::WallDuration(kAnswerPollSeconds).sleep();
  }
  return false;
}

double percentile(const std::vector<double>& sorted, double fraction) {
  const std::size_t index = std::min(sorted.size() - 1, std::size_t(fraction * double(sorted.size())));
  return sorted[index];
}

}  // namespace

int main(int argc, char** argv) {
  ros::init(argc, argv, "amytiss_bench_service", ros::init_options::AnonymousName);
  if (argc < 3) {
    std::fprintf(stderr, "usage: bench_service THREADS CALLS_PER_THREAD [SEED]\n");
    return 2;
  }
  const std::size_t threads = std::stoul(argv[1]), calls = std::stoul(argv[2]);
  const unsigned seed = argc > 3 ? unsigned(std::stoul(argv[3])) : 1u;
  ros::NodeHandle handle;
  // The first status may come before the synthesis ends: wait for a ready one.
  const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(kReadyWaitSeconds);
  amytiss::PolicyStatus::ConstPtr status;
  while ((!status || !status->ready) && ros::ok() && ros::WallTime::now() < deadline)
    status = ros::topic::waitForMessage<amytiss::PolicyStatus>("/amytiss/status", handle, ros::Duration(1.0));
  if (!status || !status->ready) {
    std::fprintf(stderr, "no ready policy on /amytiss/status within %.0f s\n", kReadyWaitSeconds);
    return 1;
  }
  if (!ros::service::waitForService("/amytiss/get_input", ros::Duration(60.0))) {
    std::fprintf(stderr, "no /amytiss/get_input service\n");
    return 1;
  }
  const amytiss::Policy policy = amytiss::read_policy_file(status->policy_file).policy;
  // The server loads the file after the status arrives: time only the calls it can answer.
  if (!server_answers(handle, policy, deadline)) {
    std::fprintf(stderr, "/amytiss/get_input answered no valid state before the deadline\n");
    return 1;
  }

  std::vector<ThreadResult> results(threads);
  std::vector<std::thread> workers;
  const auto start = std::chrono::steady_clock::now();
  for (std::size_t t = 0; t < threads; ++t)
    workers.emplace_back([&, t] { results[t] = run_client(policy, calls, seed + unsigned(t)); });
  for (auto& worker : workers) worker.join();
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

  std::vector<double> latencies;
  std::size_t failures = 0;
  for (const auto& result : results) {
    latencies.insert(latencies.end(), result.latencies_us.begin(), result.latencies_us.end());
    failures += result.failures;
  }
  std::sort(latencies.begin(), latencies.end());
  std::printf("policy '%s' (hash %s, %zu cells, horizon %u)\n", status->config_name.c_str(),
              status->config_hash.c_str(), policy.states.size(), policy.horizon);
  std::printf("%zu threads x %zu calls = %zu calls in %.2f s: %.0f calls/s\n", threads, calls, latencies.size(),
              seconds, double(latencies.size()) / seconds);
  std::printf("latency us: p50 %.0f, p99 %.0f, max %.0f\n", percentile(latencies, 0.50), percentile(latencies, 0.99),
              latencies.back());
  std::printf("failures: %zu\n", failures);
  return failures == 0 ? 0 : 1;
}
