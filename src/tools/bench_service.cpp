// Load test of /amytiss/get_input: N threads x M calls with random valid states (uniform over
// the served policy's grid, random time step below the horizon), each thread on its own
// persistent connection, opened before the clock starts; prints calls/s, latency percentiles,
// failures, when the threads finished (a thread served late finishes late), and the CPU time per
// call of this client and of the server (when it runs on this machine). Run by
// scripts/bench_service, which starts the nodes.
//   bench_service THREADS CALLS_PER_THREAD [SEED] [CLIENT]
// CLIENT: tcpros (default: one blocking socket per thread, tcpros_service_client.hpp) or roscpp
// (ros::ServiceClient, which hands each call to its network thread and back).
#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <functional>
#include <memory>
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
#include "tcpros_service_client.hpp"

namespace {

constexpr double kReadyWaitSeconds = 600.0;  // the synthesis of the benchmark's configuration
constexpr double kAnswerPollSeconds = 0.05;
const char* const kServerNode = "/amytiss/policy_server";
const char* const kService = "/amytiss/get_input";

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

// Random valid requests: states uniform over the policy's grid, strictly inside its outermost
// cells, time steps below the horizon.
class RequestSource {
 public:
  RequestSource(const amytiss::Policy& policy, unsigned seed) : random_(seed), steps_(0, policy.horizon - 1) {
    for (std::size_t dim = 0; dim < policy.states.dims(); ++dim) {
      if (!policy.states.uniform(dim)) {
        const double low = policy.states.covered_low(dim), high = policy.states.covered_high(dim);
        const double margin = 0.005 * policy.states.eta()[dim];  // eta(): the smallest cell width
        coordinates_.emplace_back(low + margin, high - margin);
        continue;
      }
      const double half = policy.states.eta()[dim] / 2;
      coordinates_.emplace_back(policy.states.lb()[dim] - half * 0.99,
                                policy.states.lb()[dim] + (policy.states.count(dim) - 1) * policy.states.eta()[dim] +
                                    half * 0.99);
    }
  }
  void fill(amytiss::GetInput& service) {
    service.request.state.resize(coordinates_.size());
    for (std::size_t dim = 0; dim < coordinates_.size(); ++dim) service.request.state[dim] = coordinates_[dim](random_);
    service.request.time_step = steps_(random_);
  }

 private:
  std::mt19937_64 random_;
  std::vector<std::uniform_real_distribution<double>> coordinates_;
  std::uniform_int_distribution<unsigned> steps_;
};

// One client thread: `call(service)` on its own connection, which has answered once already.
template <class Call>
ThreadResult run_client(Call call, const amytiss::Policy& policy, std::size_t calls, unsigned seed, StartGate& gate,
                        const std::chrono::steady_clock::time_point& common_start) {
  RequestSource requests(policy, seed);
  ThreadResult result;
  result.latencies_us.reserve(calls);
  amytiss::GetInput service;
  gate.wait();
  for (std::size_t done = 0; done < calls; ++done) {
    requests.fill(service);
    const auto sent = std::chrono::steady_clock::now();
    const bool called = call(service);
    const auto answered = std::chrono::steady_clock::now();
    result.latencies_us.push_back(std::chrono::duration<double, std::micro>(answered - sent).count());
    if (!called || !service.response.success) ++result.failures;
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
  ros::ServiceClient client = handle.serviceClient<amytiss::GetInput>(kService);
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

// The ready policy the server answers from, once it answers (null: none before `deadline`).
amytiss::PolicyStatus::ConstPtr ready_status(ros::NodeHandle& handle, const ros::WallTime& deadline) {
  // The first status may come before the synthesis ends: wait for a ready one.
  amytiss::PolicyStatus::ConstPtr status;
  while ((!status || !status->ready) && ros::ok() && ros::WallTime::now() < deadline)
    status = ros::topic::waitForMessage<amytiss::PolicyStatus>("/amytiss/status", handle, ros::Duration(1.0));
  if (!status || !status->ready) {
    std::fprintf(stderr, "no ready policy on /amytiss/status within %.0f s\n", kReadyWaitSeconds);
    return nullptr;
  }
  if (!ros::service::waitForService("/amytiss/get_input", ros::Duration(60.0))) {
    std::fprintf(stderr, "no /amytiss/get_input service\n");
    return nullptr;
  }
  return status;
}

struct Measurement {
  std::vector<ThreadResult> results;
  double seconds = 0, client_cpu = 0, server_cpu = -1;
};

// One thread per call function (each on its own, already answered connection), started together.
template <class Call>
Measurement measure(std::vector<Call>& calls, const amytiss::Policy& policy, std::size_t calls_per_thread,
                    unsigned seed) {
  const int server_pid = amytiss_ros::node_pid(kServerNode);
  Measurement measured;
  measured.results.resize(calls.size());
  std::vector<std::thread> workers;
  StartGate gate;
  std::chrono::steady_clock::time_point start;
  for (std::size_t t = 0; t < calls.size(); ++t)
    workers.emplace_back([&, t] {
      measured.results[t] = run_client(calls[t], policy, calls_per_thread, seed + unsigned(t), gate, start);
    });
  const double client_cpu_before = cpu_seconds_of_this_process();
  const double server_cpu_before = amytiss_ros::process_cpu_seconds(server_pid);
  start = std::chrono::steady_clock::now();
  gate.open();
  for (auto& worker : workers) worker.join();
  measured.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  measured.client_cpu = cpu_seconds_of_this_process() - client_cpu_before;
  if (server_pid > 0 && server_cpu_before >= 0)
    measured.server_cpu = amytiss_ros::process_cpu_seconds(server_pid) - server_cpu_before;
  return measured;
}

void report(const Measurement& measured, const char* client) {
  std::vector<double> latencies;
  std::size_t failures = 0;
  double first_done_s = measured.seconds;
  for (const auto& result : measured.results) {
    latencies.insert(latencies.end(), result.latencies_us.begin(), result.latencies_us.end());
    failures += result.failures;
    first_done_s = std::min(first_done_s, result.finished_s);
  }
  std::sort(latencies.begin(), latencies.end());
  const double calls = double(latencies.size());
  std::printf("%zu threads (%s clients) x %zu calls = %zu calls in %.2f s: %.0f calls/s\n", measured.results.size(),
              client, latencies.size() / measured.results.size(), latencies.size(), measured.seconds,
              calls / measured.seconds);
  std::printf("latency us: p50 %.0f, p99 %.0f, p99.9 %.0f, max %.0f\n", percentile(latencies, 0.50),
              percentile(latencies, 0.99), percentile(latencies, 0.999), latencies.back());
  std::printf("failures: %zu\n", failures);
  std::printf("threads finished between %.2f s and %.2f s\n", first_done_s, measured.seconds);
  std::printf("CPU per call: client %.0f us", 1e6 * measured.client_cpu / calls);
  if (measured.server_cpu >= 0)
    std::printf(", server %.0f us\n", 1e6 * measured.server_cpu / calls);
  else
    std::printf(", server not on this machine\n");
}

std::size_t failures_of(const Measurement& measured) {
  std::size_t failures = 0;
  for (const auto& result : measured.results) failures += result.failures;
  return failures;
}

// roscpp's persistent clients; a client whose call failed is opened again.
Measurement measure_roscpp(ros::NodeHandle& handle, const amytiss::Policy& policy, std::size_t threads,
                           std::size_t calls, unsigned seed) {
  std::vector<std::function<bool(amytiss::GetInput&)>> callers;
  for (std::size_t t = 0; t < threads; ++t) {
    auto client = std::make_shared<ros::ServiceClient>(handle.serviceClient<amytiss::GetInput>(kService, true));
    amytiss::GetInput service = first_cell_call(policy);
    if (!client->call(service) || !service.response.success)
      throw std::runtime_error("the first call on a new persistent connection failed");
    callers.push_back([client, &handle](amytiss::GetInput& call) {
      const bool called = client->call(call);
      if (!called) *client = handle.serviceClient<amytiss::GetInput>(kService, true);
      return called;
    });
  }
  return measure(callers, policy, calls, seed);
}

Measurement measure_tcpros(const amytiss::Policy& policy, std::size_t threads, std::size_t calls, unsigned seed) {
  std::vector<std::function<bool(amytiss::GetInput&)>> callers;
  for (std::size_t t = 0; t < threads; ++t) {
    auto client = std::make_shared<amytiss_tools::TcprosServiceClient>(
        kService, amytiss_tools::service_md5sum<amytiss::GetInput>());
    amytiss::GetInput service = first_cell_call(policy);
    if (!client->call(service) || !service.response.success)
      throw std::runtime_error("the first call on a new connection failed: " + client->error());
    callers.push_back([client](amytiss::GetInput& call) { return client->call(call); });
  }
  return measure(callers, policy, calls, seed);
}

}  // namespace

int main(int argc, char** argv) {
  ros::init(argc, argv, "amytiss_bench_service", ros::init_options::AnonymousName);
  const std::string client = argc > 4 ? argv[4] : "tcpros";
  if (argc < 3 || (client != "tcpros" && client != "roscpp")) {
    std::fprintf(stderr, "usage: bench_service THREADS CALLS_PER_THREAD [SEED] [tcpros|roscpp]\n");
    return 2;
  }
  const std::size_t threads = std::stoul(argv[1]), calls = std::stoul(argv[2]);
  const unsigned seed = argc > 3 ? unsigned(std::stoul(argv[3])) : 1u;
  ros::NodeHandle handle;
  const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(kReadyWaitSeconds);
  const amytiss::PolicyStatus::ConstPtr status = ready_status(handle, deadline);
  if (!status) return 1;
  const amytiss::Policy policy = amytiss::read_policy_file(status->policy_file).policy;
  // The server loads the file after the status arrives: time only the calls it can answer.
  if (!server_answers(handle, policy, deadline)) {
    std::fprintf(stderr, "%s answered no valid state before the deadline\n", kService);
    return 1;
  }
  try {
    const Measurement measured = client == "roscpp" ? measure_roscpp(handle, policy, threads, calls, seed)
                                                    : measure_tcpros(policy, threads, calls, seed);
    std::printf("policy '%s' (hash %s, %zu cells, horizon %u)\n", status->config_name.c_str(),
                status->config_hash.c_str(), policy.states.size(), policy.horizon);
    report(measured, client.c_str());
    return failures_of(measured) == 0 ? 0 : 1;
  } catch (const std::exception& error) {
    std::fprintf(stderr, "%s\n", error.what());
    return 1;
  }
}
