#include "daemon/config/signal_config_reader.hpp"

#include <cmath>
#include <string>
#include <string_view>

namespace hsa::daemon {

namespace {

template <class Params>
SignalConfig<Params> parse_binding(const io::TableReader& t, const std::vector<DriverConfig>& drivers) {
  SignalConfig<Params> s;
  std::string names;
  for (const auto& d : drivers) names += (names.empty() ? "" : ", ") + d.name;
  const std::string driver_expected = "the name of a configured driver (one of: " + names + ")";
  s.driver = t.string("driver", driver_expected);
  bool known = false;
  for (const auto& d : drivers) known = known || d.name == s.driver;
  if (!known) t.fail("driver", driver_expected);
  constexpr std::string_view channel_expected = "the name of one of the driver's channels";
  s.channel = t.string("channel", channel_expected);
  if (s.channel.empty()) t.fail("channel", channel_expected);
  return s;
}

// Scaling belongs to the driver channel (one convention: value = raw·scale + offset). A signal
// that still has the keys of the old second stage, which subtracted its offset, is refused with
// what changed rather than read with a sign the user did not mean.
void refuse_signal_scaling(const io::TableReader& t) {
  for (const std::string_view key : {"scale", "offset"}) {
    if (t.has(key)) {
      t.fail(key, "no " + std::string(key) +
                      " here: a signal no longer scales; set scale and offset on the driver's channel, where "
                      "value = raw * scale + offset (docs/drivers.md, \"Scaling: one convention\")");
    }
  }
}

template <class Params>
void parse_signal_limits(const io::TableReader& t, Params& p) {
  // Absent limits stay infinite: no range check on that side.
  p.low_limit = t.number("low_limit", io::NumberRange::any(), p.low_limit);
  if (t.has("high_limit")) {
    const io::NumberRange above_low =
        std::isfinite(p.low_limit) ? io::NumberRange::above(p.low_limit) : io::NumberRange::any();
    p.high_limit = t.number("high_limit", above_low);
  }
}

// An analog binding, input or output: the channel and the limits, no scaling.
template <class Params>
SignalConfig<Params> parse_analog(const io::TableReader& t, const std::vector<DriverConfig>& drivers) {
  refuse_signal_scaling(t);
  t.reject_unknown_keys({"driver", "channel", "low_limit", "high_limit"});
  auto s = parse_binding<Params>(t, drivers);
  parse_signal_limits(t, s.params);
  return s;
}

void parse_into(const io::TableReader& t, const std::vector<DriverConfig>& drivers, AnalogInputConfig& out) {
  out = parse_analog<io::AnalogInputParams>(t, drivers);
}

void parse_into(const io::TableReader& t, const std::vector<DriverConfig>& drivers, DigitalInputConfig& out) {
  t.reject_unknown_keys({"driver", "channel", "invert"});
  out = parse_binding<io::DigitalInputParams>(t, drivers);
  out.params.invert = t.boolean("invert", false);
}

DigitalOutputConfig parse_digital_output(const io::TableReader& t, const std::vector<DriverConfig>& drivers) {
  t.reject_unknown_keys({"driver", "channel", "invert"});
  auto s = parse_binding<io::DigitalOutputParams>(t, drivers);
  s.params.invert = t.boolean("invert", false);
  return s;
}

io::TableReader signal_table(const io::TableReader& signals, std::string_view name, std::string_view kind) {
  return *signals.table(name, true,
                        "a table [" + signals.key_path(name) + "] binding the " + std::string(kind) +
                            " to a driver and channel");
}

std::string_view kind_of(AxisInput input) { return io::to_string(channel_kind(info(input).kind)); }

// A required input.
template <class Config>
void read_input(const io::TableReader& t, AxisInput input, const control::ControlLaw&,
                const std::vector<DriverConfig>& drivers, Config& out) {
  parse_into(signal_table(t, info(input).key, kind_of(input)), drivers, out);
}

// An optional input, or one the law may need.
template <class Config>
void read_input(const io::TableReader& t, AxisInput input, const control::ControlLaw& law,
                const std::vector<DriverConfig>& drivers, std::optional<Config>& out) {
  const AxisInputInfo& i = info(input);
  if (i.presence == InputPresence::law && law.needs_spool()) {
    // The law's valve loop closes on it.
    const std::string needed = std::string(i.name) + " input (drive = \"" + std::string(law.name()) + "\" needs it)";
    parse_into(signal_table(t, i.key, needed), drivers, out.emplace());
  } else if (t.has(i.key)) {
    parse_into(signal_table(t, i.key, kind_of(input)), drivers, out.emplace());
  }
}

constexpr std::string_view kSignalKeys[] = {
#define HSA_INPUT_KEY(signal, name, kind, presence, unreadable) #signal,
    HSA_AXIS_INPUTS(HSA_INPUT_KEY)
#undef HSA_INPUT_KEY
    "valve_command", "valve_enable"};

}  // namespace

AxisSignalConfig parse_signals(const io::TableReader& t, const control::ControlLaw& law,
                               const std::vector<DriverConfig>& drivers) {
  t.reject_unknown_keys(kSignalKeys);
  AxisSignalConfig s;
#define HSA_READ_INPUT(signal, name, kind, presence, unreadable) \
  read_input(t, AxisInput::signal, law, drivers, s.signal);
  HSA_AXIS_INPUTS(HSA_READ_INPUT)
#undef HSA_READ_INPUT
  s.valve_command = parse_analog<io::AnalogOutputParams>(signal_table(t, "valve_command", "analog output"), drivers);
  s.valve_enable = parse_digital_output(signal_table(t, "valve_enable", "digital output"), drivers);
  return s;
}

}  // namespace hsa::daemon
