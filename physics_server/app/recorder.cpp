#include "recorder.hpp"

#include <cmath>
#include <cstdio>
#include <utility>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "swarmbox/common/logfmt.hpp"
#include "swarmbox/record/foxglove_schemas.hpp"

namespace swarmbox::physics {
namespace {

std::int64_t PeriodNs(double hz) { return hz > 0 ? std::max<std::int64_t>(1, std::llround(1e9 / hz)) : 0; }
std::uint64_t Ns(std::int64_t t) { return t < 0 ? 0 : static_cast<std::uint64_t>(t); }

}  // namespace

Status ValidateRecordOptions(const RecordOptions& o) {
  if (!(o.rate_hz > 0) || !std::isfinite(o.rate_hz)) {
    return Error(ErrorCode::kInvalidArgument, "record rate_hz must be > 0");
  }
  if (!(o.camera_hz >= 0) || !std::isfinite(o.camera_hz)) {
    return Error(ErrorCode::kInvalidArgument, "record camera_hz must be >= 0");
  }
  if (!(o.camera_scale > 0 && o.camera_scale <= 1)) {
    return Error(ErrorCode::kInvalidArgument, "record camera_scale must be in (0, 1]");
  }
  if (o.jpeg_quality < 1 || o.jpeg_quality > 100) {
    return Error(ErrorCode::kInvalidArgument, "record jpeg_quality must be in [1, 100]");
  }
  if (o.queue_bytes == 0) return Error(ErrorCode::kInvalidArgument, "record queue_bytes must be > 0");
  return Ok{};
}

Recorder::Recorder(std::vector<record::Sink*> sinks, std::vector<std::string> drones, WorldConfig world,
                   RecordOptions options)
    : sinks_(std::move(sinks)),
      drones_(std::move(drones)),
      world_(std::move(world)),
      options_(std::move(options)),
      period_ns_(PeriodNs(options_.rate_hz)),
      camera_period_ns_(PeriodNs(options_.camera_hz)) {
  for (std::size_t i = 0; i < drones_.size(); ++i) drone_index_[drones_[i]] = i;
}

Result<std::unique_ptr<Recorder>> Recorder::Create(std::vector<record::Sink*> sinks, std::vector<std::string> drones,
                                                   WorldConfig world, RecordOptions options) {
  SWARMBOX_TRY(ValidateRecordOptions(options));
  std::unique_ptr<Recorder> r(new Recorder(std::move(sinks), std::move(drones), std::move(world), std::move(options)));
  SWARMBOX_TRY(r->AddChannels());
  r->writer_ = std::thread([p = r.get()] { p->WriterLoop(); });
  return r;
}

Recorder::~Recorder() {
  if (!finished_) {
    if (Status s = Finish(); !s) std::fprintf(stderr, "swarmbox-physics: recording: %s\n", s.error().ToString().c_str());
  }
}

int Recorder::Add(std::string topic) {
  topics_.push_back(std::move(topic));
  return static_cast<int>(topics_.size() - 1);
}

Status Recorder::AddChannels() {
  using namespace record;
  std::vector<std::string_view> schemas;
  auto add = [&](std::string topic, std::string_view schema) {
    schemas.push_back(schema);
    return Add(std::move(topic));
  };
  world_ch_ = add("/world", kSceneUpdate);
  tf_ch_ = add("/tf", kFrameTransforms);
  for (const std::string& d : drones_) {
    DroneChannels c{};
    const std::string base = "/drones/" + d + "/";
    c.truth = add(base + "truth", kDroneTruth);
    c.estimate = add(base + "estimate", kPoseInFrame);
    c.setpoint = add(base + "setpoint", kSetpoint);
    c.flocking = add(base + "flocking", kFlocking);
    c.raft = add(base + "raft", kRaftState);
    c.status = add(base + "status", kAgentStatus);
    c.camera = camera_period_ns_ > 0 ? add(base + "camera", kCompressedImage) : -1;
    per_drone_.push_back(c);
  }
  flocking_scene_ch_ = add("/flocking", kSceneUpdate);
  links_ch_ = add("/radio/links", kLinks);
  sectors_ch_ = add("/mission/sectors", kSectors);
  detections_ch_ = add("/detections", kDetection);
  log_ch_ = add("/log", kLog);
  ids_.assign(sinks_.size(), {});
  for (std::size_t s = 0; s < sinks_.size(); ++s) {
    for (std::size_t c = 0; c < topics_.size(); ++c) {
      auto id = sinks_[s]->AddChannel(MakeChannel(topics_[c], schemas[c]));
      if (!id) return id.error().Context("recording channel " + topics_[c]);
      ids_[s].push_back(*id);
    }
  }
  return Ok{};
}

void Recorder::Write(int channel, std::uint64_t t_ns, std::string json) {
  if (channel < 0) return;
  std::unique_lock<std::mutex> lock(mu_);
  // Back pressure, not loss: a writer that far behind holds the step up.
  cv_.wait(lock, [&] { return queued_bytes_ < options_.queue_bytes || stopping_; });
  if (stopping_) return;
  queued_bytes_ += json.size();
  ++messages_;
  bytes_ += json.size();
  queue_.push_back({channel, t_ns, std::move(json)});
  lock.unlock();
  cv_.notify_all();
}

void Recorder::WriterLoop() {
  std::deque<Pending> batch;
  while (true) {
    {
      std::unique_lock<std::mutex> lock(mu_);
      cv_.wait(lock, [&] { return !queue_.empty() || stopping_; });
      if (queue_.empty() && stopping_) return;
      batch.swap(queue_);
    }
    std::size_t done_bytes = 0;
    for (const Pending& p : batch) {
      for (std::size_t s = 0; s < sinks_.size(); ++s) {
        Status st = sinks_[s]->Write(ids_[s][static_cast<std::size_t>(p.channel)], p.t_ns, p.json);
        if (!st) {
          std::lock_guard<std::mutex> lock(mu_);
          if (!error_) error_ = st.error().Context("writing " + topics_[static_cast<std::size_t>(p.channel)]);
          ++errors_;
        }
      }
      done_bytes += p.json.size();
    }
    batch.clear();
    {
      std::lock_guard<std::mutex> lock(mu_);
      queued_bytes_ -= done_bytes;
    }
    cv_.notify_all();
  }
}

Status Recorder::Finish() {
  if (finished_) return Ok{};
  Drain();
  {
    // The writer empties the queue before it sees stopping_ with nothing left.
    std::unique_lock<std::mutex> lock(mu_);
    cv_.wait(lock, [&] { return queue_.empty(); });
    stopping_ = true;
  }
  cv_.notify_all();
  if (writer_.joinable()) writer_.join();
  finished_ = true;
  if (error_) {
    Error e = *error_;
    if (errors_ > 1) return e.Context(std::to_string(errors_) + " recording writes failed; the first");
    return e;
  }
  return Ok{};
}

void Recorder::Start() { Write(world_ch_, 0, WorldSceneJson(0, world_)); }

void Recorder::WriteTruth(std::uint64_t t_ns, std::span<const TruthPose> poses) {
  Write(tf_ch_, t_ns, TransformsJson(t_ns, poses));
  for (const TruthPose& p : poses) {
    auto it = drone_index_.find(std::string(p.drone));
    if (it == drone_index_.end()) continue;
    Write(per_drone_[it->second].truth, t_ns, TruthJson(t_ns, p));
  }
}

void Recorder::OnStep(const World& world) {
  const std::int64_t t_ns = world.time_ns();
  if (t_ns >= next_truth_ns_) {
    next_truth_ns_ = (t_ns / period_ns_ + 1) * period_ns_;
    poses_.resize(world.drone_count());
    for (std::size_t i = 0; i < world.drone_count(); ++i) {
      const DroneTruth truth = world.Truth(i);
      TruthPose& p = poses_[i];
      p.drone = world.drone_name(i);
      p.position_m = {truth.position_m.x, truth.position_m.y, truth.position_m.z};
      p.velocity_m_s = {truth.velocity_m_s.x, truth.velocity_m_s.y, truth.velocity_m_s.z};
      p.orientation_wxyz = {truth.attitude.w, truth.attitude.x, truth.attitude.y, truth.attitude.z};
    }
    WriteTruth(Ns(t_ns), poses_);
  }
  Drain();
}

void Recorder::OnCamera(std::size_t drone, const CameraImage& image) {
  if (drone >= per_drone_.size() || camera_period_ns_ <= 0) return;
  DroneChannels& c = per_drone_[drone];
  if (image.time_ns < c.next_camera_ns || image.width_px <= 0 || image.height_px <= 0) return;
  if (image.bgr.size() < static_cast<std::size_t>(image.width_px) * static_cast<std::size_t>(image.height_px) * 3) return;
  c.next_camera_ns = (image.time_ns / camera_period_ns_ + 1) * camera_period_ns_;
  const cv::Mat bgr(image.height_px, image.width_px, CV_8UC3, const_cast<std::uint8_t*>(image.bgr.data()));
  cv::Mat scaled;
  if (options_.camera_scale < 1.0) {
    cv::resize(bgr, scaled, cv::Size(), options_.camera_scale, options_.camera_scale, cv::INTER_AREA);
  } else {
    scaled = bgr;
  }
  std::vector<std::uint8_t> jpeg;
  if (!cv::imencode(".jpg", scaled, jpeg, {cv::IMWRITE_JPEG_QUALITY, options_.jpeg_quality})) return;
  Write(c.camera, Ns(image.time_ns), CompressedImageJson(Ns(image.time_ns), drones_[drone] + "/camera", jpeg));
}

void Recorder::OnTelemetry(const bus::Telemetry& telemetry) {
  std::lock_guard<std::mutex> lock(in_mu_);
  telemetry_in_.push_back(telemetry);
}

void Recorder::OnLogLine(std::string_view line) {
  std::lock_guard<std::mutex> lock(in_mu_);
  lines_in_.emplace_back(line);
}

void Recorder::Drain() {
  {
    std::lock_guard<std::mutex> lock(in_mu_);
    telemetry_scratch_.swap(telemetry_in_);
    lines_scratch_.swap(lines_in_);
  }
  for (const std::string& line : lines_scratch_) WriteLogLine(line);
  for (const bus::Telemetry& t : telemetry_scratch_) WriteTelemetry(t);
  telemetry_scratch_.clear();
  lines_scratch_.clear();
}

void Recorder::WriteLogLine(const std::string& line) {
  const LogfmtFields fields = ParseLogfmt(line);
  std::uint64_t t_ns = 0;
  if (auto t = FindField(fields, "t")) {
    char* end = nullptr;
    const double s = std::strtod(t->c_str(), &end);
    if (end != t->c_str()) t_ns = record::SecondsToNs(s);
  }
  const std::string node = FindField(fields, "node").value_or(options_.node);
  const std::string event = FindField(fields, "event").value_or("");
  Write(log_ch_, t_ns, LogJson(t_ns, node, event, line));
}

void Recorder::WriteTelemetry(const bus::Telemetry& t) {
  auto it = drone_index_.find(t.drone);
  if (it == drone_index_.end()) return;  // not a drone of this trial
  const DroneChannels& c = per_drone_[it->second];
  const std::uint64_t t_ns = Ns(t.sim_time_ns);
  for (const bus::Event& e : t.events) Write(log_ch_, Ns(e.sim_time_ns), EventLogJson(e));
  Write(c.estimate, t_ns, EstimateJson(t));
  Write(c.setpoint, t_ns, SetpointJson(t));
  if (HasFlocking(t)) {
    Write(c.flocking, t_ns, FlockingJson(t));
    Write(flocking_scene_ch_, t_ns, FlockingSceneJson(t));
  }
  if (!t.raft_role.empty()) Write(c.raft, t_ns, RaftJson(t));
  Write(c.status, t_ns, StatusJson(t));
  if (!t.links.empty()) Write(links_ch_, t_ns, LinksJson(t));
  if (!t.sectors.empty() && t.sectors != last_sectors_) {
    last_sectors_ = t.sectors;
    Write(sectors_ch_, t_ns, SectorsJson(t));
  }
  for (const bus::Detection& d : t.detections) Write(detections_ch_, Ns(d.sim_time_ns), DetectionJson(d));
}

}  // namespace swarmbox::physics
