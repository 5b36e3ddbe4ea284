// One axis of the daemon: its signals, its control law and its safety thresholds, all in SI units.
// The law is built and checked while the configuration is read (control/law_registry.hpp); each
// running axis gets its own clone.
#pragma once

#include <cstdint>
#include <string>

#include <memory>

#include "control/control_law.hpp"
#include "daemon/config/recorder_config.hpp"
#include "daemon/config/signal_config.hpp"
#include "daemon/supervisor/motion_capability.hpp"
#include "daemon/supervisor/safety_defaults.hpp"

namespace hsa::daemon {

struct SoftLimits {
  double min_m = 0.0;  // the rod position must stay within [min_m, max_m]; min_m < max_m
  double max_m = 0.0;
  // A move's (MOVE_TO) bounds: the largest acceleration it may ask for, which is also the one it
  // gets when it asks for none, and the jerk of every move; 0: derived from the speed
  // (safety_defaults::kDefaultRampS, kDefaultJerkRampS). With a plant set the acceleration is at
  // most the capability's, and unset it is the capability's (capability_check.hpp).
  double max_accel_m_s2 = 0.0;
  double max_jerk_m_s3 = 0.0;
};

// Fault thresholds. Each is a limit the supervisor compares against.
struct SafetyConfig {
  double max_pressure_pa = 0.0;        // either chamber above this faults
  double max_following_error_m = 0.0;  // |rate-limited setpoint − position| above this faults
  // The margin of the jump check: two encoder samples Δt apart may differ by pi.max_speed_m_s · Δt
  // plus this (quantisation, noise); more faults. Without a speed limit, this per sample.
  double encoder_jump_m = 0.0;
  // Times in seconds; the defaults are safety_defaults.hpp's, the one place they are written.
  double following_error_s = safety_defaults::kFollowingErrorS;  // over max_following_error_m this long faults
  double encoder_stale_s = safety_defaults::kEncoderStaleS;      // no fresh encoder sample this long faults
  double input_stale_s = safety_defaults::kInputStaleS;          // any bound input without a new timestamp
  double max_blind_time_s = safety_defaults::kMaxBlindTimeS;     // ENABLED: time between two cycles
  double current_saturation_s = safety_defaults::kCurrentSaturationS;  // valve command saturated this long
  std::uint32_t overrun_streak = safety_defaults::kOverrunStreak;      // consecutive RT overruns
  double setpoint_timeout_s = safety_defaults::kSetpointTimeoutS;  // silence that holds position (no fault)
  double startup_timeout_s = safety_defaults::kStartupTimeoutS;    // INIT waits this long for first samples
  // The valve's null command, written in the safe state: an opening of 0 for a servo-valve (in
  // [-1, 1]); the bias current in A for a proportional valve (in [0, max_current_a]; defaults to
  // valve_law.bias_current_a).
  double safe_valve_command = 0.0;
};

struct AxisConfig {
  std::string name;  // [A-Za-z0-9_]+, unique; LCM channels are HSA/<name>/...
  // The control law, chosen by `drive` (its name, control/law_registry.cpp) and configured from
  // the tables it reads ([axes.pi], and [axes.valve_law] for "proportional"). Its periods are
  // derived from the base period and cylinder_rate_hz.
  std::shared_ptr<const control::ControlLaw> law;

  std::uint32_t cylinder_rate_hz = 1000;   // divides the base rate
  std::uint32_t telemetry_rate_hz = 1000;  // divides the base rate
  // Derived: base ticks per cylinder-loop tick (= cascade.valve_ticks_per_cylinder_tick) and per
  // telemetry message.
  std::uint32_t ticks_per_cylinder_tick = 10;
  std::uint32_t ticks_per_telemetry = 10;
  double area_ratio = 1.0;  // α = annulus / piston area, for the load pressure p_A − α·p_B (0, 1]

  AxisSignalConfig signals;
  SoftLimits limits;
  SafetyConfig safety;
  // What the plant can follow per direction, from the plant-set file the axis names ([axes.pi]
  // `plants`; capability_check.hpp), and that file; infinite and "" without one: the configured
  // bounds alone.
  MotionCapability capability{};
  std::string capability_source;
  AxisRecorderConfig recorder;  // [axes.recorder]: the flight recorder's ring
};

}  // namespace hsa::daemon
