// trajroi view's parsers of what a browser (or anything) sends: an HTTP request head, then, as
// after an upgrade, WebSocket client frames parsed one after another from the rest. Each input
// is a value or a named error; no input is read past its end.
#include <cstdint>
#include <span>
#include <string_view>

#include "trajroi/view/http.hpp"
#include "trajroi/view/websocket.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  const trajroi::view::HttpParse head = trajroi::view::parse_request(text);
  std::span<const std::uint8_t> rest(data, size);
  if (head.status == trajroi::view::HttpParse::Status::kDone) {
    (void)trajroi::view::websocket_upgrade_problem(head.request);
    if (trajroi::view::websocket_upgrade_problem(head.request).empty())
      (void)trajroi::view::websocket_accept_head(head.request);
    rest = rest.subspan(head.consumed);
  }
  for (int frames = 0; frames < 64 && !rest.empty(); ++frames) {
    const trajroi::view::ClientFrame f = trajroi::view::parse_client_frame(rest, 4096);
    if (f.status != trajroi::view::ClientFrame::Status::kFrame) break;
    if (f.consumed == 0 || f.consumed > rest.size()) __builtin_trap();
    rest = rest.subspan(f.consumed);
  }
  return 0;
}
