#include "tcpros_service_client.hpp"

#include <netdb.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include <boost/shared_array.hpp>
#include <ros/header.h>
#include <ros/service_manager.h>
#include <ros/this_node.h>

namespace amytiss_tools {

namespace {

int connect_to(const std::string& host, std::uint32_t port) {
  addrinfo hints{};
  hints.ai_family = AF_UNSPEC;
  hints.ai_socktype = SOCK_STREAM;
  addrinfo* found = nullptr;
  const int resolved = getaddrinfo(host.c_str(), std::to_string(port).c_str(), &hints, &found);
  if (resolved != 0) throw std::runtime_error("cannot resolve " + host + ": " + gai_strerror(resolved));
  int socket_fd = -1;
  for (addrinfo* address = found; address && socket_fd < 0; address = address->ai_next) {
    socket_fd = socket(address->ai_family, address->ai_socktype, address->ai_protocol);
    if (socket_fd >= 0 && connect(socket_fd, address->ai_addr, address->ai_addrlen) != 0) {
      close(socket_fd);
      socket_fd = -1;
    }
  }
  freeaddrinfo(found);
  if (socket_fd < 0)
    throw std::runtime_error("cannot connect to " + host + ":" + std::to_string(port) + ": " + std::strerror(errno));
  // A call is one small write: send it at once.
  const int one = 1;
  setsockopt(socket_fd, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);
  return socket_fd;
}

}  // namespace

TcprosServiceClient::TcprosServiceClient(const std::string& service, const std::string& md5sum) {
  std::string host;
  std::uint32_t port = 0;
  if (!ros::ServiceManager::instance()->lookupService(service, host, port))
    throw std::runtime_error("the master knows no service " + service);
  socket_ = connect_to(host, port);
  // The connection header: 4-byte length, then length-prefixed key=value fields (ros::Header).
  const ros::M_string fields{
      {"callerid", ros::this_node::getName()}, {"service", service}, {"md5sum", md5sum}, {"persistent", "1"}};
  boost::shared_array<std::uint8_t> header;
  std::uint32_t header_size = 0;
  ros::Header::write(fields, header, header_size);
  std::uint8_t length[4];
  std::memcpy(length, &header_size, 4);  // TCPROS is little-endian, as is this host
  std::uint32_t reply_size = 0;
  if (!write_all(length, 4) || !write_all(header.get(), header_size) ||
      !read_all(reinterpret_cast<std::uint8_t*>(&reply_size), 4))
    throw std::runtime_error("connection header to " + service + ": " + error_);
  std::vector<std::uint8_t> reply(reply_size);
  ros::Header parsed;
  std::string why, refused;
  if (!read_all(reply.data(), reply.size()) || !parsed.parse(reply.data(), reply_size, why))
    throw std::runtime_error("connection header from " + service + ": " + (why.empty() ? error_ : why));
  if (parsed.getValue("error", refused)) throw std::runtime_error(service + " refused the connection: " + refused);
}

TcprosServiceClient::~TcprosServiceClient() {
  if (socket_ >= 0) close(socket_);
}

bool TcprosServiceClient::exchange() {
  if (!write_all(request_.data(), request_.size())) return false;
  // The answer: one byte ok, the length, then the response (or, not ok, the error text).
  std::uint8_t head[5];
  if (!read_all(head, sizeof head)) return false;
  std::uint32_t length = 0;
  std::memcpy(&length, head + 1, 4);
  answer_.resize(length);
  if (!read_all(answer_.data(), length)) return false;
  if (head[0] == 1) return true;
  error_.assign(answer_.begin(), answer_.end());
  return false;
}

bool TcprosServiceClient::write_all(const std::uint8_t* data, std::size_t size) {
  while (size > 0) {
    const ssize_t sent = send(socket_, data, size, MSG_NOSIGNAL);
    if (sent < 0 && errno == EINTR) continue;
    if (sent <= 0) {
      error_ = std::string("send: ") + std::strerror(errno);
      return false;
    }
    data += sent;
    size -= std::size_t(sent);
  }
  return true;
}

bool TcprosServiceClient::read_all(std::uint8_t* data, std::size_t size) {
  while (size > 0) {
    const ssize_t received = recv(socket_, data, size, 0);
    if (received < 0 && errno == EINTR) continue;
    if (received <= 0) {
      error_ = received == 0 ? "the server closed the connection" : std::string("recv: ") + std::strerror(errno);
      return false;
    }
    data += received;
    size -= std::size_t(received);
  }
  return true;
}

}  // namespace amytiss_tools
