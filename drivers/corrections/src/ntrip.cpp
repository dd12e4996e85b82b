#include "trajroi/corrections/ntrip.hpp"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <stdexcept>

#include "trajroi/text/base64.hpp"

namespace trajroi::corrections {
namespace {

bool starts_with_nocase(std::string_view s, std::string_view prefix) noexcept {
  return s.size() >= prefix.size() && std::equal(prefix.begin(), prefix.end(), s.begin(), [](char a, char b) {
           return std::tolower(static_cast<unsigned char>(a)) == std::tolower(static_cast<unsigned char>(b));
         });
}

std::vector<std::string_view> split(std::string_view s, char sep) {
  std::vector<std::string_view> out;
  for (;;) {
    const std::size_t at = s.find(sep);
    out.push_back(s.substr(0, at));
    if (at == std::string_view::npos) return out;
    s.remove_prefix(at + 1);
  }
}

double number(std::string_view s) {
  double v = 0.0;
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  return ec == std::errc() && end == s.data() + s.size() ? v : 0.0;
}

// An HTTP status code: exactly three digits (RFC 9110 section 15), else 0.
int status_code(std::string_view s) {
  if (s.size() != 3) return 0;
  int v = 0;
  for (const char c : s) {
    if (c < '0' || c > '9') return 0;
    v = v * 10 + (c - '0');
  }
  return v;
}

}  // namespace

std::string NtripUrl::redacted() const {
  std::string s = "ntrip://";
  if (!user.empty()) s += user + (password.empty() ? "" : ":***") + "@";
  return s + host + ":" + std::to_string(port) + "/" + mountpoint;
}

NtripUrl parse_ntrip_url(std::string_view url) {
  const std::string whole(url);
  const auto bad = [&whole](const std::string& why) { return std::invalid_argument(whole + ": " + why); };
  constexpr std::string_view kScheme = "ntrip://";
  if (!starts_with_nocase(url, kScheme)) throw bad("not an ntrip:// URL (ntrip://user:password@host:port/mountpoint)");
  url.remove_prefix(kScheme.size());
  NtripUrl u;
  if (const std::size_t q = url.find('?'); q != std::string_view::npos) {
    const std::string_view query = url.substr(q + 1);
    url = url.substr(0, q);
    if (query == "version=1") {
      u.version = 1;
    } else if (query != "version=2") {
      throw bad("unknown option '" + std::string(query) + "' (version=1 or version=2)");
    }
  }
  const std::size_t slash = url.find('/');
  if (slash == std::string_view::npos || slash + 1 == url.size())
    throw bad("no mountpoint (ntrip://host:port/MOUNTPOINT)");
  u.mountpoint = std::string(url.substr(slash + 1));
  if (u.mountpoint.find_first_of("/ \t") != std::string::npos) throw bad("mountpoint '" + u.mountpoint + "'");
  std::string_view authority = url.substr(0, slash);
  if (const std::size_t at = authority.rfind('@'); at != std::string_view::npos) {
    const std::string_view credentials = authority.substr(0, at);
    authority.remove_prefix(at + 1);
    const std::size_t colon = credentials.find(':');
    u.user = std::string(credentials.substr(0, colon));
    if (colon != std::string_view::npos) u.password = std::string(credentials.substr(colon + 1));
  }
  const std::size_t colon = authority.rfind(':');
  u.host = std::string(authority.substr(0, colon));
  if (u.host.empty()) throw bad("no host");
  if (colon != std::string_view::npos) {
    const std::string_view port = authority.substr(colon + 1);
    unsigned value = 0;
    const auto [end, ec] = std::from_chars(port.data(), port.data() + port.size(), value);
    if (ec != std::errc() || end != port.data() + port.size() || value == 0 || value > 65535)
      throw bad("port '" + std::string(port) + "'");
    u.port = static_cast<std::uint16_t>(value);
  }
  return u;
}

std::string ntrip_request(const NtripUrl& url, std::string_view user_agent, std::string_view gga) {
  std::string r = "GET /" + url.mountpoint + (url.version == 2 ? " HTTP/1.1\r\n" : " HTTP/1.0\r\n");
  if (url.version == 2) {
    r += "Host: " + url.host + ":" + std::to_string(url.port) + "\r\n";
    r += "Ntrip-Version: Ntrip/2.0\r\n";
  }
  r += "User-Agent: NTRIP " + std::string(user_agent) + "\r\n";
  if (!url.user.empty()) r += "Authorization: Basic " + text::base64(url.user + ":" + url.password) + "\r\n";
  if (url.version == 2) {
    if (!gga.empty()) {
      std::string_view line = gga;
      while (!line.empty() && (line.back() == '\n' || line.back() == '\r'))
        line.remove_suffix(1);
      r += "Ntrip-GGA: " + std::string(line) + "\r\n";
    }
    r += "Connection: close\r\n";
  }
  r += "\r\n";
  if (url.version == 1 && !gga.empty()) r += std::string(gga);
  return r;
}

NtripAnswer parse_ntrip_answer(std::string_view bytes, bool closed) {
  NtripAnswer a;
  const std::size_t line_end = bytes.find("\r\n");
  if (line_end == std::string_view::npos) {
    // No line yet: garbage when it cannot become one.
    const bool could_be =
        bytes.size() < 512 &&
        (starts_with_nocase("ICY ", bytes.substr(0, 4)) || starts_with_nocase("HTTP/", bytes.substr(0, 5)) ||
         starts_with_nocase("SOURCETABLE", bytes.substr(0, 11)) || bytes.size() < 4);
    a.kind = could_be ? NtripAnswer::Kind::kIncomplete : NtripAnswer::Kind::kGarbage;
    return a;
  }
  a.status_line = std::string(bytes.substr(0, line_end));
  const std::string_view line = a.status_line;
  if (starts_with_nocase(line, "ICY 200")) {
    // NTRIP 1.0: the stream follows the status line (some casters add headers and a blank line).
    a.kind = NtripAnswer::Kind::kStream;
    a.status = 200;
    a.head_bytes = line_end + 2;
    if (bytes.substr(a.head_bytes, 2) == "\r\n") a.head_bytes += 2;
    return a;
  }
  const bool sourcetable = starts_with_nocase(line, "SOURCETABLE");
  const bool http = starts_with_nocase(line, "HTTP/1.");
  if (!sourcetable && !http) {
    a.kind = NtripAnswer::Kind::kGarbage;
    return a;
  }
  std::size_t head_end = bytes.find("\r\n\r\n");
  if (head_end == std::string_view::npos) {
    if (!closed) {
      a.kind = bytes.size() > 16384 ? NtripAnswer::Kind::kGarbage : NtripAnswer::Kind::kIncomplete;
      return a;
    }
    head_end = bytes.size() >= 2 ? bytes.size() - 2 : bytes.size();  // the head is all that came
    a.head_bytes = bytes.size();
  } else {
    a.head_bytes = head_end + 4;
  }
  const std::vector<std::string_view> words = split(line, ' ');
  a.status = words.size() > 1 ? status_code(words[1]) : 0;
  bool table_body = sourcetable;
  const std::string_view headers =
      head_end > line_end + 2 ? bytes.substr(line_end + 2, head_end - line_end - 2) : std::string_view();
  for (const std::string_view header : split(headers, '\n')) {
    std::string_view h = header;
    if (!h.empty() && h.back() == '\r') h.remove_suffix(1);
    if (starts_with_nocase(h, "Content-Type:") && h.find("sourcetable") != std::string_view::npos) table_body = true;
    if (starts_with_nocase(h, "Transfer-Encoding:") && h.find("chunked") != std::string_view::npos) a.chunked = true;
  }
  if (a.status == 200) {
    a.kind = table_body ? NtripAnswer::Kind::kSourceTable : NtripAnswer::Kind::kStream;
  } else {
    a.kind = NtripAnswer::Kind::kRefused;
  }
  return a;
}

std::vector<SourceTableStream> parse_source_table(std::string_view body) {
  std::vector<SourceTableStream> out;
  for (std::string_view line : split(body, '\n')) {
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    if (!line.starts_with("STR;")) continue;
    std::vector<std::string_view> f = split(line, ';');
    if (f.size() < 2 || f[1].empty()) continue;
    // RTCM 10410.1 gives 19 fields; some casters (RTKLIB's) send fewer: the missing are empty.
    f.resize(std::max<std::size_t>(f.size(), 12));
    SourceTableStream s;
    s.mountpoint = std::string(f[1]);
    s.identifier = std::string(f[2]);
    s.format = std::string(f[3]);
    s.format_details = std::string(f[4]);
    s.nav_system = std::string(f[6]);
    s.country = std::string(f[8]);
    s.latitude_deg = number(f[9]);
    s.longitude_deg = number(f[10]);
    s.wants_gga = f[11] == "1";
    out.push_back(std::move(s));
  }
  return out;
}

ChunkedDecoder::Status ChunkedDecoder::feed(std::span<const std::uint8_t> in, std::vector<std::uint8_t>& out) {
  const auto fail = [this](std::string why) {
    state_ = State::kError;
    error_ = std::move(why);
    return Status::kError;
  };
  for (std::size_t i = 0; i < in.size();) {
    const auto c = static_cast<char>(in[i]);
    switch (state_) {
      case State::kSize: {
        const int digit = std::isxdigit(static_cast<unsigned char>(c)) == 0 ? -1
                          : std::isdigit(static_cast<unsigned char>(c)) != 0
                              ? c - '0'
                              : std::tolower(static_cast<unsigned char>(c)) - 'a' + 10;
        if (digit >= 0) {
          if (++size_digits_ > 8) return fail("chunk size longer than 8 hex digits");
          remaining_ = remaining_ * 16 + static_cast<std::uint64_t>(digit);
        } else if (size_digits_ > 0 && (c == ';' || c == ' ')) {
          state_ = State::kSizeExtension;
        } else if (size_digits_ > 0 && c == '\r') {
          state_ = State::kSizeLf;
        } else {
          return fail("bad chunk size");
        }
        ++i;
        break;
      }
      case State::kSizeExtension:
        if (c == '\r') state_ = State::kSizeLf;
        ++i;
        break;
      case State::kSizeLf:
        if (c != '\n') return fail("no line feed after the chunk size");
        ++i;
        size_digits_ = 0;
        state_ = remaining_ == 0 ? State::kEnd : State::kData;
        if (state_ == State::kEnd) return Status::kEnd;
        break;
      case State::kData: {
        const std::size_t n = static_cast<std::size_t>(std::min<std::uint64_t>(remaining_, in.size() - i));
        out.insert(out.end(), in.begin() + static_cast<std::ptrdiff_t>(i),
                   in.begin() + static_cast<std::ptrdiff_t>(i + n));
        remaining_ -= n;
        i += n;
        if (remaining_ == 0) state_ = State::kDataCr;
        break;
      }
      case State::kDataCr:
        if (c != '\r') return fail("no CR LF after a chunk's data");
        state_ = State::kDataLf;
        ++i;
        break;
      case State::kDataLf:
        if (c != '\n') return fail("no CR LF after a chunk's data");
        state_ = State::kSize;
        ++i;
        break;
      case State::kEnd:
        return Status::kEnd;
      case State::kError:
        return Status::kError;
    }
  }
  return state_ == State::kEnd ? Status::kEnd : state_ == State::kError ? Status::kError : Status::kOk;
}

}  // namespace trajroi::corrections
