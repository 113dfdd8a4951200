// The downward camera: victims land where the pinhole model puts them.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <vector>

#include "swarmbox/physics/ground_renderer.hpp"

#include "test_util.hpp"

namespace swarmbox::physics {
namespace {

using testing::CalmWorld;
using testing::LoadShippedAirframe;
using testing::MakeWorld;
using testing::Spawn;

struct Centroid {
  double u = 0, v = 0;
  int count = 0;
};

// Victim pixels: red channel high, blue low (grass and soil have R < 130); the head is the
// brighter (G > 170) part.
void FindVictim(const CameraImage& img, Centroid* body, Centroid* head) {
  for (int y = 0; y < img.height_px; ++y) {
    for (int x = 0; x < img.width_px; ++x) {
      const std::size_t i = (static_cast<std::size_t>(y) * static_cast<std::size_t>(img.width_px) + static_cast<std::size_t>(x)) * 3;
      const int b = img.bgr[i], g = img.bgr[i + 1], r = img.bgr[i + 2];
      if (r < 215 || b > 90) continue;
      Centroid* c = g > 170 ? head : body;
      c->u += x;  // OpenCV convention: pixel (x, y) is centred on coordinate (x, y)
      c->v += y;
      ++c->count;
    }
  }
  if (body->count) body->u /= body->count, body->v /= body->count;
  if (head->count) head->u /= head->count, head->v /= head->count;
}

// Independent pinhole model: camera at `cam` (world), yaw `yaw` of a level drone; optical frame
// x = body right (-y_b), y = body back (-x_b), z = down.
void Project(const Vec3& p, const Vec3& cam, double yaw, const CameraIntrinsics& k, double* u, double* v) {
  const Vec3 d = p - cam;
  const double xb = std::cos(yaw) * d.x + std::sin(yaw) * d.y;
  const double yb = -std::sin(yaw) * d.x + std::cos(yaw) * d.y;
  const double zb = d.z;
  *u = k.fx_px * (-yb) / (-zb) + k.cx_px;
  *v = k.fy_px * (-xb) / (-zb) + k.cy_px;
}

void CheckVictimPixel(double yaw, double victim_heading) {
  WorldConfig config = CalmWorld();
  config.victims.push_back({.id = "v1", .x_m = 2.0, .y_m = 1.0, .heading_rad = victim_heading});
  auto world = MakeWorld(config, 5);
  const Airframe af = LoadShippedAirframe("x500");
  const auto d = Spawn(*world, testing::MakeSpawn("d", af, Vec3{0, 0, 8}, yaw));
  world->SetPinned(d, true);
  CameraImage img;
  world->RenderCamera(d, &img);
  ASSERT_EQ(img.width_px, af.camera.width_px);
  ASSERT_EQ(img.height_px, af.camera.height_px);
  ASSERT_EQ(img.bgr.size(), static_cast<std::size_t>(af.camera.width_px * af.camera.height_px * 3));
  EXPECT_NEAR(img.intrinsics.fx_px, af.camera.width_px / 2.0 / std::tan(af.camera.hfov_rad / 2), 1e-9);
  EXPECT_DOUBLE_EQ(img.intrinsics.cx_px, af.camera.width_px / 2.0);

  const Vec3 cam = world->Truth(d).position_m + Vec3{0, 0, af.camera.offset_m.z};
  EXPECT_NEAR(img.camera_pose.position_m.z, cam.z, 1e-9);
  const Vec3 dir{std::cos(victim_heading), std::sin(victim_heading), 0};
  double bu, bv, hu, hv;
  Project(Vec3{2, 1, 0} + dir * -0.15, cam, yaw, img.intrinsics, &bu, &bv);  // body ellipse centre
  Project(Vec3{2, 1, 0} + dir * 0.7, cam, yaw, img.intrinsics, &hu, &hv);    // head centre
  Centroid body, head;
  FindVictim(img, &body, &head);
  ASSERT_GT(body.count, 200);  // 0.54 m^2 at ~8 m: ~ 460 px
  ASSERT_GT(head.count, 15);   // 0.045 m^2: ~ 38 px
  // Rasterised polygons of ~20 vertices and pixel noise: centroids within 0.5 px (body) and
  // 1 px (the small head).
  EXPECT_NEAR(body.u, bu, 0.5);
  EXPECT_NEAR(body.v, bv, 0.5);
  EXPECT_NEAR(head.u, hu, 1.0);
  EXPECT_NEAR(head.v, hv, 1.0);
}

TEST(Camera, VictimAppearsWhereThePinholeModelPredicts) { CheckVictimPixel(0.0, 0.0); }

TEST(Camera, ImageTurnsWithTheDrone) { CheckVictimPixel(std::numbers::pi / 2, 2.0); }

TEST(Camera, RenderingIsDeterministicAndNoisy) {
  auto world = MakeWorld(CalmWorld(), 9);
  const auto d = Spawn(*world, testing::MakeSpawn("d", LoadShippedAirframe("x500"), Vec3{0, 0, 20}));
  world->SetPinned(d, true);
  CameraImage a, b;
  world->RenderCamera(d, &a);
  world->RenderCamera(d, &b);
  EXPECT_EQ(a.bgr, b.bgr);  // same step, same seed
  world->Step();
  world->RenderCamera(d, &b);
  EXPECT_NE(a.bgr, b.bgr);  // next step: fresh noise on the same view
  std::size_t differing = 0;
  for (std::size_t i = 0; i < a.bgr.size(); ++i) differing += a.bgr[i] != b.bgr[i] ? 1u : 0u;
  EXPECT_GT(differing, a.bgr.size() / 2);  // noise std 4 levels changes most pixels
}

TEST(Camera, PixelNoiseMatchesItsConfiguration) {
  auto world = MakeWorld(CalmWorld(), 21);
  const auto d = Spawn(*world, testing::MakeSpawn("d", LoadShippedAirframe("x500"), Vec3{0, 0, 20}));
  world->SetPinned(d, true);  // the same view twice, two independent noise draws
  CameraImage a, b;
  world->RenderCamera(d, &a);
  world->Step();
  world->RenderCamera(d, &b);
  double sum = 0, sum2 = 0;
  for (std::size_t i = 0; i < a.bgr.size(); ++i) {
    const double diff = static_cast<double>(a.bgr[i]) - static_cast<double>(b.bgr[i]);
    sum += diff;
    sum2 += diff * diff;
  }
  const double n = static_cast<double>(a.bgr.size());
  const double std = std::sqrt(sum2 / n - (sum / n) * (sum / n));
  // The difference of two independent N(0, 4^2) draws has std 4 sqrt(2) = 5.66 (rounding to whole
  // levels adds < 1%); 230 400 samples give a 0.15% standard error: allow 5%.
  const double expected = LoadShippedAirframe("x500").camera.noise_std * std::sqrt(2.0);
  EXPECT_NEAR(std, expected, 0.05 * expected);
  EXPECT_NEAR(sum / n, 0.0, 0.05);
}

TEST(Camera, ObstacleTopsAreSeenFromAbove) {
  WorldConfig config = CalmWorld();
  config.obstacles.push_back({.id = "block", .center_m = {0, 0, 2}, .size_m = {4, 4, 4}, .yaw_rad = 0});
  auto world = MakeWorld(config);
  const auto d = Spawn(*world, testing::MakeSpawn("d", LoadShippedAirframe("x500"), Vec3{0, 0, 15}));
  world->SetPinned(d, true);
  CameraImage img;
  world->RenderCamera(d, &img);
  // The image centre looks straight down onto the block's top (grey ~155, noise 4).
  const std::size_t c = (static_cast<std::size_t>(img.height_px / 2 * img.width_px + img.width_px / 2)) * 3u;
  EXPECT_NEAR(img.bgr[c + 2], 160, 20);
  EXPECT_NEAR(img.bgr[c + 1], 155, 20);
  EXPECT_NEAR(img.bgr[c], 150, 20);
}

// The truth the renderer reports matches what it drew: the box holds every figure pixel, tightly,
// and the visible fraction falls as an obstacle or the image border hides the figure.
TEST(Camera, TruthBoxesMatchDrawnPeople) {
  WorldConfig config = CalmWorld();
  config.victims.push_back({.id = "seen", .x_m = 2.0, .y_m = 1.0, .heading_rad = 0.3});
  config.victims.push_back({.id = "far", .x_m = 80.0, .y_m = 80.0, .heading_rad = 0.0});
  GroundRenderer renderer(config);
  CameraSpec spec;  // 320 x 240
  spec.noise_std = 0;
  const Pose pose{Vec3{0, 0, 10}, Quat{}};
  CameraImage img;
  std::vector<VisiblePerson> people;
  renderer.Render(pose, spec, 1, &img, &people);
  ASSERT_EQ(people.size(), 1u);  // "far" is out of view
  EXPECT_EQ(people[0].id, "seen");
  EXPECT_NEAR(people[0].visible_fraction, 1.0, 1e-9);
  // Figure pixels (R high, B low): all inside the box, touching each of its sides.
  int x0 = img.width_px, y0 = img.height_px, x1 = -1, y1 = -1;
  for (int y = 0; y < img.height_px; ++y) {
    for (int x = 0; x < img.width_px; ++x) {
      const std::size_t i = (static_cast<std::size_t>(y) * static_cast<std::size_t>(img.width_px) + static_cast<std::size_t>(x)) * 3;
      if (img.bgr[i + 2] < 215 || img.bgr[i] > 90) continue;
      x0 = std::min(x0, x), y0 = std::min(y0, y), x1 = std::max(x1, x), y1 = std::max(y1, y);
    }
  }
  ASSERT_GE(x1, 0);
  const cv::Rect box = people[0].box_px;
  EXPECT_GE(x0, box.x);
  EXPECT_GE(y0, box.y);
  EXPECT_LE(x1, box.x + box.width - 1);
  EXPECT_LE(y1, box.y + box.height - 1);
  EXPECT_LE(x0 - box.x, 1);
  EXPECT_LE(y0 - box.y, 1);
  EXPECT_LE(box.x + box.width - 1 - x1, 1);
  EXPECT_LE(box.y + box.height - 1 - y1, 1);
}

TEST(Camera, TruthVisibleFractionFallsUnderObstaclesAndAtTheBorder) {
  WorldConfig config = CalmWorld();
  // A lying figure along x (heading 0) centred at the origin; a box hides its feet end.
  config.victims.push_back({.id = "v", .x_m = 0.0, .y_m = 0.0, .heading_rad = 0.0});
  config.obstacles.push_back({.id = "slab", .center_m = {-0.55, 0, 0.05}, .size_m = {0.8, 2, 0.1}, .yaw_rad = 0});
  GroundRenderer renderer(config);
  CameraSpec spec;
  spec.noise_std = 0;
  CameraImage img;
  std::vector<VisiblePerson> people;
  renderer.Render(Pose{Vec3{0, 0, 8}, Quat{}}, spec, 1, &img, &people);
  ASSERT_EQ(people.size(), 1u);
  EXPECT_GT(people[0].visible_fraction, 0.3);
  EXPECT_LT(people[0].visible_fraction, 0.8);

  // No obstacle, the camera moved half an image height east: image up is body +x (east), so the
  // bottom image border now runs through the figure's centre.
  config.obstacles.clear();
  GroundRenderer clear(config);
  const double fx = 160.0 / std::tan(0.6);
  const double half_height_m = 120.0 / fx * 8.0;  // ground half-height of the image at 8 m
  clear.Render(Pose{Vec3{half_height_m, 0, 8}, Quat{}}, spec, 1, &img, &people);
  ASSERT_EQ(people.size(), 1u);
  EXPECT_GT(people[0].visible_fraction, 0.2);
  EXPECT_LT(people[0].visible_fraction, 0.8);
  const cv::Rect box = people[0].box_px;
  EXPECT_EQ(box.y + box.height, img.height_px);  // clipped at the bottom edge (world -x of the camera)
  EXPECT_GE(box.y, 0);
}

TEST(Camera, DueAtItsRate) {
  auto world = MakeWorld(CalmWorld());
  const auto d = Spawn(*world, testing::MakeSpawn("d", LoadShippedAirframe("x500")));
  int due = 0;
  for (int k = 0; k < 250; ++k) {
    if (world->CameraDue(d)) ++due;
    world->Step();
  }
  EXPECT_EQ(due, 5);  // 5 Hz over 1 s
}

}  // namespace
}  // namespace swarmbox::physics
