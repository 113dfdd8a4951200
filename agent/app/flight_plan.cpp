#include "flight_plan.hpp"

#include <cmath>
#include <cstdlib>

namespace swarmbox::agent {
namespace {

constexpr const char* kForms =
    "takeoff:H, hover:S, goto:X:Y:Z[:YAW_DEG], velocity:VX:VY:VZ:S, land";

std::vector<std::string> Split(std::string_view text, char sep) {
  std::vector<std::string> out;
  std::size_t start = 0;
  while (true) {
    const std::size_t pos = text.find(sep, start);
    out.emplace_back(text.substr(start, pos == std::string_view::npos ? std::string_view::npos : pos - start));
    if (pos == std::string_view::npos) break;
    start = pos + 1;
  }
  return out;
}

bool Number(const std::string& s, double* out) {
  if (s.empty()) return false;
  char* end = nullptr;
  *out = std::strtod(s.c_str(), &end);
  return end != nullptr && *end == '\0' && std::isfinite(*out);
}

}  // namespace

Result<FlightPlan> FlightPlan::Parse(std::string_view text) {
  FlightPlan plan;
  if (text.empty()) return Error(ErrorCode::kInvalidArgument, std::string("empty plan; steps: ") + kForms);
  for (const std::string& item : Split(text, ',')) {
    const std::vector<std::string> f = Split(item, ':');
    auto bad = [&](const std::string& why) {
      return Error(ErrorCode::kInvalidArgument, "plan step '" + item + "': " + why + " (steps: " + kForms + ")");
    };
    Step st;
    st.text = item;
    std::vector<double> v;
    for (std::size_t i = 1; i < f.size(); ++i) {
      double x = 0.0;
      if (!Number(f[i], &x)) return bad("'" + f[i] + "' is not a number");
      v.push_back(x);
    }
    const std::string& k = f[0];
    if (k == "takeoff") {
      if (v.size() != 1 || !(v[0] > 0.0)) return bad("needs one height > 0 [m]");
      st.kind = Step::Kind::kTakeoff;
      st.value = flight::Vec3(0.0, 0.0, v[0]);
    } else if (k == "hover") {
      if (v.size() != 1 || v[0] < 0.0) return bad("needs one duration >= 0 [s]");
      st.kind = Step::Kind::kHover;
      st.duration_s = v[0];
    } else if (k == "goto") {
      if (v.size() != 3 && v.size() != 4) return bad("needs X:Y:Z [m] and an optional yaw [deg]");
      st.kind = Step::Kind::kGoto;
      st.value = flight::Vec3(v[0], v[1], v[2]);
      st.yaw_rad = v.size() == 4 ? v[3] * flight::kPi / 180.0 : std::nan("");
    } else if (k == "velocity") {
      if (v.size() != 4 || v[3] < 0.0) return bad("needs VX:VY:VZ [m/s] and a duration [s]");
      st.kind = Step::Kind::kVelocity;
      st.value = flight::Vec3(v[0], v[1], v[2]);
      st.duration_s = v[3];
      st.yaw_rad = std::nan("");
    } else if (k == "land") {
      if (!v.empty()) return bad("takes no arguments");
      st.kind = Step::Kind::kLand;
    } else {
      return bad("unknown step '" + k + "'");
    }
    plan.steps_.push_back(st);
  }
  return plan;
}

std::string_view FlightPlan::current() const {
  return finished() ? std::string_view("done") : std::string_view(steps_[index_].text);
}

std::optional<flight::Setpoint> FlightPlan::Tick(const FlightStatus& st) {
  using flight::FlightMode;
  using flight::Setpoint;
  if (finished()) return std::nullopt;
  const Step& step = steps_[index_];
  if (!started_) {
    // Take-off only from the ground, after the pre-flight wait.
    if (step.kind == Step::Kind::kTakeoff) {
      if (st.mode != FlightMode::kIdle && st.mode != FlightMode::kLanded) {
        ready_since_s_ = -1.0;
        return std::nullopt;
      }
      if (ready_since_s_ < 0.0) ready_since_s_ = st.t_s;
      if (st.t_s - ready_since_s_ < preflight_s_) return std::nullopt;
    }
    started_ = true;
    step_start_s_ = st.t_s;
    switch (step.kind) {
      case Step::Kind::kTakeoff: return Setpoint::Takeoff(step.value.z());
      case Step::Kind::kHover: return Setpoint::Hold();
      case Step::Kind::kGoto: return Setpoint::Position(step.value, step.yaw_rad);
      case Step::Kind::kVelocity: return Setpoint::Velocity(step.value, step.yaw_rad);
      case Step::Kind::kLand: return Setpoint::Land();
    }
    return std::nullopt;
  }
  bool done = false;
  std::optional<Setpoint> out;
  switch (step.kind) {
    case Step::Kind::kTakeoff: done = st.hover || st.mode == FlightMode::kHold; break;
    case Step::Kind::kHover: done = st.t_s - step_start_s_ >= step.duration_s; break;
    case Step::Kind::kGoto: done = st.arrived; break;
    case Step::Kind::kVelocity:
      done = st.t_s - step_start_s_ >= step.duration_s;
      if (done) out = Setpoint::Hold();
      break;
    case Step::Kind::kLand: done = st.landed || st.mode == FlightMode::kLanded; break;
  }
  if (st.rejected) done = true;  // the controller refused it: move on rather than hang
  if (done) {
    ++index_;
    started_ = false;
  }
  return out;
}

}  // namespace swarmbox::agent
