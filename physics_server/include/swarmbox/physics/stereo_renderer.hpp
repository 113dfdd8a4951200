// StereoRenderer: the OAK-D Pro's stereo pair (StereoSpec) over a StereoScene, ray-cast per pixel
// so that each view sees the world from its own pose (parallax: a point at depth Z is
// f * B / Z pixels further right in the left image than in the right one), with the IR dot
// projector's pattern drawn into both views and the true depth of every left pixel.
//
//   StereoRenderer renderer(&scene);            // draws the projector's dot pattern once
//   StereoFrame frame;
//   renderer.Render(body_pose, spec, /*noise_seed=*/k, &frame);
//   // frame.left / frame.right: CV_8U, rectified; frame.depth_truth_m: CV_32F (0: no surface)
//
// Image model, per pixel (one ray through its centre; 2 x 2 rays per pixel cost 4x and gave the
// same depth errors, BENCHMARKS.md "stereo"): radiance = albedo * (ambient + projector), where ambient is the cell's
// in-band irradiance (sun or shade, StereoScene) and projector = optical_power / (FOI solid angle
// * d^2) * pattern, d the distance from the projector, pattern the dot field (mean 1 over the
// field of illumination, 1/dot_fill on a dot, 0 between dots); nothing beyond range_m. Both
// views share one auto-exposure (the left view's mean radiance to level 100, gain capped), then
// Gaussian read noise (seeded, independent per view) and 8-bit clipping. So the dots fade with
// the inverse square of the distance and drown in sunlight: the ambient sets the exposure, and a
// dot a few per cent above it is a level or two, under the noise.
// Bodies (StereoScene::boxes: drones, payloads) are oriented boxes intersected per ray; a ray
// sees the nearer of its box hit and its height-field hit, the box's textured albedo lit by the
// ambient of the cell under the hit and by the projector as any surface; the truth depth is the
// nearer one. With no box in the scene the output is what it was without boxes, to the bit.
// Not modelled: the projector's own occlusion (a dot lands wherever the camera's ray does),
// shading by the surface normal, cast shadows within the height field, lens distortion.
//
// Pure: no clock; the same pose, spec and seed give the same images. Not thread-safe (scratch
// buffers); one renderer per thread. Keeps a pointer to the scene, which must outlive it.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include <opencv2/core.hpp>

#include "swarmbox/physics/stereo_scene.hpp"
#include "swarmbox/physics/stereo_spec.hpp"
#include "swarmbox/physics/types.hpp"

namespace swarmbox::physics {

struct StereoFrame {
  cv::Mat left;              // CV_8U, width_px x height_px, rectified
  cv::Mat right;             // CV_8U
  cv::Mat depth_truth_m;     // CV_32F: depth along the left optical axis; 0 where no surface
  double focal_px = 0;       // both cameras
  double cx_px = 0;
  double cy_px = 0;
  double baseline_m = 0;
  Pose left_optical_pose;    // optical frame (x right, y down, z forward) -> world
  double exposure_gain = 0;  // 8-bit levels per W/m^2 of (albedo-weighted) irradiance
};

class StereoRenderer {
 public:
  explicit StereoRenderer(const StereoScene* scene);

  void Render(const Pose& body_pose, const StereoSpec& spec, std::uint64_t noise_seed, StereoFrame* out);

 private:
  // Radiance of each pixel of one view (and its depth when `depth` is set).
  void CastView(const Vec3& centre, const double* r_wc, const StereoSpec& spec, const Vec3& projector,
                cv::Mat* radiance, cv::Mat* depth);
  // CastView's parts. The pattern's mean irradiance at 1 m from the projector [W/m^2] (0: no dots).
  double PatternIrradianceAt1m(const ProjectorSpec& p) const;
  // The dot pattern's irradiance at world point `hit` [W/m^2]: e1 (the mean at 1 m) times the
  // pattern there over the squared distance; 0 outside the field of illumination or beyond range_m.
  double PatternIrradiance(const Vec3& hit, const Vec3& projector, const double* r_wc, double e1,
                           double range_m) const;
  void EnsurePattern(const ProjectorSpec& p);
  // The scene's boxes in the form the per-ray test wants (world -> box rotation), per Render.
  void PrepareBoxes();
  // Each box's bounding sphere's extent in a view from `centre` (normalised image coordinates), so
  // that a ray tests only the boxes whose extent holds it.
  void BoundBoxesInView(const Vec3& centre, const double* r_wc);
  // The nearest box hit along centre + t * d (the ray of normalised image point (xn, yn)) before
  // t_surface_m, and its textured albedo there; t_surface_m (and *albedo untouched) without one.
  double NearestBoxHit(const Vec3& centre, const Vec3& d, double xn, double yn, double t_surface_m,
                       float* albedo) const;

  struct RayBox {
    const SceneBox* box;
    std::array<double, 9> world_to_box;  // row-major
    double xn_min = 0, xn_max = 0, yn_min = 0, yn_max = 0;  // in the current view (BoundBoxesInView)
  };

  const StereoScene* scene_;
  cv::Mat pattern_;          // CV_32F dot field over tan-angle space, mean 1
  double pattern_res_ = 0;   // tan units per pattern pixel
  double pattern_tan_h_ = 0, pattern_tan_v_ = 0;
  int pattern_dots_ = -1;
  double pattern_fill_ = -1;
  cv::Mat radiance_l_, radiance_r_, noise_;
  std::vector<RayBox> ray_boxes_;  // the scene's boxes, per Render
  cv::Mat tile_max_;         // the scene's highest cell per tile (the march's skip test), per Render
};

}  // namespace swarmbox::physics
