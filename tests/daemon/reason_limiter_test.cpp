// Warnings by reason: a new reason is said at once however many of another are held back; a
// lasting one is summarised once per interval with its count and times.
#include <gtest/gtest.h>
#include <spdlog/sinks/ostream_sink.h>

#include <sstream>

#include "log.hpp"

namespace {

using trajroi::daemon::log::ReasonLimiter;
constexpr std::int64_t kMs = 1'000'000;

struct Captured {
  std::ostringstream text;
  std::shared_ptr<spdlog::logger> previous = spdlog::default_logger();
  Captured() {
    auto logger = std::make_shared<spdlog::logger>("captured", std::make_shared<spdlog::sinks::ostream_sink_mt>(text));
    logger->set_pattern("%v");
    spdlog::set_default_logger(logger);
  }
  ~Captured() { spdlog::set_default_logger(previous); }
  [[nodiscard]] std::vector<std::string> lines() const {
    std::vector<std::string> out;
    std::istringstream in(text.str());
    for (std::string line; std::getline(in, line);)
      out.push_back(line);
    return out;
  }
};

TEST(ReasonLimiter, ANewReasonIsSaidAtOnceAndRepeatsAreSummarisedPerInterval) {
  Captured log;
  ReasonLimiter limiter(5.0);
  // 100 ms apart: "no attitude yet" from 0 s, then from 0.5 s "fix type 0" too.
  for (int i = 0; i < 100; ++i) {
    const std::int64_t now = i * 100 * kMs;
    limiter.warn(1, "sweep " + std::to_string(i) + " withheld: no attitude yet", now);
    if (i >= 5) limiter.warn(2, "sweep " + std::to_string(i) + " withheld: GNSS fix type 0 < minimum 3", now);
    if (i % 10 == 0) limiter.flush(now);
  }
  const auto lines = log.lines();
  ASSERT_GE(lines.size(), 2U);
  EXPECT_EQ(lines[0], "sweep 0 withheld: no attitude yet");
  EXPECT_EQ(lines[1], "sweep 5 withheld: GNSS fix type 0 < minimum 3");  // at 0.5 s, not held behind the other
  // Then each reason once per 5 s, the last one held standing for its count.
  int summaries = 0;
  for (const std::string& l : lines) {
    if (l.find(" like it from ") != std::string::npos || l.find(" times from ") != std::string::npos) ++summaries;
  }
  EXPECT_GE(summaries, 2) << log.text.str();
  EXPECT_LE(lines.size(), 2U + 2U * 2U) << log.text.str();  // 10 s: at most two summaries per reason
  EXPECT_NE(log.text.str().find("sweep 50 withheld: no attitude yet (and 49 like it from "), std::string::npos)
      << log.text.str();
}

TEST(ReasonLimiter, HeldRepeatsAreSaidByFlushWhenNoMoreCome) {
  Captured log;
  ReasonLimiter limiter(1.0);
  limiter.warn(3, "sweep 1 withheld: no GNSS fix yet", 0);
  limiter.warn(3, "sweep 2 withheld: no GNSS fix yet", 100 * kMs);
  limiter.warn(3, "sweep 3 withheld: no GNSS fix yet", 200 * kMs);
  limiter.flush(900 * kMs);  // the interval has not passed
  EXPECT_EQ(log.lines().size(), 1U);
  limiter.flush(1000 * kMs);
  const auto lines = log.lines();
  ASSERT_EQ(lines.size(), 2U) << log.text.str();
  EXPECT_EQ(lines[1].rfind("sweep 3 withheld: no GNSS fix yet (2 times from ", 0), 0U) << lines[1];
  limiter.flush(5000 * kMs);  // nothing held: nothing said
  EXPECT_EQ(log.lines().size(), 2U);
}

}  // namespace
