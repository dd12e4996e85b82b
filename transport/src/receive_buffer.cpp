#include "trajroi/transport/receive_buffer.hpp"

#include <dirent.h>
#include <netinet/in.h>
#include <sys/socket.h>

#include <cstdlib>
#include <string_view>

namespace trajroi::transport {

ReceiveBuffer set_receive_buffer(int fd, int bytes) {
  ReceiveBuffer r;
  r.asked_bytes = bytes;
  r.found = true;
  r.forced = setsockopt(fd, SOL_SOCKET, SO_RCVBUFFORCE, &bytes, sizeof bytes) == 0;
  if (!r.forced) (void)setsockopt(fd, SOL_SOCKET, SO_RCVBUF, &bytes, sizeof bytes);
  int doubled = 0;
  socklen_t length = sizeof doubled;
  if (getsockopt(fd, SOL_SOCKET, SO_RCVBUF, &doubled, &length) == 0) r.granted_bytes = doubled / 2;
  return r;
}

ReceiveBuffer set_udp_receive_buffers(std::uint16_t port, int bytes) {
  ReceiveBuffer result;
  result.asked_bytes = bytes;
  DIR* dir = opendir("/proc/self/fd");
  if (dir == nullptr) return result;
  while (const dirent* entry = readdir(dir)) {
    char* end = nullptr;
    const long fd = std::strtol(entry->d_name, &end, 10);
    if (end == entry->d_name || *end != '\0' || fd == dirfd(dir)) continue;
    int type = 0;
    socklen_t length = sizeof type;
    sockaddr_in local{};
    socklen_t local_length = sizeof local;
    if (getsockopt(static_cast<int>(fd), SOL_SOCKET, SO_TYPE, &type, &length) != 0 || type != SOCK_DGRAM ||
        getsockname(static_cast<int>(fd), reinterpret_cast<sockaddr*>(&local), &local_length) != 0 ||
        local.sin_family != AF_INET || ntohs(local.sin_port) != port) {
      continue;
    }
    const ReceiveBuffer one = set_receive_buffer(static_cast<int>(fd), bytes);
    // The worst of them, if several.
    if (!result.found || one.granted_bytes < result.granted_bytes) result = one;
  }
  closedir(dir);
  return result;
}

bool udpm_receive_options(const std::string& url, int& recv_buf_size, std::uint16_t& port) {
  constexpr std::string_view kScheme = "udpm://";
  recv_buf_size = 0;
  port = 7667;
  if (url.rfind(kScheme, 0) != 0) return false;
  const std::string_view rest = std::string_view(url).substr(kScheme.size());
  const std::size_t query = rest.find('?');
  const std::string_view address = rest.substr(0, query);
  if (const std::size_t colon = address.find(':'); colon != std::string_view::npos) {
    port = static_cast<std::uint16_t>(std::strtoul(std::string(address.substr(colon + 1)).c_str(), nullptr, 10));
  }
  if (query == std::string_view::npos) return true;
  std::string_view options = rest.substr(query + 1);
  while (!options.empty()) {
    const std::size_t amp = options.find('&');
    const std::string_view option = options.substr(0, amp);
    constexpr std::string_view kKey = "recv_buf_size=";
    if (option.rfind(kKey, 0) == 0) recv_buf_size = std::atoi(std::string(option.substr(kKey.size())).c_str());
    if (amp == std::string_view::npos) break;
    options.remove_prefix(amp + 1);
  }
  return true;
}

std::string describe_capped(const std::string& who, const ReceiveBuffer& buffer) {
  if (!buffer.capped()) return {};
  return who + ": the kernel capped the LCM receive buffer at " + std::to_string(buffer.granted_bytes / 1024) +
         " KiB of the " + std::to_string(buffer.asked_bytes / 1024) +
         " KiB asked for (net.core.rmem_max); clouds may be lost when this subscriber falls behind. Run it as root "
         "(SO_RCVBUFFORCE), or raise the limit with the drop-in trajroi ships: sysctl -p "
         "/usr/lib/sysctl.d/60-trajroi-lcm.conf (systemd/60-trajroi-lcm.conf in the source tree)";
}

std::string without_receive_buffer(const std::string& url) {
  const std::size_t at = url.find("recv_buf_size=");
  if (at == std::string::npos) return url;
  const std::size_t end = url.find('&', at);
  std::string out = url.substr(0, at) + (end == std::string::npos ? "" : url.substr(end + 1));
  while (!out.empty() && (out.back() == '&' || out.back() == '?'))
    out.pop_back();
  return out;
}

}  // namespace trajroi::transport
