#pragma once

namespace trajroi::roi {

// One LiDAR return: 16 bytes, so a frame is a dense array that streams well.
// Coordinates in metres in whichever frame the owning container says (sensor, robot, global).
struct PointXYZI {
  float x;
  float y;
  float z;
  float intensity;
};

// A double-precision point, for inputs that are given in double (CSV files, the paper's
// artificial data) and must be decided without rounding to float first.
struct PointXYZd {
  double x;
  double y;
  double z;
};

}  // namespace trajroi::roi
