#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "trajroi/roi/centres.hpp"

namespace trajroi::eval {

// A top-down SVG drawing of the global XY plane: +x right, +y up, metres scaled to pixels.
// Builds the document in memory; str() returns it complete.
class SvgCanvas {
 public:
  // The drawing covers [x_min, x_max] × [y_min, y_max] plus a margin, at px_per_m. The title
  // may hold one '\n': the text after it becomes a smaller second line.
  SvgCanvas(double x_min, double y_min, double x_max, double y_max, double px_per_m, std::string_view title);

  void dot(double x, double y, std::string_view colour, double size_px = 2.0);
  void circle(double cx, double cy, double radius_m, std::string_view colour, double width_px = 1.0);
  void polygon(std::span<const Eigen::Vector2d> corners, std::string_view colour, double width_px = 1.0);
  void polyline(std::span<const Eigen::Vector2d> points, std::string_view colour, double width_px = 1.5);
  // A legend entry in the header's legend row, one per call, left to right.
  void legend(std::string_view colour, std::string_view label);

  [[nodiscard]] std::string str() const { return element(0.0); }
  // The drawing as an <svg> element placed at x = x_px inside a larger drawing.
  [[nodiscard]] std::string element(double x_px) const;
  [[nodiscard]] double width_px() const noexcept { return width_px_; }
  [[nodiscard]] double height_px() const noexcept { return height_px_; }

 private:
  // <polygon> or <polyline> through the points, unfilled.
  void path_element(const char* tag, std::span<const Eigen::Vector2d> points, std::string_view colour, double width_px,
                    double opacity);
  [[nodiscard]] double px(double x) const noexcept { return (x - x_min_) * scale_ + kMargin; }
  [[nodiscard]] double py(double y) const noexcept { return (y_max_ - y) * scale_ + kMargin + kHeader; }

  static constexpr double kMargin = 20.0;
  static constexpr double kHeader = 64.0;  // two title lines and the legend row
  double x_min_;
  double y_max_;
  double scale_;
  double width_px_;
  double height_px_;
  double legend_x_ = kMargin;
  std::string body_;
  std::string overlay_;
  std::string title_;
};

// Several drawings side by side in one document.
[[nodiscard]] std::string side_by_side(std::span<const SvgCanvas> panels);

// A plot of series against one x axis (Figs. 22 and 23 of the paper): lines or dots, axes
// scaled to the data, ticks and a legend.
class SvgChart {
 public:
  SvgChart(std::string_view title, std::string_view x_label, std::string_view y_label);
  void line(std::string_view name, std::string_view colour, std::vector<std::pair<double, double>> points);
  void dots(std::string_view name, std::string_view colour, std::vector<std::pair<double, double>> points);
  [[nodiscard]] std::string str() const;

 private:
  struct Series {
    std::string name;
    std::string colour;
    std::vector<std::pair<double, double>> points;
    bool dots;
  };
  std::string title_, x_label_, y_label_;
  std::vector<Series> series_;
};

// Colours used for classified points everywhere, so pictures read the same.
inline constexpr std::string_view kColourTp = "#2ca02c";  // kept, in the truth corridor
inline constexpr std::string_view kColourFp = "#d62728";  // kept, outside it
inline constexpr std::string_view kColourFn = "#ff7f0e";  // missed
inline constexpr std::string_view kColourTn = "#c7c7c7";  // rightly dropped
inline constexpr std::string_view kColourRoi = "#1f77b4";
inline constexpr std::string_view kColourTrajectory = "#000000";
inline constexpr std::string_view kColourRaw = "#7f7f7f";

// Draws every point coloured by its class: kept (ascending indices into the points) against
// truth (per point, non-zero inside the ground-truth corridor); adds the four legend entries.
void draw_classified(SvgCanvas& canvas, std::span<const Eigen::Vector2d> points, std::span<const std::uint32_t> kept,
                     std::span<const std::uint8_t> truth, double dot_px);
// Outlines a chain of circles (diameter) or rectangles (height along, width across).
void draw_chain(SvgCanvas& canvas, std::span<const roi::Centre> centres, bool circles, double diameter_or_height_m,
                double width_m);

}  // namespace trajroi::eval
