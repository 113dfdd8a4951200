// The schemas are built from a few shared pieces (time, Vector3, Quaternion, Pose, Color, ...) so
// the same type reads the same wherever it appears, as in Foxglove's published schemas (field names
// and meanings from https://docs.foxglove.dev/docs/visualization/message-schemas).
#include "swarmbox/record/foxglove_schemas.hpp"

#include <cmath>
#include <map>
#include <utility>

namespace swarmbox::record {

namespace {

using Props = std::vector<std::pair<std::string, std::string>>;

std::string Q(std::string_view s) { return yaml::JsonQuote(s); }

std::string Described(std::string body, std::string_view description) {
  if (description.empty()) return "{" + body + "}";
  return "{" + body + ",\"description\":" + Q(description) + "}";
}

std::string Obj(std::string_view title, std::string_view description, const Props& props) {
  std::string body;
  if (!title.empty()) body += "\"title\":" + Q(title) + ",";
  body += "\"type\":\"object\",\"properties\":{";
  for (std::size_t i = 0; i < props.size(); ++i) {
    if (i > 0) body += ",";
    body += Q(props[i].first) + ":" + props[i].second;
  }
  body += "}";
  return Described(std::move(body), description);
}

std::string Num(std::string_view d) { return Described("\"type\":\"number\"", d); }
std::string Int(std::string_view d) { return Described("\"type\":\"integer\"", d); }
std::string UInt(std::string_view d) { return Described("\"type\":\"integer\",\"minimum\":0", d); }
std::string Str(std::string_view d) { return Described("\"type\":\"string\"", d); }
std::string Bool(std::string_view d) { return Described("\"type\":\"boolean\"", d); }
std::string Arr(const std::string& items, std::string_view d) {
  return Described("\"type\":\"array\",\"items\":" + items, d);
}
std::string NullableNum() { return "{\"type\":[\"number\",\"null\"]}"; }
// A fixed-length array of `n` items.
std::string Tuple(const std::string& item, int n, std::string_view d) {
  const std::string len = std::to_string(n);
  return Described("\"type\":\"array\",\"items\":" + item + ",\"minItems\":" + len + ",\"maxItems\":" + len, d);
}
// One of several integer constants: {"title": name, "const": value}.
std::string Enum(std::string_view title, const std::vector<std::pair<std::string, int>>& values,
                 std::string_view d) {
  std::string body = "\"title\":" + Q(title) + ",\"oneOf\":[";
  for (std::size_t i = 0; i < values.size(); ++i) {
    if (i > 0) body += ",";
    body += "{\"title\":" + Q(values[i].first) + ",\"const\":" + std::to_string(values[i].second) + "}";
  }
  return Described(body + "]", d);
}
std::string StrEnum(const std::vector<std::string>& values, std::string_view d) {
  std::string body = "\"type\":\"string\",\"enum\":[";
  for (std::size_t i = 0; i < values.size(); ++i) body += (i > 0 ? "," : "") + Q(values[i]);
  return Described(body + "]", d);
}

std::string Time(std::string_view d) {
  return Obj("time", d, {{"sec", UInt("")}, {"nsec", Described("\"type\":\"integer\",\"minimum\":0,\"maximum\":999999999", "")}});
}
std::string Duration(std::string_view d) {
  return Obj("duration", d, {{"sec", Int("")}, {"nsec", Described("\"type\":\"integer\",\"minimum\":0,\"maximum\":999999999", "")}});
}
std::string Vector3(std::string_view d) {
  return Obj("foxglove.Vector3", d, {{"x", Num("x coordinate length")}, {"y", Num("y coordinate length")},
                                     {"z", Num("z coordinate length")}});
}
std::string Point3() {
  return Obj("foxglove.Point3", "A point in 3D space", {{"x", Num("x coordinate position")},
                                                       {"y", Num("y coordinate position")},
                                                       {"z", Num("z coordinate position")}});
}
std::string Quaternion(std::string_view d) {
  return Obj("foxglove.Quaternion", d, {{"x", Num("x value")}, {"y", Num("y value")}, {"z", Num("z value")},
                                        {"w", Num("w value")}});
}
std::string Pose(std::string_view d) {
  return Obj("foxglove.Pose", d, {{"position", Vector3("Point denoting position in 3D space")},
                                  {"orientation", Quaternion("Quaternion denoting orientation in 3D space")}});
}
std::string Color(std::string_view d) {
  return Obj("foxglove.Color", d, {{"r", Num("Red value between 0 and 1")}, {"g", Num("Green value between 0 and 1")},
                                   {"b", Num("Blue value between 0 and 1")}, {"a", Num("Alpha value between 0 and 1")}});
}

std::string ArrowPrimitive() {
  return Obj("foxglove.ArrowPrimitive", "A primitive representing an arrow",
      {{"pose", Pose("Position of the arrow's tail and orientation of the arrow (identity: +x)")},
       {"shaft_length", Num("Length of the arrow shaft")}, {"shaft_diameter", Num("Diameter of the arrow shaft")},
       {"head_length", Num("Length of the arrow head")}, {"head_diameter", Num("Diameter of the arrow head")},
       {"color", Color("Color of the arrow")}});
}

// A cube or a sphere: a pose, a size and a colour.
std::string SizedPrimitive(std::string_view title, std::string_view what) {
  return Obj(title, std::string("A primitive representing a ") + std::string(what),
             {{"pose", Pose("Position of the center and orientation")},
              {"size", Vector3("Size along each axis")}, {"color", Color("Color")}});
}

std::string CylinderPrimitive() {
  return Obj("foxglove.CylinderPrimitive", "A primitive representing a cylinder, elliptic cylinder, or truncated cone",
      {{"pose", Pose("Position of the center and orientation")}, {"size", Vector3("Size of the bounding box")},
       {"bottom_scale", Num("0-1, ratio of the diameter of the bottom face to the bounding box")},
       {"top_scale", Num("0-1, ratio of the diameter of the top face to the bounding box")},
       {"color", Color("Color")}});
}

std::string LinePrimitive() {
  return Obj("foxglove.LinePrimitive", "A primitive representing a series of points connected by lines",
      {{"type", Enum("foxglove.LineType", {{"LINE_STRIP", 0}, {"LINE_LOOP", 1}, {"LINE_LIST", 2}}, "Drawing primitive to use for lines")},
       {"pose", Pose("Origin of lines relative to reference frame")},
       {"thickness", Num("Line thickness")},
       {"scale_invariant", Bool("Whether thickness is in pixels (true) or in the frame's units (false)")},
       {"points", Arr(Point3(), "Points along the line")}, {"color", Color("Solid color for the whole line")},
       {"colors", Arr(Color(""), "Per-point colors")}, {"indices", Arr(UInt(""), "Indices into points")}});
}

std::string TextPrimitive() {
  return Obj("foxglove.TextPrimitive", "A primitive representing a text label",
      {{"pose", Pose("Position of the center of the text box and orientation of the text")},
       {"billboard", Bool("Whether the text always faces the camera")}, {"font_size", Num("Font size (height of one line of text)")},
       {"scale_invariant", Bool("Whether font_size is in pixels (true) or in the frame's units (false)")},
       {"color", Color("Color of the text")}, {"text", Str("Text")}});
}

std::string SceneEntity() {
  const std::string kv = Obj("foxglove.KeyValuePair", "A key with its associated value",
                             {{"key", Str("Key")}, {"value", Str("Value")}});
  return Obj("foxglove.SceneEntity", "A visual element in a 3D scene",
      {{"timestamp", Time("Timestamp of the entity")}, {"frame_id", Str("Frame of reference")},
       {"id", Str("Identifier for the entity; replaces any prior entity on the same topic with the same id")},
       {"lifetime", Duration("Time after timestamp when the entity is removed; zero: until replaced or deleted")},
       {"frame_locked", Bool("Whether the entity follows frame_id as it moves (true) or stays where it was (false)")},
       {"metadata", Arr(kv, "Additional metadata (keys unique)")},
       {"arrows", Arr(ArrowPrimitive(), "Arrow primitives")},
       {"cubes", Arr(SizedPrimitive("foxglove.CubePrimitive", "cube or rectangular prism"), "Cube primitives")},
       {"spheres", Arr(SizedPrimitive("foxglove.SpherePrimitive", "sphere or ellipsoid"), "Sphere primitives")},
       {"cylinders", Arr(CylinderPrimitive(), "Cylinder primitives")}, {"lines", Arr(LinePrimitive(), "Line primitives")},
       {"texts", Arr(TextPrimitive(), "Text primitives")}});
}

std::string SceneUpdate() {
  const std::string deletion = Obj("foxglove.SceneEntityDeletion", "Command to remove previously published entities",
      {{"timestamp", Time("Only matching entities earlier than this timestamp are deleted")},
       {"type", Enum("foxglove.SceneEntityDeletionType", {{"MATCHING_ID", 0}, {"ALL", 1}}, "Type of deletion action to perform")},
       {"id", Str("Identifier which must match if type is MATCHING_ID")}});
  return Obj(kSceneUpdate, "An update to the entities displayed in a 3D scene",
             {{"deletions", Arr(deletion, "Scene entities to delete")}, {"entities", Arr(SceneEntity(), "Scene entities to add or replace")}});
}

std::string FrameTransforms() {
  const std::string transform = Obj("foxglove.FrameTransform", "A transform between two reference frames in 3D space",
      {{"timestamp", Time("Timestamp of transform")}, {"parent_frame_id", Str("Name of the parent frame")},
       {"child_frame_id", Str("Name of the child frame")},
       {"translation", Vector3("Translation component of the transform")},
       {"rotation", Quaternion("Rotation component of the transform")}});
  return Obj(kFrameTransforms, "An array of FrameTransform messages", {{"transforms", Arr(transform, "Array of transforms")}});
}

std::string PoseInFrame() {
  return Obj(kPoseInFrame, "A timestamped pose for an object or reference frame in 3D space",
             {{"timestamp", Time("Timestamp of pose")}, {"frame_id", Str("Frame of reference for pose position and orientation")},
              {"pose", Pose("Pose in 3D space")}});
}

std::string CompressedImage() {
  return Obj(kCompressedImage, "A compressed image",
             {{"timestamp", Time("Timestamp of image")}, {"frame_id", Str("Frame of reference for the image")},
              {"data", Described("\"type\":\"string\",\"contentEncoding\":\"base64\"", "Compressed image data")},
              {"format", Str("Image format: jpeg, png, webp or avif")}});
}

std::string Log() {
  return Obj(kLog, "A log message",
             {{"timestamp", Time("Timestamp of log message")},
              {"level", Enum("foxglove.LogLevel", {{"UNKNOWN", 0}, {"DEBUG", 1}, {"INFO", 2}, {"WARNING", 3}, {"ERROR", 4}, {"FATAL", 5}}, "Log level")},
              {"message", Str("Log message")}, {"name", Str("Process or node name")},
              {"file", Str("Filename")}, {"line", UInt("Line number in the file")}});
}

// SwarmBox's own: positions are ENU [m] in the world frame, times simulated.
std::string Vec3Array(std::string_view d) { return Tuple(Num(""), 3, d); }

std::string DroneTruth() {
  return Obj(kDroneTruth, "A drone's true state from the physics server",
             {{"timestamp", Time("Simulated time")}, {"drone", Str("Drone name")},
              {"position", Vec3Array("[x, y, z] ENU [m]")}, {"velocity", Vec3Array("[vx, vy, vz] ENU [m/s]")},
              {"orientation", Quaternion("Body attitude in the world frame")}});
}

std::string Setpoint() {
  return Obj(kSetpoint, "What the drone's flight controller was asked to do",
             {{"timestamp", Time("Simulated time")}, {"flight_mode", Str("Flight mode")},
              {"position", Tuple(NullableNum(), 3, "[x, y, z] ENU [m]; null where unset")},
              {"velocity", Tuple(NullableNum(), 3, "[vx, vy, vz] ENU [m/s]; null where unset")},
              {"yaw", Described("\"type\":[\"number\",\"null\"]", "Yaw [rad]; null where unset")}});
}

std::string Flocking() {
  return Obj(kFlocking, "A drone's Boids acceleration terms",
             {{"timestamp", Time("Simulated time")}, {"separation", Vec3Array("[m/s^2]")},
              {"alignment", Vec3Array("[m/s^2]")}, {"cohesion", Vec3Array("[m/s^2]")},
              {"sum", Vec3Array("Sum of the three [m/s^2]")}});
}

std::string RaftState() {
  return Obj(kRaftState, "A drone's Raft state",
             {{"timestamp", Time("Simulated time")},
              {"role", StrEnum({"follower", "candidate", "leader", "learner"}, "Raft role")},
              {"term", UInt("Current term")}, {"leader", Str("The leader this drone knows of (\"\" when none)")},
              {"commit_index", UInt("Highest log index known committed")}});
}

std::string AgentStatus() {
  return Obj(kAgentStatus, "A drone's agent status",
             {{"timestamp", Time("Simulated time")}, {"battery_fraction", Num("Battery left, 0-1")},
              {"mission_stage", Str("Mission stage")}, {"armed", Bool("Motors armed")}, {"landed", Bool("On the ground")}});
}

std::string Links() {
  const std::string link = Obj("", "A radio link as measured by the sending agent",
      {{"from", Str("Measuring drone")}, {"to", Str("Peer drone")}, {"loss", Num("Loss fraction, 0-1")},
       {"rtt_ms", Num("Round-trip time [ms]")}});
  return Obj(kLinks, "The mesh radio's links", {{"timestamp", Time("Simulated time")}, {"links", Arr(link, "Links")}});
}

std::string Sectors() {
  const std::string sector = Obj("", "A drone's search sector",
      {{"drone", Str("Drone searching it")},
       {"polygon", Arr(Tuple(Num(""), 2, "[x, y] ENU [m]"), "Corners in order")}});
  return Obj(kSectors, "The leader's search plan", {{"timestamp", Time("Simulated time")}, {"sectors", Arr(sector, "Sectors")}});
}

std::string Detection() {
  return Obj(kDetection, "A victim detection",
             {{"timestamp", Time("Simulated time")}, {"drone", Str("Detecting drone")},
              {"position", Vec3Array("Estimated victim position, ENU [m]")}, {"confidence", Num("0-1")}});
}

const std::map<std::string_view, std::string>& Texts() {
  static const auto* texts = new std::map<std::string_view, std::string>{
      {kSceneUpdate, SceneUpdate()}, {kFrameTransforms, FrameTransforms()}, {kPoseInFrame, PoseInFrame()},
      {kCompressedImage, CompressedImage()}, {kLog, Log()}, {kDroneTruth, DroneTruth()},
      {kSetpoint, Setpoint()}, {kFlocking, Flocking()}, {kRaftState, RaftState()},
      {kAgentStatus, AgentStatus()}, {kLinks, Links()}, {kSectors, Sectors()}, {kDetection, Detection()}};
  return *texts;
}

}  // namespace

const std::vector<std::string_view>& SchemaNames() {
  static const std::vector<std::string_view> names = {
      kSceneUpdate, kFrameTransforms, kPoseInFrame, kCompressedImage, kLog, kDroneTruth, kSetpoint,
      kFlocking,    kRaftState,       kAgentStatus, kLinks,           kSectors, kDetection};
  return names;
}

std::string_view SchemaText(std::string_view schema_name) {
  const auto& texts = Texts();
  auto it = texts.find(schema_name);
  return it == texts.end() ? std::string_view{} : std::string_view{it->second};
}

ChannelSpec MakeChannel(std::string topic, std::string_view schema_name) {
  const std::string_view text = SchemaText(schema_name);
  SWARMBOX_CHECK(!text.empty());
  return ChannelSpec{std::move(topic), std::string(schema_name), std::string(text)};
}

std::string JsonTimestamp(std::uint64_t ns) {
  return "{\"sec\":" + std::to_string(ns / 1000000000u) + ",\"nsec\":" + std::to_string(ns % 1000000000u) + "}";
}

yaml::Node TimestampNode(std::uint64_t ns) {
  yaml::Node n = yaml::Node::Mapping();
  n.Set("sec", yaml::Node::Scalar(std::to_string(ns / 1000000000u)));
  n.Set("nsec", yaml::Node::Scalar(std::to_string(ns % 1000000000u)));
  return n;
}

std::uint64_t SecondsToNs(double seconds) {
  if (!(seconds > 0)) return 0;
  return static_cast<std::uint64_t>(std::llround(seconds * 1e9));
}

}  // namespace swarmbox::record
