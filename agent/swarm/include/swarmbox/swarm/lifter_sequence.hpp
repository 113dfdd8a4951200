// LifterSequence: the heavy lifter's (x8_heavy) rescue, an explicit pure state machine.
//
// The stretcher starts lying on the ground under the lifter's spawn point. When the committed
// mission state puts a victim in RESCUE with this drone as its rescuer, the lifter:
//   kTakeoffForPickup  climbs to the hook height over the stretcher        ("takeoff_for_pickup")
//   kAttachEmpty       settles, asks payload_attach {empty mass}, waits    ("attach_empty")
//   kClimbToTransit    climbs to transit altitude, stretcher slung below   ("climb")
//   kTransitToVictim   flies to the drop point beside the victim           ("transit_to_victim")
//   kSurveyDropPoint   only with survey_drop_point: descends to survey_height_m over the default
//                      drop point, settles, asks the host for a drop spot (want_drop_spot: the
//                      point and the stretcher's yaw, the lifter's, then held until the release)
//                      and takes its answer (in.drop_spot): found -> the drop point moves there
//                      (event drop_spot_chosen; the lifter first flies over it at survey height);
//                      not found -> drop_spot_none; no answer within survey_timeout_s ->
//                      drop_spot_unverified reason=no_depth; both keep the default point
//                                                                          ("survey_drop_point")
//   kDescendToRelease  lowers the stretcher onto the ground                ("descend_to_release")
//   kRelease           settles, asks payload_release, waits                ("release")
//   kWaitLoading       holds while the evacuee is loaded, loading_time_s   ("loading")
//   kAttachLoaded      asks payload_attach {loaded mass = 80 kg}, waits    ("attach_loaded")
//   kClimbWithLoad     climbs to transit altitude, swing damped            ("climb_loaded")
//   kCarryHome         flies home, swing damped                            ("carry_home")
//   kDescendToDrop     lowers the stretcher onto the ground at home        ("descend_to_drop")
//   kReleaseAtHome     asks payload_release, waits; proposes MarkRescued   ("release_at_home")
//   kMoveToLandingPoint  moves aside (land_offset_m) at low height         ("move_to_land")
//   kLanding -> kOnGround ("landing", "on_ground"); MarkRescued is re-proposed until committed.
// With standby_after_delivery, after the release at home the lifter first holds at hook height
// over the stretcher it just set down ("standby") while a confirmed victim still waits for a
// rescue: a BeginRescue for it then goes straight to kAttachEmpty (no landing and take-off in
// between); with no victim waiting (or battery low) it moves aside and lands as above.
// A payload request is repeated every attach_retry_s until the payload status changes (a world
// command can be lost or refused when the hook is out of reach). Battery low: event=battery_low;
// the lifter abandons a rescue not yet loaded and goes home (with whatever it carries).
// Heights are above home_m.z (flat ground). Payload actions happen only once settled: within
// position_tolerance_m / altitude_tolerance_m of the target and slower than settle_speed_m_s for
// settle_time_s (the slung stretcher has stopped swinging).
//
//   LifterSequence lifter({.name = "lifter", .home_m = spawn});
//   lifter.Step(input, &output);  // output.payload -> WorldCommand payload_attach/payload_release
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

#include "swarmbox/swarm/mission_types.hpp"

namespace swarmbox::swarm {

struct LifterConfig {
  std::string name;
  Eigen::Vector3d home_m = Eigen::Vector3d::Zero();  // spawn point on the ground [m]
  double base_height_m = 0.6;            // body origin above ground when landed [m]
  double transit_altitude_m = 15.0;      // below the scouts' search altitude [m]
  double cruise_speed_m_s = 4.0;
  double loaded_speed_m_s = 2.5;         // with the evacuee on board [m/s]
  // Sling geometry (airframe PayloadSpec): hook under the body origin, hook -> payload centre.
  double hook_below_body_m = 0.4;
  double sling_length_m = 4.0;
  double payload_half_height_m = 0.125;
  // Descend this much below the attach height to set down; negative: release the stretcher this
  // far above the ground (a rigid sling on a stretcher lying on the ground drags it by friction
  // and upsets the swing damping) [m].
  double release_sink_m = 0.25;
  double stretcher_offset_m = 3.0;       // drop point this far from the victim, toward home [m]
  Eigen::Vector2d land_offset_m{6.0, 0.0};  // landing point beside the stretcher at home [m]
  // Where the stretcher lies at start, relative to home_m (the physics server lays a ground
  // payload beside the drone, not under it) [m].
  Eigen::Vector2d stretcher_start_offset_m{0.0, 0.0};
  bool standby_after_delivery = false;    // hover over the stretcher while victims wait
  double loading_time_s = 30.0;
  double empty_stretcher_mass_kg = 15.0;  // assumption: litter alone
  double loaded_mass_kg = 80.0;           // stretcher and evacuee (the brief)
  double position_tolerance_m = 0.5;
  double altitude_tolerance_m = 0.3;
  double settle_speed_m_s = 0.3;
  double settle_time_s = 1.5;
  // Setting the stretcher down needs less than hooking it: within release_tolerance_m and slower
  // than release_speed_m_s for settle_time_s (a slung load keeps the lifter moving a little).
  double release_tolerance_m = 2.0;
  double release_speed_m_s = 2.5;
  // Arrival over the drop point or home at transit altitude (then the descent starts): within
  // arrive_tolerance_m and slower than arrive_speed_m_s (a heavy swinging load keeps the lifter
  // circling slowly around its target; the descent is a position hold on the same point).
  double arrive_tolerance_m = 1.5;
  double arrive_speed_m_s = 1.0;
  double attach_retry_s = 3.0;
  double proposal_retry_s = 2.0;
  // The drop-spot survey (kSurveyDropPoint; agent/depth drop_spot.hpp chooses the spot): the body's
  // height above the ground at which the lifter looks at the drop point with its stereo camera (the
  // sling hangs 4.5 m below the body, so the stretcher stays ~3.5 m above the ground there), and
  // how long it waits for the host's answer once settled [m, s]. Off: the sequence is unchanged.
  bool survey_drop_point = false;
  double survey_height_m = 8.0;
  double survey_timeout_s = 10.0;

  // Body height above the ground at which the hook reaches the stretcher lying flat [m].
  double AttachHeight() const { return payload_half_height_m + sling_length_m + hook_below_body_m; }
};

class LifterSequence {
 public:
  enum class Stage {
    kOnGround, kTakeoffForPickup, kAttachEmpty, kClimbToTransit, kTransitToVictim, kSurveyDropPoint,
    kDescendToRelease, kRelease, kWaitLoading, kAttachLoaded, kClimbWithLoad, kCarryHome,
    kDescendToDrop, kReleaseAtHome, kMoveToLandingPoint, kLanding, kStandby,
  };
  static std::string_view StageName(Stage stage);

  explicit LifterSequence(LifterConfig config);

  void Step(const MissionInput& in, MissionOutput* out);

  Stage stage() const { return stage_; }
  std::uint32_t victim() const { return victim_; }
  // Where the stretcher lies (or will be set down) on the ground [m, ENU].
  const Eigen::Vector2d& stretcher_xy_m() const { return stretcher_xy_m_; }
  // Where the stretcher is to be set down beside the current victim: stretcher_offset_m from it
  // toward home, or the spot the survey chose [m, ENU].
  const Eigen::Vector2d& drop_xy_m() const { return drop_xy_m_; }
  const LifterConfig& config() const { return config_; }

 private:
  // Step's parts: re-propose MarkRescued until committed; react once to a low battery.
  void RepeatMarkRescued(const MissionInput& in, MissionOutput* out);
  void HandleBatteryLow(const MissionInput& in, MissionOutput* out);
  // One pass of the state machine: the current stage's setpoint and transition.
  void RunStage(const MissionInput& in, MissionOutput* out);
  // One handler per stage (the two descents and the two releases share one each).
  void RunOnGround(const MissionInput& in, MissionOutput* out);
  void RunStandby(const MissionInput& in, MissionOutput* out);
  void RunTakeoffForPickup(const MissionInput& in, MissionOutput* out);
  void RunAttachEmpty(const MissionInput& in, MissionOutput* out);
  void RunClimb(const MissionInput& in, Stage if_unhooked, double speed_m_s, Stage next,
                MissionOutput* out);
  void RunTransitToVictim(const MissionInput& in, MissionOutput* out);
  // kSurveyDropPoint: settle at survey height, ask, take the answer (or time out), then fly over
  // the chosen point at survey height before the descent.
  void RunSurveyDropPoint(const MissionInput& in, MissionOutput* out);
  void TakeDropSpotAnswer(const MissionInput& in, const DropSpotAnswer& answer, MissionOutput* out);
  // The stretcher's yaw as surveyed, held from the survey's settling to the release.
  bool HoldsSurveyYaw() const;
  // Lowers the slung load onto the ground at `xy_m`; settled there -> `next`.
  void RunDescend(const MissionInput& in, const Eigen::Vector2d& xy_m, Stage next, MissionOutput* out);
  // Holds at release height over `xy_m` and asks for the release; true once the hook is empty
  // (the stretcher then lies under the lifter).
  bool ReleasedAt(const MissionInput& in, const Eigen::Vector2d& xy_m, MissionOutput* out);
  void RunRelease(const MissionInput& in, MissionOutput* out);
  void RunWaitLoading(const MissionInput& in, MissionOutput* out);
  void RunAttachLoaded(const MissionInput& in, MissionOutput* out);
  void RunCarryHome(const MissionInput& in, MissionOutput* out);
  void RunReleaseAtHome(const MissionInput& in, MissionOutput* out);
  void RunMoveToLandingPoint(const MissionInput& in, MissionOutput* out);
  void RunLanding(const MissionInput& in, MissionOutput* out);
  // Over `xy_m` and slow enough to start the descent (arrive tolerances).
  bool Arrived(const MissionInput& in, const Eigen::Vector2d& xy_m) const;
  // A rescue committed for this drone (phase RESCUE, its victim being rescued by it): takes it
  // (victim, drop point) and returns true.
  bool TakeRescue(const MissionInput& in);
  void Enter(Stage stage, const MissionInput& in, MissionOutput* out);
  // True once within tolerance of `target_m` and slow for settle_time_s (the attach tolerances,
  // or with `release` the looser release ones).
  bool Settled(const MissionInput& in, const Eigen::Vector3d& target_m, bool release = false);
  void Hold(const Eigen::Vector3d& target_m, double speed_m_s, bool damp, MissionOutput* out) const;
  void RequestPayload(const MissionInput& in, PayloadAction action, double mass_kg,
                      MissionOutput* out);
  double Ground() const { return config_.home_m.z(); }
  // Body heights [m, world]: the hook reaches the stretcher lying flat; the load is set down;
  // transit altitude.
  double AttachZ() const { return Ground() + config_.AttachHeight(); }
  double ReleaseZ() const { return AttachZ() - config_.release_sink_m; }
  double TransitZ() const { return Ground() + config_.transit_altitude_m; }
  double SurveyZ() const { return Ground() + config_.survey_height_m; }
  Eigen::Vector2d HomeXy() const { return config_.home_m.head<2>(); }

  LifterConfig config_;
  Stage stage_ = Stage::kOnGround;
  std::uint32_t victim_ = 0;
  Eigen::Vector2d victim_xy_m_ = Eigen::Vector2d::Zero();
  Eigen::Vector2d drop_xy_m_ = Eigen::Vector2d::Zero();  // where the stretcher is to be set down
  Eigen::Vector2d stretcher_xy_m_ = Eigen::Vector2d::Zero();
  double stage_start_s_ = 0.0;
  double settled_since_s_ = -1.0;
  double last_request_s_ = -1e9;
  double last_proposal_s_ = -1e9;
  std::uint32_t delivered_victim_ = 0;  // MarkRescued to (re)propose until committed
  bool battery_low_reported_ = false;
  // The drop-spot survey: when it settled and asked (-1: not yet), whether the answer (or the
  // timeout) is in, the yaw it asked with.
  double survey_asked_s_ = -1.0;
  bool survey_decided_ = false;
  double survey_yaw_rad_ = 0.0;
};

}  // namespace swarmbox::swarm
