// Load test of /amytiss/get_input: N threads x M calls with random valid states (uniform over
// the served policy's grid, random time step below the horizon), each thread on its own
// persistent connection, opened before the clock starts; prints calls/s, latency percentiles,
// failures, when the threads finished (a thread served late finishes late), and the CPU time per
// call of this client and of the server (when it runs on this machine). Run by
// scripts/bench_service, which starts the nodes.
//   bench_service THREADS CALLS_PER_THREAD [SEED]
#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <mutex>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include <amytiss/GetInput.h>
#include <amytiss/PolicyStatus.h>
#include <ros/ros.h>
#include <ros/topic.h>

#include "amytiss/policy_file.hpp"
#include "node_process.hpp"

namespace {

constexpr double kReadyWaitSeconds = 600.0;  // the synthesis of the benchmark's configuration
constexpr double kAnswerPollSeconds = 0.05;
const char* const kServerNode = "/amytiss/policy_server";

struct ThreadResult {
  std::vector<double> latencies_us;
  std::size_t failures = 0;
  double finished_s = 0;  // since the common start
};

/// Lets the client threads start calling together, once every connection is open.
class StartGate {
 public:
  void open() {
    std::lock_guard<std::mutex> lock(mutex_);
    open_ = true;
    opened_.notify_all();
  }
  void wait() {
    std::unique_lock<std::mutex> lock(mutex_);
    opened_.wait(lock, [this] { return open_; });
  }

 private:
  std::mutex mutex_;
  std::condition_variable opened_;
  bool open_ = false;
};

double cpu_seconds_of_this_process() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return double(usage.ru_utime.tv_sec + usage.ru_stime.tv_sec) +
         1e-6 * double(usage.ru_utime.tv_usec + usage.ru_stime.tv_usec);
}

// One client thread on `client`, a persistent connection that has answered once already.
ThreadResult run_client(ros::ServiceClient& client, const amytiss::Policy& policy, std::size_t calls, unsigned seed,
                        StartGate& gate, const std::chrono::steady_clock::time_point& common_start) {
  ros::NodeHandle handle;
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
  gate.wait();
  for (std::size_t call = 0; call < calls; ++call) {
    for (std::size_t dim = 0; dim < coordinates.size(); ++dim) service.request.state[dim] = coordinates[dim](random);
    service.request.time_step = steps(random);
    const auto sent = std::chrono::steady_clock::now();
    const bool called = client.call(service);
    const auto answered = std::chrono::steady_clock::now();
    result.latencies_us.push_back(std::chrono::duration<double, std::micro>(answered - sent).count());
    if (!called || !service.response.success) {
      ++result.failures;
      if (!called) client = handle.serviceClient<amytiss::GetInput>("/amytiss/get_input", true);
    }
  }
  result.finished_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - common_start).count();
  return result;
}

// A valid request: the first cell's centre at step 0.
amytiss::GetInput first_cell_call(const amytiss::Policy& policy) {
  amytiss::GetInput service;
  service.request.state = policy.states.point(0);
  service.request.time_step = 0;
  return service;
}

// Whether the server answers first_cell_call() with success before `deadline`, asking every
// kAnswerPollSeconds.
bool server_answers(ros::NodeHandle& handle, const amytiss::Policy& policy, const ros::WallTime& deadline) {
  ros::ServiceClient client = handle.serviceClient<amytiss::GetInput>("/amytiss/get_input");
  amytiss::GetInput service = first_cell_call(policy);
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

  // The connections are opened (one answered call each) before the clock starts.
  std::vector<ros::ServiceClient> clients;
  for (std::size_t t = 0; t < threads; ++t) {
    clients.push_back(handle.serviceClient<amytiss::GetInput>("/amytiss/get_input", true));
    amytiss::GetInput service = first_cell_call(policy);
    if (!clients.back().call(service) || !service.response.success) {
      std::fprintf(stderr, "the first call on a new persistent connection failed\n");
      return 1;
    }
  }
  const int server_pid = amytiss_ros::node_pid(kServerNode);
  std::vector<ThreadResult> results(threads);
  std::vector<std::thread> workers;
  StartGate gate;
  std::chrono::steady_clock::time_point start;
  for (std::size_t t = 0; t < threads; ++t)
    workers.emplace_back(
        [&, t] { results[t] = run_client(clients[t], policy, calls, seed + unsigned(t), gate, start); });
  const double client_cpu_before = cpu_seconds_of_this_process();
  const double server_cpu_before = amytiss_ros::process_cpu_seconds(server_pid);
  start = std::chrono::steady_clock::now();
  gate.open();
  for (auto& worker : workers) worker.join();
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const double client_cpu = cpu_seconds_of_this_process() - client_cpu_before;
  const double server_cpu = amytiss_ros::process_cpu_seconds(server_pid) - server_cpu_before;

  std::vector<double> latencies;
  std::size_t failures = 0;
  double first_done_s = seconds;
  for (const auto& result : results) {
    latencies.insert(latencies.end(), result.latencies_us.begin(), result.latencies_us.end());
    failures += result.failures;
    first_done_s = std::min(first_done_s, result.finished_s);
  }
  std::sort(latencies.begin(), latencies.end());
  std::printf("policy '%s' (hash %s, %zu cells, horizon %u)\n", status->config_name.c_str(),
              status->config_hash.c_str(), policy.states.size(), policy.horizon);
  std::printf("%zu threads x %zu calls = %zu calls in %.2f s: %.0f calls/s\n", threads, calls, latencies.size(),
              seconds, double(latencies.size()) / seconds);
  std::printf("latency us: p50 %.0f, p99 %.0f, p99.9 %.0f, max %.0f\n", percentile(latencies, 0.50),
              percentile(latencies, 0.99), percentile(latencies, 0.999), latencies.back());
  std::printf("failures: %zu\n", failures);
  std::printf("threads finished between %.2f s and %.2f s\n", first_done_s, seconds);
  const double calls_done = double(latencies.size());
  std::printf("CPU per call: client %.0f us", 1e6 * client_cpu / calls_done);
  if (server_pid > 0 && server_cpu >= 0)
    std::printf(", server %.0f us (pid %d)\n", 1e6 * server_cpu / calls_done, server_pid);
  else
    std::printf(", server not on this machine\n");
  return failures == 0 ? 0 : 1;
}
