// GetInput requests whose state length claims more values than the request carries are refused
// before roscpp decodes them (it would allocate the claimed length first).
#include <cstring>
#include <vector>

#include <gtest/gtest.h>
#include <ros/serialization.h>

#include "checked_get_input.hpp"

namespace {

// The bytes roscpp receives for a request (after the 4-byte frame length).
std::vector<std::uint8_t> serialized(const amytiss::GetInput::Request& request) {
  std::vector<std::uint8_t> bytes(ros::serialization::serializationLength(request));
  ros::serialization::OStream stream(bytes.data(), std::uint32_t(bytes.size()));
  ros::serialization::serialize(stream, request);
  return bytes;
}

TEST(CheckedGetInput, WellFormedRequestsPass) {
  amytiss::GetInput::Request request;
  for (const std::vector<double>& state : {std::vector<double>{}, {1.0}, {1.0, -2.0, 3.5}}) {
    request.state = state;
    const std::vector<std::uint8_t> bytes = serialized(request);
    EXPECT_EQ("", amytiss_ros::oversized_get_input_reason(bytes.data(), bytes.size())) << state.size();
  }
}

TEST(CheckedGetInput, AClaimBeyondTheBytesIsRefused) {
  // 16 bytes claiming 2^29 doubles: 4 GiB if decoded.
  std::vector<std::uint8_t> bytes(16, 0);
  const std::uint32_t claimed = 1u << 29;
  std::memcpy(bytes.data(), &claimed, sizeof claimed);
  const std::string reason = amytiss_ros::oversized_get_input_reason(bytes.data(), bytes.size());
  EXPECT_NE(reason.find("claims 536870912 values"), std::string::npos) << reason;
  EXPECT_NE(reason.find("16 bytes"), std::string::npos) << reason;

  amytiss::GetInput::Request request;
  request.state = {1.0, 2.0};
  std::vector<std::uint8_t> short_by_one = serialized(request);
  short_by_one.pop_back();
  EXPECT_NE("", amytiss_ros::oversized_get_input_reason(short_by_one.data(), short_by_one.size()));
  EXPECT_NE("", amytiss_ros::oversized_get_input_reason(short_by_one.data(), 3));
}

}  // namespace
