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

Error BadStep(const std::string& item, const std::string& why) {
  return Error(ErrorCode::kInvalidArgument, "plan step '" + item + "': " + why + " (steps: " + kForms + ")");
}

// The step's kind from its name and numbers; "" or why they do not fit it.
std::string FillStep(const std::string& k, const std::vector<double>& v, FlightPlan::Step* st) {
  using Kind = FlightPlan::Step::Kind;
  if (k == "takeoff") {
    if (v.size() != 1 || !(v[0] > 0.0)) return "needs one height > 0 [m]";
    st->kind = Kind::kTakeoff;
    st->value = flight::Vec3(0.0, 0.0, v[0]);
  } else if (k == "hover") {
    if (v.size() != 1 || v[0] < 0.0) return "needs one duration >= 0 [s]";
    st->kind = Kind::kHover;
    st->duration_s = v[0];
  } else if (k == "goto") {
    if (v.size() != 3 && v.size() != 4) return "needs X:Y:Z [m] and an optional yaw [deg]";
    st->kind = Kind::kGoto;
    st->value = flight::Vec3(v[0], v[1], v[2]);
    st->yaw_rad = v.size() == 4 ? v[3] * flight::kPi / 180.0 : std::nan("");
  } else if (k == "velocity") {
    if (v.size() != 4 || v[3] < 0.0) return "needs VX:VY:VZ [m/s] and a duration [s]";
    st->kind = Kind::kVelocity;
    st->value = flight::Vec3(v[0], v[1], v[2]);
    st->duration_s = v[3];
    st->yaw_rad = std::nan("");
  } else if (k == "land") {
    if (!v.empty()) return "takes no arguments";
    st->kind = Kind::kLand;
  } else {
    return "unknown step '" + k + "'";
  }
  return "";
}

// One step "name:number:...".
Result<FlightPlan::Step> ParseStep(const std::string& item) {
  const std::vector<std::string> f = Split(item, ':');
  FlightPlan::Step st;
  st.text = item;
  std::vector<double> v;
  for (std::size_t i = 1; i < f.size(); ++i) {
    double x = 0.0;
    if (!Number(f[i], &x)) return BadStep(item, "'" + f[i] + "' is not a number");
    v.push_back(x);
  }
  if (const std::string why = FillStep(f[0], v, &st); !why.empty()) return BadStep(item, why);
  return st;
}

// What the flight stack is told when the step starts.
std::optional<flight::Setpoint> SetpointFor(const FlightPlan::Step& step) {
  using flight::Setpoint;
  using Kind = FlightPlan::Step::Kind;
  switch (step.kind) {
    case Kind::kTakeoff:
      return Setpoint::Takeoff(step.value.z());
    case Kind::kHover:
      return Setpoint::Hold();
    case Kind::kGoto:
      return Setpoint::Position(step.value, step.yaw_rad);
    case Kind::kVelocity:
      return Setpoint::Velocity(step.value, step.yaw_rad);
    case Kind::kLand:
      return Setpoint::Land();
  }
  return std::nullopt;
}

}  // namespace

Result<FlightPlan> FlightPlan::Parse(std::string_view text) {
  FlightPlan plan;
  if (text.empty()) return Error(ErrorCode::kInvalidArgument, std::string("empty plan; steps: ") + kForms);
  for (const std::string& item : Split(text, ',')) {
    auto st = ParseStep(item);
    if (!st) return st.error();
    plan.steps_.push_back(std::move(*st));
  }
  return plan;
}

std::string_view FlightPlan::current() const {
  return finished() ? std::string_view("done") : std::string_view(steps_[index_].text);
}

bool FlightPlan::ReadyToStart(const Step& step, const FlightStatus& st) {
  // Take-off only from the ground, after the pre-flight wait.
  if (step.kind != Step::Kind::kTakeoff) return true;
  if (st.mode != flight::FlightMode::kIdle && st.mode != flight::FlightMode::kLanded) {
    ready_since_s_ = -1.0;
    return false;
  }
  if (ready_since_s_ < 0.0) ready_since_s_ = st.t_s;
  return st.t_s - ready_since_s_ >= preflight_s_;
}

bool FlightPlan::StepDone(const Step& step, const FlightStatus& st,
                          std::optional<flight::Setpoint>* out) const {
  using flight::FlightMode;
  bool done = false;
  switch (step.kind) {
    case Step::Kind::kTakeoff: done = st.hover || st.mode == FlightMode::kHold; break;
    case Step::Kind::kHover: done = st.t_s - step_start_s_ >= step.duration_s; break;
    case Step::Kind::kGoto: done = st.arrived; break;
    case Step::Kind::kVelocity:
      done = st.t_s - step_start_s_ >= step.duration_s;
      if (done) *out = flight::Setpoint::Hold();
      break;
    case Step::Kind::kLand: done = st.landed || st.mode == FlightMode::kLanded; break;
  }
  return done || st.rejected;  // the controller refused it: move on rather than hang
}

std::optional<flight::Setpoint> FlightPlan::Tick(const FlightStatus& st) {
  if (finished()) return std::nullopt;
  const Step& step = steps_[index_];
  if (!started_) {
    if (!ReadyToStart(step, st)) return std::nullopt;
    started_ = true;
    step_start_s_ = st.t_s;
    return SetpointFor(step);
  }
  std::optional<flight::Setpoint> out;
  if (StepDone(step, st, &out)) {
    ++index_;
    started_ = false;
  }
  return out;
}

}  // namespace swarmbox::agent
