#include "trajroi/eval/svg.hpp"

#include <algorithm>
#include <cstdio>

namespace trajroi::eval {
namespace {

void append_format(std::string& out, const char* format, auto... args) {
  char buffer[256];
  const int n = std::snprintf(buffer, sizeof buffer, format, args...);
  if (n > 0) out.append(buffer, std::min<std::size_t>(static_cast<std::size_t>(n), sizeof buffer - 1));
}

std::string escape(std::string_view text) {
  std::string out;
  for (const char c : text) {
    switch (c) {
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '&': out += "&amp;"; break;
      default: out += c;
    }
  }
  return out;
}

}  // namespace

SvgCanvas::SvgCanvas(double x_min, double y_min, double x_max, double y_max, double px_per_m,
                     std::string_view title)
    : x_min_(x_min),
      y_max_(y_max),
      scale_(px_per_m),
      width_px_((x_max - x_min) * px_per_m + 2 * kMargin),
      height_px_((y_max - y_min) * px_per_m + 2 * kMargin + kHeader),
      title_(escape(title)) {}

void SvgCanvas::dot(double x, double y, std::string_view colour, double size_px) {
  append_format(body_, "<rect x=\"%.1f\" y=\"%.1f\" width=\"%.1f\" height=\"%.1f\" fill=\"%.*s\"/>\n",
                px(x) - size_px / 2, py(y) - size_px / 2, size_px, size_px,
                static_cast<int>(colour.size()), colour.data());
}

void SvgCanvas::circle(double cx, double cy, double radius_m, std::string_view colour,
                       double width_px) {
  append_format(overlay_,
                "<circle cx=\"%.2f\" cy=\"%.2f\" r=\"%.2f\" fill=\"none\" stroke=\"%.*s\" "
                "stroke-width=\"%.1f\" stroke-opacity=\"0.7\"/>\n",
                px(cx), py(cy), radius_m * scale_, static_cast<int>(colour.size()), colour.data(),
                width_px);
}

void SvgCanvas::path_element(const char* tag, std::span<const Eigen::Vector2d> points,
                             std::string_view colour, double width_px, double opacity) {
  append_format(overlay_, "<%s points=\"", tag);
  for (const Eigen::Vector2d& p : points) append_format(overlay_, "%.2f,%.2f ", px(p.x()), py(p.y()));
  append_format(overlay_, "\" fill=\"none\" stroke=\"%.*s\" stroke-width=\"%.1f\" stroke-opacity=\"%.2f\"/>\n",
                static_cast<int>(colour.size()), colour.data(), width_px, opacity);
}

void SvgCanvas::polygon(std::span<const Eigen::Vector2d> corners, std::string_view colour,
                        double width_px) {
  path_element("polygon", corners, colour, width_px, 0.7);
}

void SvgCanvas::polyline(std::span<const Eigen::Vector2d> points, std::string_view colour,
                         double width_px) {
  path_element("polyline", points, colour, width_px, 1.0);
}

void SvgCanvas::legend(std::string_view colour, std::string_view label) {
  constexpr double kRowY = 46.0;
  append_format(overlay_,
                "<rect x=\"%.1f\" y=\"%.1f\" width=\"10\" height=\"10\" fill=\"%.*s\"/>"
                "<text x=\"%.1f\" y=\"%.1f\" font-size=\"12\" font-family=\"sans-serif\">",
                legend_x_, kRowY, static_cast<int>(colour.size()), colour.data(), legend_x_ + 14.0,
                kRowY + 9.5);
  overlay_ += escape(label);
  overlay_ += "</text>\n";
  legend_x_ += 24.0 + 6.5 * static_cast<double>(label.size());
}

std::string SvgCanvas::str() const {
  std::string out;
  append_format(out,
                "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"%.0f\" height=\"%.0f\" "
                "viewBox=\"0 0 %.0f %.0f\">\n<rect width=\"100%%\" height=\"100%%\" fill=\"white\"/>\n",
                width_px_, height_px_, width_px_, height_px_);
  const std::size_t newline = title_.find('\n');
  append_format(out, "<text x=\"%.1f\" y=\"18\" font-size=\"15\" font-family=\"sans-serif\">", kMargin);
  out += title_.substr(0, newline);
  out += "</text>\n";
  if (newline != std::string::npos) {
    append_format(out, "<text x=\"%.1f\" y=\"36\" font-size=\"12\" font-family=\"sans-serif\">", kMargin);
    out += title_.substr(newline + 1);
    out += "</text>\n";
  }
  out += body_;
  out += overlay_;
  out += "</svg>\n";
  return out;
}

}  // namespace trajroi::eval
