#include "swarmbox/physics/thermal_renderer.hpp"

#include <cmath>

#include <opencv2/imgproc.hpp>

#include "detail/render_scene.hpp"
#include "detail/scene_draw.hpp"
#include "detail/thermal_scene.hpp"

namespace swarmbox::physics {

CameraIntrinsics IntrinsicsFor(const airframe::ThermalSpec& spec) {
  CameraIntrinsics k;
  k.fx_px = spec.FocalPx();
  k.fy_px = k.fx_px;
  k.cx_px = spec.width_px / 2.0;
  k.cy_px = spec.height_px / 2.0;
  return k;
}

ThermalRenderer::ThermalRenderer(const WorldConfig& config) : config_(&config) {
  const detail::RenderScene rgb = detail::BuildScene(config);
  scene_ = std::make_unique<detail::RenderScene>(detail::ThermalSceneOf(rgb, config));
  air_k_ = detail::ThermalEnvOf(config, rgb.light).air_k;
}

ThermalRenderer::~ThermalRenderer() = default;

void ThermalRenderer::Render(const Pose& body_pose, const airframe::ThermalSpec& spec,
                             std::uint64_t noise_seed, ThermalImage* out,
                             std::vector<VisiblePerson>* people) {
  if (people != nullptr) people->clear();
  const detail::RenderScene& scene = *scene_;
  const int w = spec.width_px, h = spec.height_px;
  out->width_px = w;
  out->height_px = h;
  out->intrinsics = IntrinsicsFor(spec);
  out->camera_pose = detail::OpticalPoseAt(body_pose, spec.offset_m);
  const detail::Projector cam = detail::MakeProjector(body_pose, out->camera_pose, out->intrinsics);

  img_.create(h, w, CV_32F);
  detail::DrawGround(scene, cam, img_);
  detail::DrawSky(cam, scene.sky, img_);
  cv::Mat* labels = nullptr;
  if (people != nullptr) {
    labels_.create(h, w, CV_16U);
    labels_.setTo(0);
    labels = &labels_;
  }
  std::vector<detail::InView> in_view;
  detail::DrawScene(scene, cam, img_, labels, people != nullptr, &in_view);
  if (people != nullptr) detail::ListVisible(*config_, labels_, cam, in_view, &scratch_, people);

  out->centikelvin.resize(static_cast<std::size_t>(w) * static_cast<std::size_t>(h));
  cv::Mat dst(h, w, CV_16U, out->centikelvin.data());
  ApplySensor(spec, noise_seed, &dst);
}

// The optics' blur, the frame's offset and the temporal noise, then 0.01 K counts into `dst`.
void ThermalRenderer::ApplySensor(const airframe::ThermalSpec& spec, std::uint64_t noise_seed, cv::Mat* dst) {
  if (spec.psf_sigma_px > 0) {
    cv::GaussianBlur(img_, blurred_, cv::Size(), spec.psf_sigma_px, spec.psf_sigma_px, cv::BORDER_REFLECT101);
  } else {
    img_.copyTo(blurred_);
  }
  cv::RNG rng(noise_seed);
  const double offset = spec.offset_std_k > 0 ? spec.offset_std_k * rng.gaussian(1.0) : 0.0;
  if (spec.netd_k > 0) {
    noise_.create(img_.rows, img_.cols, CV_32F);
    rng.fill(noise_, cv::RNG::NORMAL, offset, spec.netd_k);
    blurred_ += noise_;
  } else if (offset != 0) {
    blurred_ += cv::Scalar(offset);
  }
  blurred_.convertTo(*dst, CV_16U, kThermalCountsPerK);
}

}  // namespace swarmbox::physics
