// The input signals of an axis, as one table.
//
// HSA_AXIS_INPUTS below is the axis's input set: every struct that carries one value per input (the
// configuration's [axes.signals] tables, the bindings, the bound signals, the samples the
// supervisor judges) takes its members from it, and the configuration reader, describe(), the
// binding checks, the loop's read into SupervisorInputs and the supervisor's judging of every
// input (a first sample at start-up, a sample not ok, a timestamp that stopped) walk it. FaultSignal
// (fault.hpp) is its enumerators and names. So a new input is a line here; a fault on it is a line
// in HSA_FAULT_REASONS and its check in AxisSupervisor::evaluate. The valve outputs are not inputs
// and stay named members.
//
// X(signal, name, kind, presence, unreadable)
//   signal      the key under [axes.signals], the member in every per-axis struct, the enumerator
//   name        how faults name it ("pressure A over limit ...")
//   kind        the channel kind it binds to: encoder or analog (an io::AnalogSample, with
//               low_limit and high_limit) or digital (an io::DigitalSample, with invert)
//   presence    required; optional; or law: required when the axis's control law closes a loop
//               on it (ControlLaw::needs_spool), optional otherwise
//   unreadable  the FaultReason a sample that is not ok, or whose timestamp stopped for longer than
//               input_stale_ns, trips: sensor_not_ok, or estop for a loop whose broken wire must
//               read as pressed
//
// Ordered as the inputs are read, bound and judged: when two inputs fail in one cycle, the first
// in this list is the one a fault names.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string_view>
#include <type_traits>

#include "drivers/channel.hpp"
#include "drivers/signal_binding.hpp"

#define HSA_AXIS_INPUTS(X)                                             \
  X(position, "position", encoder, required, sensor_not_ok)            \
  X(pressure_a, "pressure A", analog, required, sensor_not_ok)         \
  X(pressure_b, "pressure B", analog, required, sensor_not_ok)         \
  X(spool, "spool position", analog, law, sensor_not_ok)               \
  X(estop, "e-stop", digital, optional, estop)

namespace hsa::daemon {

enum class InputKind : std::uint8_t { encoder, analog, digital };
enum class InputPresence : std::uint8_t { required, optional, law };

// Indexes arrays kept per input.
enum class AxisInput : std::uint8_t {
#define HSA_AXIS_INPUT_ENUMERATOR(signal, name, kind, presence, unreadable) signal,
  HSA_AXIS_INPUTS(HSA_AXIS_INPUT_ENUMERATOR)
#undef HSA_AXIS_INPUT_ENUMERATOR
};

struct AxisInputInfo {
  std::string_view key;   // under [axes.signals]
  std::string_view name;  // in faults
  InputKind kind;
  InputPresence presence;
};

inline constexpr AxisInputInfo kAxisInputs[] = {
#define HSA_AXIS_INPUT_INFO(signal, name, kind, presence, unreadable) \
  {#signal, name, InputKind::kind, InputPresence::presence},
    HSA_AXIS_INPUTS(HSA_AXIS_INPUT_INFO)
#undef HSA_AXIS_INPUT_INFO
};
inline constexpr std::size_t kAxisInputCount = std::size(kAxisInputs);

constexpr const AxisInputInfo& info(AxisInput input) { return kAxisInputs[static_cast<std::size_t>(input)]; }

// The channel kind a binding of `kind` must find.
constexpr io::ChannelKind channel_kind(InputKind kind) {
  switch (kind) {
    case InputKind::encoder: return io::ChannelKind::encoder_input;
    case InputKind::analog: return io::ChannelKind::analog_input;
    case InputKind::digital: return io::ChannelKind::digital_input;
  }
  return io::ChannelKind::analog_input;
}

// The types a member of each kind has: an encoder is an analog input whose channel counts.
template <InputKind K>
using InputParams = std::conditional_t<K == InputKind::digital, io::DigitalInputParams, io::AnalogInputParams>;
template <InputKind K>
using InputSample = std::conditional_t<K == InputKind::digital, io::DigitalSample, io::AnalogSample>;
template <InputKind K>
using BoundInput = std::conditional_t<K == InputKind::digital, io::DigitalInput, io::AnalogInput>;

// A required input's member is the value itself; any other may be absent.
template <InputPresence P, class T>
using InputField = std::conditional_t<P == InputPresence::required, T, std::optional<T>>;

// An input's member, whichever its presence, or nullptr when it is absent.
template <class T>
const T* present(const T& member) {
  return &member;
}
template <class T>
const T* present(const std::optional<T>& member) {
  return member ? &*member : nullptr;
}

}  // namespace hsa::daemon
