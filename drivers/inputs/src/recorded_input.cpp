#include "trajroi/inputs/recorded_input.hpp"

#include <algorithm>

#include "trajroi/host/clock.hpp"

namespace trajroi::inputs {

RecordedInput::RecordedInput(std::filesystem::path dir, RecordedOptions options)
    : dir_(std::move(dir)),
      options_(options),
      merger_(std::make_unique<RunMerger>(dir_, options.streams, 0, options.lidar_ports)),
      pacer_(options.rate) {}

RecordedInput::~RecordedInput() = default;

std::string RecordedInput::describe() const {
  return "replay of " + dir_.string();
}

InputCounters RecordedInput::counters() const noexcept {
  InputCounters c;
  c.items = items_;
  c.oversize = oversize_ + merger_->oversize();
  c.errors = error_reported_ ? 1 : 0;
  return c;
}

RecordedInput::Next RecordedInput::next(InputItem& item, std::chrono::milliseconds timeout) {
  if (missing_reported_ < merger_->missing().size()) {
    notice_ = {Notice::Level::kWarning,
               "replay: " + merger_->missing()[missing_reported_++] + " absent: that stream is silent"};
    return Next::kNotice;
  }
  if (!error_reported_ && !merger_->error().empty()) {
    error_reported_ = true;
    error_ = "replay: " + merger_->error();
    return Next::kError;
  }
  std::int64_t t = 0;
  if (!merger_->peek_time(t)) {
    // --loop: the next lap's times follow this one's (plus a gap).
    constexpr std::int64_t kLapGap_ns = 100'000'000;
    if (!options_.loop || merger_->first_ns() > merger_->last_ns()) return Next::kEnd;
    shift_ns_ += merger_->last_ns() - merger_->first_ns() + kLapGap_ns;
    oversize_ += merger_->oversize();
    merger_ = std::make_unique<RunMerger>(dir_, options_.streams, shift_ns_, options_.lidar_ports);
    missing_reported_ = merger_->missing().size();  // said once, at the first lap
    error_reported_ = false;
    notice_ = {Notice::Level::kInfo, "replay: lap " + std::to_string(++lap_)};
    return Next::kNotice;
  }
  if (pacer_.paced()) {
    const std::int64_t due = pacer_.due_ns(t);
    const std::int64_t now = host::monotonic_ns();
    if (due > now + kPacingQuantum_ns) {
      ready_ = false;
      const std::int64_t until = std::min(due, now + std::chrono::nanoseconds(timeout).count());
      Pacer::sleep_until(until);
      if (until < due) return Next::kTimeout;
    }
  }
  (void)merger_->next(item);
  ++items_;
  std::int64_t following = 0;
  ready_ = merger_->peek_time(following) &&
           (!pacer_.paced() || pacer_.due_ns(following) <= host::monotonic_ns() + kPacingQuantum_ns);
  return Next::kItem;
}

}  // namespace trajroi::inputs
