// Drawing a RenderScene through a pinhole camera (ground_renderer.cpp), shared by the RGB camera
// (GroundRenderer) and the thermal camera (ThermalRenderer): the ground plane through one
// homography, the sky, then distractors, people with their cover, obstacles and trees in
// painter's order. The images take the scene's "colours" as they are: BGR for the RGB camera
// (CV_8UC3), kelvin for the thermal one (CV_32F).
#pragma once

#include <array>
#include <vector>

#include <opencv2/core.hpp>

#include "detail/render_scene.hpp"
#include "swarmbox/physics/camera_image.hpp"
#include "swarmbox/physics/ground_renderer.hpp"

namespace swarmbox::physics::detail {

// Projects world points through the optical camera.
struct Projector {
  std::array<double, 9> r_wc;  // optical -> world (columns: optical axes in world)
  Vec3 c;                      // camera centre, world
  CameraIntrinsics k;

  // False when p lies behind the camera (or within 5 cm of its plane).
  bool Project(const Vec3& p, cv::Point2f* out) const {
    const Vec3 d = p - c;
    const double xc = r_wc[0] * d.x + r_wc[3] * d.y + r_wc[6] * d.z;
    const double yc = r_wc[1] * d.x + r_wc[4] * d.y + r_wc[7] * d.z;
    const double zc = r_wc[2] * d.x + r_wc[5] * d.y + r_wc[8] * d.z;
    if (zc < 0.05) return false;
    *out = cv::Point2f(static_cast<float>(k.fx_px * xc / zc + k.cx_px),
                       static_cast<float>(k.fy_px * yc / zc + k.cy_px));
    return true;
  }
};

// A person in view: its figure and its unclipped box.
struct InView {
  const Figure* figure;
  cv::Rect box;
};

// The optical frame at `offset_m` in the body (looking along body -z, image up = body +x), and the
// projector of a camera there.
Pose OpticalPoseAt(const Pose& body, const Vec3& offset_m);
Projector MakeProjector(const Pose& body_pose, const Pose& optical_pose, const CameraIntrinsics& k);

// The ground texture into `img` (its size and type: the texture's channels); scene.underground
// when the camera is at or below the ground.
void DrawGround(const RenderScene& scene, const Projector& cam, cv::Mat& img);
// Pixels whose ray does not meet the ground, in `sky_colour`.
void DrawSky(const Projector& cam, const cv::Scalar& sky_colour, cv::Mat& img);
// Distractors, then people (with their cover), then obstacles and trees, lowest top first; each
// person's label (index + 1) into `labels` (when set) under everything drawn over it. Appends the
// people in view to `in_view` when `want_people`.
void DrawScene(const RenderScene& scene, const Projector& cam, cv::Mat& img, cv::Mat* labels,
               bool want_people, std::vector<InView>* in_view);
// What is left of each person in view: `labels` holds the drawn truth (DrawScene), `scratch` is a
// canvas for a figure's full area.
void ListVisible(const WorldConfig& config, const cv::Mat& labels, const Projector& cam,
                 const std::vector<InView>& in_view, cv::Mat* scratch, std::vector<VisiblePerson>* people);

}  // namespace swarmbox::physics::detail
