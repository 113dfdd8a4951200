// swarmbox-bench camera: the cost of one downward camera frame (GroundRenderer) on one core, per
// world look, at the x500's camera (trials/airframes/x500.yaml), and the cost of building the scene.
//   suite=camera scenario=rubble_dusk width_px=640 height_px=360 frames=... ms_per_frame=... build_ms=...
//     copy_ms=... jpeg_quality=90 jpeg_kb=... jpeg_encode_ms=... jpeg_decode_ms=...
// copy_ms is one copy of the raw bgr8 frame (what each hop of it costs: the server's message, DDS's
// serialisation, the agent's); jpeg_*: the frame compressed as the camera could deliver it
// (OpenCV's libjpeg at quality 90), its size and what encoding and decoding it cost.
// A frame's cost is the process's CPU time (OpenCV's worker threads included: what a frame costs
// the machine, whatever the load), averaged over views at
// 10, 20, 30, 40 and 60 m near a person with random yaw, level and rolling (motion blur). --png=DIR also writes
// one frame per scenario and altitude (camera_<scenario>_<alt>m.png) to look at.
#include <cstdio>
#include <ctime>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "bench.hpp"
#include "swarmbox/physics/ground_renderer.hpp"

namespace {

using namespace swarmbox::physics;

// Process CPU time: OpenCV's worker threads (warpPerspective runs in parallel) count too.
double ThreadCpuS() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + static_cast<double>(ts.tv_nsec) * 1e-9;
}

// A 200 x 200 m world with people of every pose and cover, distractors, boxes and trees around
// the centre (where the views look).
WorldConfig ShowcaseWorld(const char* name, std::optional<Terrain> terrain, std::optional<Lighting> lighting) {
  WorldConfig w;
  w.name = name;
  w.ground_texture_seed = 11;
  w.terrain = terrain;
  w.lighting = lighting;
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> pos(-25, 25), unit(0, 1);
  const VictimPose poses[] = {VictimPose::kLying, VictimPose::kSitting, VictimPose::kCurled, VictimPose::kStanding};
  const Bgr clothes[] = {{40, 90, 60}, {50, 80, 110}, {110, 110, 110}, {30, 30, 200}, {200, 120, 30}, {20, 200, 240}};
  for (int i = 0; i < 12; ++i) {
    Victim v;
    v.id = "v" + std::to_string(i);
    v.x_m = pos(rng), v.y_m = pos(rng), v.heading_rad = unit(rng) * 2 * std::numbers::pi;
    v.pose = poses[i % 4];
    v.clothing_bgr = clothes[i % 6];
    v.cover = (i % 3) * 0.25;
    v.height_m = 1.5 + 0.4 * unit(rng);
    w.victims.push_back(v);
  }
  const DistractorKind kinds[] = {DistractorKind::kTarp, DistractorKind::kCone, DistractorKind::kBackpack,
                                  DistractorKind::kDebris, DistractorKind::kRock};
  for (int i = 0; i < 15; ++i) {
    Distractor d;
    d.kind = kinds[i % 5];
    d.x_m = pos(rng), d.y_m = pos(rng), d.heading_rad = unit(rng) * 6.28;
    d.size_m = DefaultSizeM(d.kind) * (0.7 + 0.6 * unit(rng));
    d.colour_bgr = DefaultColour(d.kind);
    w.distractors.push_back(d);
  }
  for (int i = 0; i < 8; ++i) {
    ObstacleBox b;
    b.id = "o" + std::to_string(i);
    b.kind = i % 2 ? ObstacleKind::kTree : ObstacleKind::kBox;
    const double sz = 2 + 4 * unit(rng), hgt = b.kind == ObstacleKind::kTree ? 6 + 6 * unit(rng) : 1 + 3 * unit(rng);
    b.size_m = {sz, b.kind == ObstacleKind::kTree ? sz : sz * 0.6, hgt};
    b.center_m = {pos(rng) * 1.3, pos(rng) * 1.3, hgt / 2};
    b.yaw_rad = unit(rng);
    w.obstacles.push_back(b);
  }
  return w;
}

constexpr int kJpegQuality = 90;

int RunCameraBench(const swarmbox::bench::Args& args) {
  auto af = LoadAirframe(std::string(SWARMBOX_TRIALS_DIR) + "/airframes/x500.yaml");
  auto field = LoadWorld(std::string(SWARMBOX_TRIALS_DIR) + "/worlds/open_field.yaml");
  if (!af || !field) {
    std::fprintf(stderr, "camera bench: %s\n", (!af ? af.error() : field.error()).ToString().c_str());
    return 1;
  }
  const CameraSpec spec = af->camera;
  const std::string png = args.Get("png", "");
  const int frames = args.quick ? 10 : 200;
  struct Scenario {
    const char* name;
    WorldConfig world;
  };
  std::vector<Scenario> scenarios;
  scenarios.push_back({"default", *field});
  scenarios.push_back({"grass_noon", ShowcaseWorld("grass_noon", Terrain{TerrainKind::kGrass, 0.0}, Lighting{12.0, 0.0})});
  scenarios.push_back({"rubble_dusk", ShowcaseWorld("rubble_dusk", Terrain{TerrainKind::kRubble, 0.0}, Lighting{18.0, 0.2})});
  scenarios.push_back({"mixed_water_overcast",
                       ShowcaseWorld("mixed_water_overcast", Terrain{TerrainKind::kMixed, 0.15}, Lighting{10.0, 0.8})});
  scenarios.push_back({"gravel_morning", ShowcaseWorld("gravel_morning", Terrain{TerrainKind::kGravel, 0.0}, Lighting{8.0, 0.0})});
  scenarios.push_back({"soil_water_noon", ShowcaseWorld("soil_water_noon", Terrain{TerrainKind::kSoil, 0.2}, Lighting{13.0, 0.4})});
  const double altitudes[] = {10, 20, 30, 40, 60};
  for (const Scenario& s : scenarios) {
    const double b0 = ThreadCpuS();
    GroundRenderer renderer(s.world);
    const double build_ms = (ThreadCpuS() - b0) * 1e3;
    std::mt19937_64 rng(3);
    std::uniform_real_distribution<double> unit(0, 1);
    CameraImage img;
    std::vector<VisiblePerson> people;
    double render_s = 0, copy_s = 0, encode_s = 0, decode_s = 0, jpeg_bytes = 0;
    std::vector<std::uint8_t> copy, jpeg;
    cv::Mat decoded;
    for (int i = 0; i < frames; ++i) {
      const double alt = altitudes[i % 5], yaw = unit(rng) * 2 * std::numbers::pi;
      // Views near a person (a tenth of the altitude off), as a searching drone's.
      double cx = 0, cy = 0;
      if (!s.world.victims.empty()) {
        const Victim& v = s.world.victims[static_cast<std::size_t>(i) % s.world.victims.size()];
        cx = v.x_m + (unit(rng) - 0.5) * 0.2 * alt, cy = v.y_m + (unit(rng) - 0.5) * 0.2 * alt;
      }
      const Pose pose{Vec3{cx, cy, alt}, Quat{std::cos(yaw / 2), 0, 0, std::sin(yaw / 2)}};
      const Vec3 rates = (i % 2) ? Vec3{0.8 * (unit(rng) - 0.5), 0.8 * (unit(rng) - 0.5), 0} : Vec3{};
      const double t0 = ThreadCpuS();
      renderer.Render(pose, rates, spec, static_cast<std::uint64_t>(i), &img, nullptr);
      render_s += ThreadCpuS() - t0;
      const cv::Mat frame(img.height_px, img.width_px, CV_8UC3, img.bgr.data());
      const double t1 = ThreadCpuS();
      copy.assign(img.bgr.begin(), img.bgr.end());
      const double t2 = ThreadCpuS();
      cv::imencode(".jpg", frame, jpeg, {cv::IMWRITE_JPEG_QUALITY, kJpegQuality});
      const double t3 = ThreadCpuS();
      decoded = cv::imdecode(jpeg, cv::IMREAD_COLOR);
      const double t4 = ThreadCpuS();
      copy_s += t2 - t1, encode_s += t3 - t2, decode_s += t4 - t3;
      jpeg_bytes += static_cast<double>(jpeg.size());
      if (!png.empty() && i < 5) {
        renderer.Render(pose, Vec3{}, spec, static_cast<std::uint64_t>(i), &img, &people);
        cv::Mat m(img.height_px, img.width_px, CV_8UC3, img.bgr.data());
        cv::Mat boxed = m.clone();
        for (const VisiblePerson& p : people) {
          cv::rectangle(boxed, p.box_px, p.visible_fraction >= 0.5 ? cv::Scalar(255, 0, 255) : cv::Scalar(255, 255, 0));
        }
        cv::imwrite(png + "/camera_" + s.name + "_" + std::to_string(static_cast<int>(alt)) + "m.png", m);
        cv::imwrite(png + "/camera_" + s.name + "_" + std::to_string(static_cast<int>(alt)) + "m_truth.png", boxed);
      }
    }
    std::printf("suite=camera scenario=%s width_px=%d height_px=%d frames=%d ms_per_frame=%.3f build_ms=%.1f copy_ms=%.3f "
                "jpeg_quality=%d jpeg_kb=%.1f jpeg_encode_ms=%.3f jpeg_decode_ms=%.3f\n",
                s.name, spec.width_px, spec.height_px, frames, render_s / frames * 1e3, build_ms, copy_s / frames * 1e3,
                kJpegQuality, jpeg_bytes / frames / 1e3, encode_s / frames * 1e3, decode_s / frames * 1e3);
    std::fflush(stdout);
  }
  return 0;
}

}  // namespace

SWARMBOX_BENCH_SUITE(camera, "downward camera: ms per frame (one core) per world look at the x500's camera",
                     RunCameraBench);
