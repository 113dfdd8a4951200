#include "swarmbox/depth/depth_summary.hpp"

#include <algorithm>
#include <cmath>

namespace swarmbox::depth {
namespace {

// The q-quantile of `v` (reordered); 0 when empty.
float Quantile(std::vector<float>* v, double q) {
  if (v->empty()) return 0.0f;
  const auto k = static_cast<std::size_t>(q * static_cast<double>(v->size() - 1));
  std::nth_element(v->begin(), v->begin() + static_cast<std::ptrdiff_t>(k), v->end());
  return (*v)[k];
}

}  // namespace

DepthSummary Summarize(const cv::Mat& depth_m, int grid_cols, int grid_rows) {
  CV_Assert(depth_m.type() == CV_32F && grid_cols > 0 && grid_rows > 0);
  DepthSummary s;
  s.grid_cols = grid_cols;
  s.grid_rows = grid_rows;
  s.grid_m.assign(static_cast<std::size_t>(grid_cols * grid_rows), 0.0f);
  std::vector<float> all;
  std::vector<std::vector<float>> cells(s.grid_m.size());
  all.reserve(depth_m.total());
  for (int v = 0; v < depth_m.rows; ++v) {
    const auto* z = depth_m.ptr<float>(v);
    const int gr = v * grid_rows / depth_m.rows;
    for (int u = 0; u < depth_m.cols; ++u) {
      if (!(z[u] > 0) || !std::isfinite(z[u])) continue;
      all.push_back(z[u]);
      cells[static_cast<std::size_t>(gr * grid_cols + u * grid_cols / depth_m.cols)].push_back(z[u]);
    }
  }
  if (depth_m.total() > 0) s.fill_rate = static_cast<double>(all.size()) / static_cast<double>(depth_m.total());
  s.near_p5_m = Quantile(&all, 0.05);
  s.median_m = Quantile(&all, 0.5);
  for (std::size_t i = 0; i < cells.size(); ++i) s.grid_m[i] = Quantile(&cells[i], 0.5);
  return s;
}

}  // namespace swarmbox::depth
