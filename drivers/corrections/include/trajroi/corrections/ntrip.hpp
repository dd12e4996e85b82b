#pragma once

// The NTRIP client's protocol (NTRIP 1.0 and 2.0, RTCM 10410.x): the caster's URL, the request
// for a mountpoint (Basic credentials, the rover's GGA for VRS casters), the caster's answer
// (a stream, its source table when the mountpoint is wrong, a refusal with its words), the
// source table's streams, and HTTP/1.1 chunked transfer (NTRIP 2.0 streams). Pure: text and
// bytes in, values out; the socket is the adapter's.
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace trajroi::corrections {

struct NtripUrl {
  std::string user, password;
  std::string host;
  std::uint16_t port = 2101;  // IANA's port for NTRIP
  std::string mountpoint;
  int version = 2;  // ?version=1 for NTRIP 1.0 casters (RTKLIB's str2str, older ones)
  // "ntrip://user:***@host:port/mountpoint": for logs (never the password).
  [[nodiscard]] std::string redacted() const;
};

// ntrip://[user[:password]@]host[:port]/mountpoint[?version=1|2]. Throws std::invalid_argument
// naming what is wrong ("ntrip://caster: no mountpoint (…/MOUNTPOINT)").
[[nodiscard]] NtripUrl parse_ntrip_url(std::string_view url);

// The request for the URL's mountpoint: NTRIP 2.0 as HTTP/1.1 (Host, Ntrip-Version), 1.0 as
// HTTP/1.0; Basic credentials when the URL has a user; `gga` (a whole sentence, "$…\r\n") in an
// Ntrip-GGA header (2.0) or after the request (1.0) when not empty.
[[nodiscard]] std::string ntrip_request(const NtripUrl& url, std::string_view user_agent, std::string_view gga);

struct NtripAnswer {
  enum class Kind : std::uint8_t {
    kIncomplete,   // the head has not all come
    kStream,       // "ICY 200 OK" (1.0) or "HTTP/1.x 200" with a stream: RTCM follows
    kSourceTable,  // "SOURCETABLE 200 OK" or a gnss/sourcetable body: the mountpoint is not there
    kRefused,      // any other status: credentials (401), forbidden, not found …
    kGarbage,      // not an NTRIP or HTTP answer
  };
  Kind kind = Kind::kIncomplete;
  int status = 0;
  std::string status_line;     // as the caster said it
  bool chunked = false;        // Transfer-Encoding: chunked (2.0)
  std::size_t head_bytes = 0;  // the answer's head, to its empty line ("ICY 200 OK\r\n" alone for 1.0)
};

// The caster's answer from the bytes received so far; `closed`: the caster has closed the
// connection, so what came is all there is (RTKLIB's caster answers a refusal with its status
// line alone, then closes).
[[nodiscard]] NtripAnswer parse_ntrip_answer(std::string_view bytes, bool closed = false);

struct SourceTableStream {
  std::string mountpoint, identifier, format, format_details, nav_system, country;
  double latitude_deg = 0.0, longitude_deg = 0.0;
  bool wants_gga = false;  // field 12 "nmea": 1 when the caster needs the rover's position (VRS)
};

// The STR records of a source table body ("STR;mountpoint;identifier;format;…"; fields a
// caster leaves out are empty); other records (CAS, NET) and lines without a mountpoint are
// left out.
[[nodiscard]] std::vector<SourceTableStream> parse_source_table(std::string_view body);

// HTTP/1.1 chunked transfer decoding (RFC 9112 §7.1), resumable across reads.
class ChunkedDecoder {
 public:
  enum class Status : std::uint8_t { kOk, kEnd, kError };
  // Appends the data of the chunks in `in` to `out`.
  Status feed(std::span<const std::uint8_t> in, std::vector<std::uint8_t>& out);
  [[nodiscard]] const std::string& error() const noexcept { return error_; }

 private:
  enum class State : std::uint8_t { kSize, kSizeExtension, kSizeLf, kData, kDataCr, kDataLf, kEnd, kError };
  State state_ = State::kSize;
  std::uint64_t remaining_ = 0;
  int size_digits_ = 0;
  std::string error_;
};

}  // namespace trajroi::corrections
