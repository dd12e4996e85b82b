#pragma once

// The health monitor's text helpers (health.cpp, health_pose_inputs.cpp).
#include <cstdio>
#include <string>

#include "status.hpp"

namespace trajroi::daemon {

template <typename... Args>
std::string sprintf_text(const char* pattern, Args... args) {
  char text[640];
  std::snprintf(text, sizeof text, pattern, args...);
  return text;
}

// The first senders of the LiDAR port's datagrams that were not VLP-16 packets:
// "from 127.0.0.1:40000, 10.0.0.7:2368 and others".
[[nodiscard]] std::string sender_list(const StatusSnapshot& s);

}  // namespace trajroi::daemon
