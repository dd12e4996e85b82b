#include "trajroi/eval/svg.hpp"

#include <algorithm>
#include <cmath>
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
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '&':
        out += "&amp;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

}  // namespace

SvgCanvas::SvgCanvas(double x_min, double y_min, double x_max, double y_max, double px_per_m, std::string_view title)
    : x_min_(x_min),
      y_max_(y_max),
      scale_(px_per_m),
      width_px_((x_max - x_min) * px_per_m + 2 * kMargin),
      height_px_((y_max - y_min) * px_per_m + 2 * kMargin + kHeader),
      title_(escape(title)) {}

void SvgCanvas::dot(double x, double y, std::string_view colour, double size_px) {
  append_format(body_, "<rect x=\"%.1f\" y=\"%.1f\" width=\"%.1f\" height=\"%.1f\" fill=\"%.*s\"/>\n",
                px(x) - size_px / 2, py(y) - size_px / 2, size_px, size_px, static_cast<int>(colour.size()),
                colour.data());
}

void SvgCanvas::circle(double cx, double cy, double radius_m, std::string_view colour, double width_px) {
  append_format(overlay_,
                "<circle cx=\"%.2f\" cy=\"%.2f\" r=\"%.2f\" fill=\"none\" stroke=\"%.*s\" "
                "stroke-width=\"%.1f\" stroke-opacity=\"0.7\"/>\n",
                px(cx), py(cy), radius_m * scale_, static_cast<int>(colour.size()), colour.data(), width_px);
}

void SvgCanvas::path_element(const char* tag, std::span<const Eigen::Vector2d> points, std::string_view colour,
                             double width_px, double opacity) {
  append_format(overlay_, "<%s points=\"", tag);
  for (const Eigen::Vector2d& p : points)
    append_format(overlay_, "%.2f,%.2f ", px(p.x()), py(p.y()));
  append_format(overlay_, "\" fill=\"none\" stroke=\"%.*s\" stroke-width=\"%.1f\" stroke-opacity=\"%.2f\"/>\n",
                static_cast<int>(colour.size()), colour.data(), width_px, opacity);
}

void SvgCanvas::polygon(std::span<const Eigen::Vector2d> corners, std::string_view colour, double width_px) {
  path_element("polygon", corners, colour, width_px, 0.7);
}

void SvgCanvas::polyline(std::span<const Eigen::Vector2d> points, std::string_view colour, double width_px) {
  path_element("polyline", points, colour, width_px, 1.0);
}

void SvgCanvas::legend(std::string_view colour, std::string_view label) {
  constexpr double kRowY = 46.0;
  append_format(overlay_,
                "<rect x=\"%.1f\" y=\"%.1f\" width=\"10\" height=\"10\" fill=\"%.*s\"/>"
                "<text x=\"%.1f\" y=\"%.1f\" font-size=\"12\" font-family=\"sans-serif\">",
                legend_x_, kRowY, static_cast<int>(colour.size()), colour.data(), legend_x_ + 14.0, kRowY + 9.5);
  overlay_ += escape(label);
  overlay_ += "</text>\n";
  legend_x_ += 24.0 + 6.5 * static_cast<double>(label.size());
}

std::string SvgCanvas::element(double x_px) const {
  std::string out;
  append_format(out,
                "<svg xmlns=\"http://www.w3.org/2000/svg\" x=\"%.0f\" width=\"%.0f\" height=\"%.0f\" "
                "viewBox=\"0 0 %.0f %.0f\">\n<rect width=\"100%%\" height=\"100%%\" fill=\"white\"/>\n",
                x_px, width_px_, height_px_, width_px_, height_px_);
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

std::string side_by_side(std::span<const SvgCanvas> panels) {
  double width = 0.0, height = 0.0;
  for (const SvgCanvas& p : panels) {
    width += p.width_px();
    height = std::max(height, p.height_px());
  }
  std::string out;
  append_format(out,
                "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"%.0f\" height=\"%.0f\" viewBox=\"0 0 %.0f %.0f\">\n",
                width, height, width, height);
  double x = 0.0;
  for (const SvgCanvas& p : panels) {
    out += p.element(x);
    x += p.width_px();
  }
  out += "</svg>\n";
  return out;
}

void draw_classified(SvgCanvas& canvas, std::span<const Eigen::Vector2d> points, std::span<const std::uint32_t> kept,
                     std::span<const std::uint8_t> truth, double dot_px) {
  std::vector<std::uint8_t> kept_mask(points.size(), 0);
  for (const std::uint32_t i : kept)
    kept_mask[i] = 1;
  for (std::size_t i = 0; i < points.size(); ++i) {
    const bool in_truth = truth[i] != 0;
    const std::string_view colour =
        kept_mask[i] != 0 ? (in_truth ? kColourTp : kColourFp) : (in_truth ? kColourFn : kColourTn);
    canvas.dot(points[i].x(), points[i].y(), colour, dot_px);
  }
  canvas.legend(kColourTp, "TP: kept, in the ground-truth corridor");
  canvas.legend(kColourFp, "FP: kept, outside it");
  canvas.legend(kColourFn, "FN: missed");
  canvas.legend(kColourTn, "TN: dropped, outside it");
}

void draw_chain(SvgCanvas& canvas, std::span<const roi::Centre> centres, bool circles, double diameter_or_height_m,
                double width_m) {
  for (const roi::Centre& c : centres) {
    if (circles) {
      canvas.circle(c.position.x(), c.position.y(), diameter_or_height_m / 2.0, kColourRoi);
      continue;
    }
    const Eigen::Vector2d u =
        diameter_or_height_m / 2.0 * Eigen::Vector2d(std::cos(c.theta_rad), std::sin(c.theta_rad));
    const Eigen::Vector2d v = width_m / 2.0 * Eigen::Vector2d(-std::sin(c.theta_rad), std::cos(c.theta_rad));
    const Eigen::Vector2d corners[4] = {c.position - u - v, c.position - u + v, c.position + u + v, c.position + u - v};
    canvas.polygon(corners, kColourRoi);
  }
}

SvgChart::SvgChart(std::string_view title, std::string_view x_label, std::string_view y_label)
    : title_(escape(title)), x_label_(escape(x_label)), y_label_(escape(y_label)) {}

void SvgChart::line(std::string_view name, std::string_view colour, std::vector<std::pair<double, double>> points) {
  series_.push_back({escape(name), std::string(colour), std::move(points), false});
}

void SvgChart::dots(std::string_view name, std::string_view colour, std::vector<std::pair<double, double>> points) {
  series_.push_back({escape(name), std::string(colour), std::move(points), true});
}

namespace {

// A tick step of 1, 2 or 5 × 10^k giving about five ticks over `span`.
double tick_step(double span) {
  if (!(span > 0.0)) return 1.0;
  const double raw = span / 5.0;
  const double magnitude = std::pow(10.0, std::floor(std::log10(raw)));
  const double f = raw / magnitude;
  return (f < 1.5 ? 1.0 : f < 3.5 ? 2.0 : f < 7.5 ? 5.0 : 10.0) * magnitude;
}

}  // namespace

std::string SvgChart::str() const {
  constexpr double kWidth = 900, kHeight = 420, kLeft = 80, kRight = 20, kTop = 60, kBottom = 50;
  double x0 = 0.0, x1 = 1.0, y0 = 0.0, y1 = 1.0;
  bool first = true;
  for (const Series& s : series_) {
    for (const auto& [x, y] : s.points) {
      if (first) {
        x0 = x1 = x;
        y1 = y;
        first = false;
      }
      x0 = std::min(x0, x);
      x1 = std::max(x1, x);
      y1 = std::max(y1, y);
    }
  }
  y0 = 0.0;
  if (x1 <= x0) x1 = x0 + 1.0;
  if (y1 <= y0) y1 = y0 + 1.0;
  y1 *= 1.05;
  const double pw = kWidth - kLeft - kRight, ph = kHeight - kTop - kBottom;
  auto px = [&](double x) { return kLeft + (x - x0) / (x1 - x0) * pw; };
  auto py = [&](double y) { return kTop + ph - (y - y0) / (y1 - y0) * ph; };
  std::string out;
  append_format(out,
                "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"%.0f\" height=\"%.0f\" viewBox=\"0 0 %.0f %.0f\">\n"
                "<rect width=\"100%%\" height=\"100%%\" fill=\"white\"/>\n"
                "<text x=\"%.0f\" y=\"22\" font-size=\"15\" font-family=\"sans-serif\">",
                kWidth, kHeight, kWidth, kHeight, kLeft);
  out += title_;
  out += "</text>\n";
  append_format(out, "<rect x=\"%.0f\" y=\"%.0f\" width=\"%.0f\" height=\"%.0f\" fill=\"none\" stroke=\"#444\"/>\n",
                kLeft, kTop, pw, ph);
  const double xs = tick_step(x1 - x0), ys = tick_step(y1 - y0);
  for (double t = std::ceil(x0 / xs) * xs; t <= x1 + 1e-9 * xs; t += xs) {
    append_format(
        out,
        "<text x=\"%.1f\" y=\"%.0f\" font-size=\"11\" font-family=\"sans-serif\" text-anchor=\"middle\">%g</text>\n",
        px(t), kTop + ph + 16, t);
  }
  for (double t = 0.0; t <= y1 + 1e-9 * ys; t += ys) {
    append_format(
        out,
        "<line x1=\"%.0f\" x2=\"%.0f\" y1=\"%.1f\" y2=\"%.1f\" stroke=\"#ddd\"/>"
        "<text x=\"%.0f\" y=\"%.1f\" font-size=\"11\" font-family=\"sans-serif\" text-anchor=\"end\">%g</text>\n",
        kLeft, kLeft + pw, py(t), py(t), kLeft - 6, py(t) + 4, t);
  }
  append_format(out, "<text x=\"%.0f\" y=\"%.0f\" font-size=\"12\" font-family=\"sans-serif\" text-anchor=\"middle\">",
                kLeft + pw / 2, kHeight - 10);
  out += x_label_;
  append_format(out,
                "</text>\n<text x=\"16\" y=\"%.0f\" font-size=\"12\" font-family=\"sans-serif\" "
                "text-anchor=\"middle\" transform=\"rotate(-90 16 %.0f)\">",
                kTop + ph / 2, kTop + ph / 2);
  out += y_label_;
  out += "</text>\n";
  double legend_x = kLeft;
  for (const Series& s : series_) {
    if (s.dots) {
      for (const auto& [x, y] : s.points) {
        append_format(out, "<circle cx=\"%.1f\" cy=\"%.1f\" r=\"2.5\" fill=\"%s\"/>\n", px(x), py(y), s.colour.c_str());
      }
    } else {
      append_format(out, "<polyline fill=\"none\" stroke=\"%s\" stroke-width=\"1\" points=\"", s.colour.c_str());
      for (const auto& [x, y] : s.points)
        append_format(out, "%.1f,%.1f ", px(x), py(y));
      out += "\"/>\n";
    }
    append_format(out,
                  "<rect x=\"%.0f\" y=\"34\" width=\"10\" height=\"10\" fill=\"%s\"/>"
                  "<text x=\"%.0f\" y=\"43\" font-size=\"12\" font-family=\"sans-serif\">",
                  legend_x, s.colour.c_str(), legend_x + 14);
    out += s.name;
    out += "</text>\n";
    legend_x += 30.0 + 6.5 * static_cast<double>(s.name.size());
  }
  out += "</svg>\n";
  return out;
}

}  // namespace trajroi::eval
