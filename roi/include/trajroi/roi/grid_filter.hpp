#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <span>
#include <utility>
#include <vector>

#include "trajroi/roi/filter_stats.hpp"
#include "trajroi/roi/shapes.hpp"

namespace trajroi::roi {

// The fast filter: the same membership decision as reference_filter for every point, bit for
// bit, at a per-point cost that does not grow with the number of ROIs.
//
// build() lays a uniform grid over the chain's bounding box and classifies every cell, with a
// margin far larger than rounding error, as outside every ROI, inside at least one ROI, or
// boundary. A boundary cell keeps the ascending list of ROIs that may contain some of its
// points; a point in such a cell is decided by calling the same RoiSet::contains() the
// reference calls, on those candidates only. Since every ROI left out of the list rejects
// the point for sure, and any ROI that accepts it makes the reference keep it, both agree.
//
// A filter() call allocates nothing once `kept` has the capacity; build() reuses its storage.
template <typename RoiSet>
class GridFilter {
 public:
  // Cell count ceiling: 4 M cells (16 MiB); a larger area gets coarser cells, still exact.
  static constexpr std::size_t kMaxCells = std::size_t{1} << 22;

  // `rois` must stay alive and unchanged until the next build().
  void build(const RoiSet& rois);

  template <typename Point>
  FilterStats filter(std::span<const Point> points, std::vector<std::uint32_t>& kept) const;

  [[nodiscard]] std::size_t cell_count() const noexcept { return cells_.size(); }
  [[nodiscard]] std::size_t boundary_cell_count() const noexcept {
    return offsets_.empty() ? 0 : offsets_.size() - 1;
  }
  [[nodiscard]] double cell_size_m() const noexcept { return cell_size_m_; }

 private:
  static constexpr std::uint32_t kOutside = 0;
  static constexpr std::uint32_t kInside = 1;
  static constexpr std::uint32_t kFirstBoundary = 2;  // cell value = boundary id + 2

  const RoiSet* rois_ = nullptr;
  double x0_ = 0.0;
  double y0_ = 0.0;
  double cell_size_m_ = 1.0;
  double inv_cell_ = 1.0;
  std::size_t nx_ = 0;
  std::size_t ny_ = 0;
  double nx_d_ = 0.0;
  double ny_d_ = 0.0;
  std::vector<std::uint32_t> cells_;
  std::vector<std::uint32_t> offsets_;     // boundary id → [offsets_[id], offsets_[id + 1])
  std::vector<std::uint32_t> candidates_;  // ROI indices, ascending within one cell
  std::vector<std::pair<std::uint32_t, std::uint32_t>> pairs_;  // build scratch: (cell, roi)
  std::vector<std::uint32_t> cursor_;                            // build scratch
};

template <typename RoiSet>
void GridFilter<RoiSet>::build(const RoiSet& rois) {
  rois_ = &rois;
  cells_.clear();
  offsets_.clear();
  candidates_.clear();
  pairs_.clear();
  nx_ = ny_ = 0;
  nx_d_ = ny_d_ = 0.0;
  const std::size_t m = rois.size();
  if (m == 0) return;

  Box bb = rois.bounds(0);
  for (std::size_t j = 1; j < m; ++j) {
    const Box b = rois.bounds(j);
    bb = {std::min(bb.x_min, b.x_min), std::min(bb.y_min, b.y_min), std::max(bb.x_max, b.x_max),
          std::max(bb.y_max, b.y_max)};
  }
  // Rounding in the per-point tests and in locating a point's cell is a few ulps of the
  // coordinates' magnitude; a margin of 1e-9 of that magnitude dwarfs it, and at 1 nm for
  // local coordinates it changes no classification that matters.
  const double magnitude = std::max({std::abs(bb.x_min), std::abs(bb.x_max), std::abs(bb.y_min),
                                     std::abs(bb.y_max), bb.x_max - bb.x_min, bb.y_max - bb.y_min,
                                     1.0});
  const double tolerance = 1e-9 * magnitude;
  const double cell_pad = 2.0 * tolerance;
  bb = {bb.x_min - 2.0 * tolerance, bb.y_min - 2.0 * tolerance, bb.x_max + 2.0 * tolerance,
        bb.y_max + 2.0 * tolerance};
  const double width = bb.x_max - bb.x_min;
  const double height = bb.y_max - bb.y_min;

  double h = rois.cell_size_hint_m();
  if (std::ceil(width / h) * std::ceil(height / h) > static_cast<double>(kMaxCells)) {
    h = std::sqrt(width * height / static_cast<double>(kMaxCells)) * 1.01;
    while (std::ceil(width / h) * std::ceil(height / h) > static_cast<double>(kMaxCells)) h *= 1.01;
  }
  cell_size_m_ = h;
  inv_cell_ = 1.0 / h;
  x0_ = bb.x_min;
  y0_ = bb.y_min;
  nx_ = std::max<std::size_t>(1, static_cast<std::size_t>(std::ceil(width / h)));
  ny_ = std::max<std::size_t>(1, static_cast<std::size_t>(std::ceil(height / h)));
  nx_d_ = static_cast<double>(nx_);
  ny_d_ = static_cast<double>(ny_);
  cells_.assign(nx_ * ny_, kOutside);

  auto cell_index = [](double v, double origin, double inv, std::size_t n) {
    const double f = std::floor((v - origin) * inv);
    if (!(f > 0.0)) return std::size_t{0};
    return std::min(static_cast<std::size_t>(f), n - 1);
  };
  for (std::size_t j = 0; j < m; ++j) {
    const Box b = rois.bounds(j);
    const double reach = tolerance + cell_pad;
    const std::size_t ix0 = cell_index(b.x_min - reach, x0_, inv_cell_, nx_);
    const std::size_t ix1 = cell_index(b.x_max + reach, x0_, inv_cell_, nx_);
    const std::size_t iy0 = cell_index(b.y_min - reach, y0_, inv_cell_, ny_);
    const std::size_t iy1 = cell_index(b.y_max + reach, y0_, inv_cell_, ny_);
    for (std::size_t iy = iy0; iy <= iy1; ++iy) {
      for (std::size_t ix = ix0; ix <= ix1; ++ix) {
        const std::size_t c = iy * nx_ + ix;
        if (cells_[c] == kInside) continue;
        const Box cell{x0_ + static_cast<double>(ix) * h - cell_pad,
                       y0_ + static_cast<double>(iy) * h - cell_pad,
                       x0_ + static_cast<double>(ix + 1) * h + cell_pad,
                       y0_ + static_cast<double>(iy + 1) * h + cell_pad};
        switch (rois.relation(j, cell, tolerance)) {
          case CellRelation::kInside: cells_[c] = kInside; break;
          case CellRelation::kBoundary:
            pairs_.emplace_back(static_cast<std::uint32_t>(c), static_cast<std::uint32_t>(j));
            break;
          case CellRelation::kOutside: break;
        }
      }
    }
  }

  // Number the boundary cells (those not made inside by some ROI) and gather their
  // candidates in ROI order: pairs_ is ordered by ROI, so each list comes out ascending.
  std::uint32_t boundary = 0;
  cursor_.clear();
  for (const auto& [c, j] : pairs_) {
    if (cells_[c] == kInside) continue;
    if (cells_[c] == kOutside) {
      cells_[c] = kFirstBoundary + boundary++;
      cursor_.push_back(0);
    }
    ++cursor_[cells_[c] - kFirstBoundary];
  }
  offsets_.assign(boundary + 1, 0);
  for (std::uint32_t id = 0; id < boundary; ++id) offsets_[id + 1] = offsets_[id] + cursor_[id];
  std::copy(offsets_.begin(), offsets_.end() - 1, cursor_.begin());
  candidates_.resize(offsets_.back());
  for (const auto& [c, j] : pairs_) {
    if (cells_[c] == kInside) continue;
    candidates_[cursor_[cells_[c] - kFirstBoundary]++] = j;
  }
}

template <typename RoiSet>
template <typename Point>
FilterStats GridFilter<RoiSet>::filter(std::span<const Point> points,
                                       std::vector<std::uint32_t>& kept) const {
  FilterStats stats;
  stats.input = points.size();
  kept.clear();
  if (rois_ == nullptr) return stats;
  const ZLimits& z_limits = rois_->z_limits();
  const std::uint32_t* cells = cells_.data();
  for (std::size_t i = 0; i < points.size(); ++i) {
    const double x = points[i].x;
    const double y = points[i].y;
    const Precheck pre = precheck(z_limits, x, y, points[i].z);
    if (pre != Precheck::kPass) {
      count(stats, pre);
      continue;
    }
    const double fx = (x - x0_) * inv_cell_;
    const double fy = (y - y0_) * inv_cell_;
    if (!(fx >= 0.0 && fx < nx_d_ && fy >= 0.0 && fy < ny_d_)) continue;
    const std::size_t ix = std::min(static_cast<std::size_t>(fx), nx_ - 1);
    const std::size_t iy = std::min(static_cast<std::size_t>(fy), ny_ - 1);
    const std::uint32_t cell = cells[iy * nx_ + ix];
    if (cell == kOutside) continue;
    bool inside = cell == kInside;
    if (!inside) {
      const std::uint32_t id = cell - kFirstBoundary;
      for (std::uint32_t k = offsets_[id]; k < offsets_[id + 1]; ++k) {
        if (rois_->contains(candidates_[k], x, y)) {
          inside = true;
          break;
        }
      }
    }
    if (inside) kept.push_back(static_cast<std::uint32_t>(i));
  }
  stats.kept = kept.size();
  return stats;
}

}  // namespace trajroi::roi
