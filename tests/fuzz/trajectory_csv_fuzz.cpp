// The trajectory CSV: any text is a validated trajectory or an error naming the line; a valid
// one answers every geometric query.
#include <cstdint>
#include <stdexcept>

#include "fuzz_input.hpp"
#include "trajroi/roi/centres.hpp"
#include "trajroi/roi/trajectory.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    const trajroi::roi::Trajectory t =
        trajroi::roi::parse_trajectory_csv(trajroi::fuzz::as_text(data, size), "fuzz.csv");
    const double length = t.length_m();
    (void)t.point_at(length / 3.0);
    (void)t.heading_at(length / 2.0);
    (void)t.project(Eigen::Vector2d(1.0, -2.0));
    std::vector<trajroi::roi::Centre> centres;
    if (length / 0.5 < static_cast<double>(trajroi::roi::kMaxCentres)) {
      trajroi::roi::place_centres(t, 0.0, length, 0.5, centres);
    }
  } catch (const std::exception&) {
  }
  return 0;
}
