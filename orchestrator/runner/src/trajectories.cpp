#include "swarmbox/runner/trajectories.hpp"

#include <algorithm>
#include <cmath>
#include <optional>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "swarmbox/common/split.hpp"
#include "swarmbox/common/yaml.hpp"

namespace swarmbox::runner {

namespace {

const cv::Scalar kPalette[] = {
    {180, 119, 31}, {14, 127, 255}, {44, 160, 44},  {40, 39, 214},  {189, 103, 148},
    {75, 86, 140},  {194, 119, 227}, {127, 127, 127}, {34, 189, 188}, {207, 190, 23},
};

using Tracks = std::vector<std::pair<std::string, std::vector<TrackPoint>>>;

// The columns of truth.csv a picture needs, found in its header (nullopt when one is missing);
// `count` is the header's width, which every row must have at least.
struct TruthColumns {
  std::size_t t = 0, drone = 0, x = 0, y = 0;
  std::size_t count = 0;

  static std::optional<TruthColumns> FromHeader(const std::vector<std::string_view>& cells) {
    int col_t = -1, col_drone = -1, col_x = -1, col_y = -1;
    for (std::size_t i = 0; i < cells.size(); ++i) {
      if (cells[i] == "t_s") col_t = static_cast<int>(i);
      if (cells[i] == "drone") col_drone = static_cast<int>(i);
      if (cells[i] == "x_m") col_x = static_cast<int>(i);
      if (cells[i] == "y_m") col_y = static_cast<int>(i);
    }
    if (col_t < 0 || col_drone < 0 || col_x < 0 || col_y < 0) return std::nullopt;
    return TruthColumns{static_cast<std::size_t>(col_t), static_cast<std::size_t>(col_drone),
                        static_cast<std::size_t>(col_x), static_cast<std::size_t>(col_y), cells.size()};
  }
};

// One data row onto its drone's track (tracks in order of first appearance).
Status AddTruthRow(const std::vector<std::string_view>& cells, const TruthColumns& columns, int line_no,
                   Tracks* tracks) {
  const std::string where = "truth.csv:" + std::to_string(line_no);
  if (cells.size() < columns.count) {
    return Error(ErrorCode::kInvalidArgument,
                 "expected " + std::to_string(columns.count) + " columns, got " + std::to_string(cells.size()),
                 where);
  }
  auto t = yaml::ScalarAsDouble(cells[columns.t]), x = yaml::ScalarAsDouble(cells[columns.x]),
       y = yaml::ScalarAsDouble(cells[columns.y]);
  if (!t || !x || !y) return Error(ErrorCode::kInvalidArgument, "t_s, x_m and y_m must be numbers", where);
  const std::string drone(cells[columns.drone]);
  auto it = std::find_if(tracks->begin(), tracks->end(), [&](const auto& tr) { return tr.first == drone; });
  if (it == tracks->end()) {
    tracks->emplace_back(drone, std::vector<TrackPoint>{});
    it = tracks->end() - 1;
  }
  it->second.push_back({*t, *x, *y});
  return Ok{};
}

}  // namespace

Result<std::vector<std::pair<std::string, std::vector<TrackPoint>>>> ParseTruthCsv(
    std::string_view csv) {
  Tracks tracks;
  std::size_t pos = 0;
  int line_no = 0;
  std::optional<TruthColumns> columns;
  while (pos < csv.size()) {
    auto nl = csv.find('\n', pos);
    std::string_view line = csv.substr(pos, nl == std::string_view::npos ? nl : nl - pos);
    pos = nl == std::string_view::npos ? csv.size() : nl + 1;
    ++line_no;
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    if (line.empty()) continue;
    const auto cells = SplitOn(line, ',');
    if (columns) {
      SWARMBOX_TRY(AddTruthRow(cells, *columns, line_no, &tracks));
      continue;
    }
    columns = TruthColumns::FromHeader(cells);
    if (!columns) {
      return Error(ErrorCode::kInvalidArgument, "truth.csv header lacks t_s, drone, x_m or y_m", "truth.csv:1");
    }
  }
  return tracks;
}

Result<WorldPicture> LoadWorldPicture(const std::string& path) {
  auto doc = yaml::ParseFile(path);
  if (!doc) return doc.error();
  WorldPicture w;
  auto num = [](const yaml::Node* n, double fallback) {
    if (n == nullptr) return fallback;
    auto v = n->AsDouble();
    return v ? *v : fallback;
  };
  if (const yaml::Node* g = doc->Find("geofence"); g != nullptr && g->is_mapping()) {
    w.size_x_m = num(g->Find("size_x_m"), w.size_x_m);
    w.size_y_m = num(g->Find("size_y_m"), w.size_y_m);
  }
  if (const yaml::Node* obs = doc->Find("obstacles"); obs != nullptr && obs->is_sequence()) {
    for (const yaml::Node& o : obs->items()) {
      const yaml::Node* c = o.Find("center_m");
      const yaml::Node* s = o.Find("size_m");
      if (c == nullptr || s == nullptr || !c->is_sequence() || !s->is_sequence() ||
          c->items().size() < 2 || s->items().size() < 2) {
        return Error(ErrorCode::kInvalidArgument, "obstacle without center_m/size_m", o.Where());
      }
      const yaml::Node* kind = o.Find("kind");
      w.obstacles.push_back({num(&c->items()[0], 0), num(&c->items()[1], 0),
                             num(&s->items()[0], 1), num(&s->items()[1], 1),
                             num(o.Find("yaw_deg"), 0), kind != nullptr && kind->is_scalar() && kind->scalar() == "tree"});
    }
  }
  if (const yaml::Node* vs = doc->Find("victims"); vs != nullptr && vs->is_sequence()) {
    for (const yaml::Node& v : vs->items()) {
      const yaml::Node* id = v.Find("id");
      w.victims.push_back({id != nullptr ? id->scalar() : "victim", num(v.Find("x_m"), 0),
                           num(v.Find("y_m"), 0)});
    }
  }
  return w;
}

namespace {

// The picture's frame: the geofence, grown to every track point, plus a margin; metres to pixels
// with y north up.
struct View {
  double half = 0;   // [m] from the centre to each edge
  double scale = 0;  // [px/m]
  cv::Point Px(double x, double y) const {
    return cv::Point(static_cast<int>(std::lround((x + half) * scale)),
                     static_cast<int>(std::lround((half - y) * scale)));
  }
};

View FrameOf(const std::vector<std::pair<std::string, std::vector<TrackPoint>>>& tracks, const WorldPicture& world,
             int size_px) {
  double half_x = world.size_x_m / 2, half_y = world.size_y_m / 2;
  for (const auto& [name, pts] : tracks) {
    for (const TrackPoint& p : pts) {
      half_x = std::max(half_x, std::fabs(p.x_m));
      half_y = std::max(half_y, std::fabs(p.y_m));
    }
  }
  View v;
  v.half = std::max(half_x, half_y) * 1.05 + 1.0;
  v.scale = size_px / (2 * v.half);
  return v;
}

// Grid every 10 m (axes darker), the geofence, the obstacles (trees as discs) and the victims.
void DrawWorld(const View& v, const WorldPicture& world, cv::Mat& img) {
  const double half = v.half;
  for (double g = -std::floor(half / 10) * 10; g <= half; g += 10) {
    const cv::Scalar c = std::fabs(g) < 1e-9 ? cv::Scalar(170, 170, 170) : cv::Scalar(228, 228, 228);
    cv::line(img, v.Px(g, -half), v.Px(g, half), c, 1);
    cv::line(img, v.Px(-half, g), v.Px(half, g), c, 1);
  }
  cv::rectangle(img, v.Px(-world.size_x_m / 2, world.size_y_m / 2),
                v.Px(world.size_x_m / 2, -world.size_y_m / 2), cv::Scalar(90, 90, 90), 2);
  for (const auto& o : world.obstacles) {
    if (o.tree) {
      cv::circle(img, v.Px(o.x_m, o.y_m), std::max(1, static_cast<int>(std::min(o.sx_m, o.sy_m) / 2 * v.scale)),
                 cv::Scalar(80, 150, 90), cv::FILLED, cv::LINE_AA);
      continue;
    }
    cv::RotatedRect r(cv::Point2f(static_cast<float>((o.x_m + half) * v.scale),
                                  static_cast<float>((half - o.y_m) * v.scale)),
                      cv::Size2f(static_cast<float>(o.sx_m * v.scale), static_cast<float>(o.sy_m * v.scale)),
                      static_cast<float>(-o.yaw_deg));
    cv::Point2f corners[4];
    r.points(corners);
    std::vector<cv::Point> poly;
    for (const auto& c : corners) poly.emplace_back(static_cast<int>(c.x), static_cast<int>(c.y));
    cv::fillConvexPoly(img, poly, cv::Scalar(120, 120, 120));
  }
  for (const auto& victim : world.victims) {
    cv::drawMarker(img, v.Px(victim.x_m, victim.y_m), cv::Scalar(0, 0, 220), cv::MARKER_STAR, 18, 2);
    cv::putText(img, victim.id, v.Px(victim.x_m, victim.y_m) + cv::Point(10, -10), cv::FONT_HERSHEY_SIMPLEX, 0.45,
                cv::Scalar(0, 0, 180), 1, cv::LINE_AA);
  }
}

// Each track in its palette colour (start circle, end cross) with its legend line.
void DrawTracks(const View& v, const std::vector<std::pair<std::string, std::vector<TrackPoint>>>& tracks,
                cv::Mat& img) {
  int legend_y = 24;
  std::size_t colour = 0;
  for (const auto& [name, pts] : tracks) {
    const cv::Scalar c = kPalette[colour++ % (sizeof kPalette / sizeof kPalette[0])];
    std::vector<cv::Point> line;
    for (const TrackPoint& p : pts) line.push_back(v.Px(p.x_m, p.y_m));
    if (line.size() > 1) cv::polylines(img, line, false, c, 2, cv::LINE_AA);
    if (!line.empty()) {
      cv::circle(img, line.front(), 5, c, 2, cv::LINE_AA);
      cv::drawMarker(img, line.back(), c, cv::MARKER_TILTED_CROSS, 12, 2);
    }
    cv::line(img, {12, legend_y - 5}, {36, legend_y - 5}, c, 3);
    cv::putText(img, name, {42, legend_y}, cv::FONT_HERSHEY_SIMPLEX, 0.5, cv::Scalar(30, 30, 30), 1,
                cv::LINE_AA);
    legend_y += 20;
  }
}

}  // namespace

Status DrawTrajectories(
    const std::vector<std::pair<std::string, std::vector<TrackPoint>>>& tracks,
    const WorldPicture& world, const std::vector<Detection>& detections, const std::string& path,
    int size_px) {
  const View view = FrameOf(tracks, world, size_px);
  cv::Mat img(size_px, size_px, CV_8UC3, cv::Scalar(250, 250, 250));
  DrawWorld(view, world, img);
  DrawTracks(view, tracks, img);
  for (const Detection& d : detections) {
    cv::circle(img, view.Px(d.x_m, d.y_m), d.confirmed ? 9 : 6,
               d.confirmed ? cv::Scalar(0, 160, 0) : cv::Scalar(0, 140, 255), 2, cv::LINE_AA);
  }
  cv::putText(img, "10 m grid, x east, y north", {12, size_px - 12}, cv::FONT_HERSHEY_SIMPLEX, 0.45,
              cv::Scalar(80, 80, 80), 1, cv::LINE_AA);
  try {
    if (!cv::imwrite(path, img)) return Error(ErrorCode::kIo, "cannot write PNG", path);
  } catch (const cv::Exception& e) {
    return Error(ErrorCode::kIo, std::string("cannot write PNG: ") + e.what(), path);
  }
  return Ok{};
}

}  // namespace swarmbox::runner
