#pragma once
// A ROS service client that speaks TCPROS (the wire protocol of ROS 1 services) on one blocking
// socket: a call is one write of the request and two reads of the answer, in the calling thread.
// roscpp's own client hands every call to its network thread and back (about ten system calls
// and two thread switches a call), which on a machine of few cores takes more CPU than the
// server it measures. For the service load test (bench_service); the messages are roscpp's.
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include <ros/serialization.h>
#include <ros/service_traits.h>

namespace amytiss_tools {

class TcprosServiceClient {
 public:
  /// Connects to `service` (looked up at the ROS master) as a persistent client of a service with
  /// checksum `md5sum`; throws std::runtime_error with the reason (no such service, refused
  /// connection, the server's error in its connection header).
  TcprosServiceClient(const std::string& service, const std::string& md5sum);
  ~TcprosServiceClient();
  TcprosServiceClient(const TcprosServiceClient&) = delete;
  TcprosServiceClient& operator=(const TcprosServiceClient&) = delete;

  /// One call of a service of type Service (the type's md5sum must be the one connected with):
  /// true with service.response filled; false when the server answered "not ok" (its message in
  /// error()) or the connection failed (then every later call fails too).
  template <class Service>
  bool call(Service& service) {
    namespace serialization = ros::serialization;
    const std::uint32_t length = serialization::serializationLength(service.request);
    request_.resize(4 + length);
    serialization::OStream length_stream(request_.data(), 4);
    serialization::serialize(length_stream, length);
    serialization::OStream body(request_.data() + 4, length);
    serialization::serialize(body, service.request);
    if (!exchange()) return false;
    serialization::IStream answer(answer_.data(), std::uint32_t(answer_.size()));
    serialization::deserialize(answer, service.response);
    return true;
  }
  const std::string& error() const { return error_; }

 private:
  // Writes request_, reads the ok byte, the length and the answer into answer_ (or error_).
  bool exchange();
  bool write_all(const std::uint8_t* data, std::size_t size);
  bool read_all(std::uint8_t* data, std::size_t size);
  int socket_ = -1;
  std::vector<std::uint8_t> request_, answer_;
  std::string error_;
};

template <class Service>
std::string service_md5sum() {
  return ros::service_traits::md5sum<Service>();
}

}  // namespace amytiss_tools
