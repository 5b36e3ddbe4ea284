// `hsactl scope`: a capture drawn by gnuplot as an oscilloscope would, time from the trigger's
// cycle on x (the file's `t`), the chosen signals in stacked panels, the trigger a vertical line,
// the title the axis, the reason and the trigger's UTC time. To a PNG (pngcairo), or with
// gnuplot's `dumb` terminal into the terminal.
//
// Panels are given as "a+b,c": signals joined by '+' share a panel, commas separate panels. Lengths
// are drawn in mm and pressures in bar, as hsactl shows them; `setpoint` is a length only in
// position mode (the file's `mode` column 0 throughout), and the default leaves it out otherwise.
#pragma once

#include <ostream>
#include <string>
#include <vector>

#include "tools/hsactl/capture_reader.hpp"

namespace hsa::ctl {

inline constexpr const char* kDefaultScopeSignals = "setpoint+rod_setpoint_m+position_m,following_error_m,valve_command";

struct ScopeTrace {
  std::string name;
  double scale = 1.0;  // drawn value = file value * scale
  std::string unit;    // of the drawn value
};
using ScopePanel = std::vector<ScopeTrace>;

// Throws std::invalid_argument naming a signal the capture does not have, and those it has.
std::vector<ScopePanel> scope_panels(const Capture& capture, const std::string& spec, bool is_default);

struct ScopeTarget {
  std::string png;  // "": the dumb terminal, on stdout
  int columns = 120, lines = 40;
};

// The data file gnuplot reads: t (s from the trigger), then each trace's drawn values, space-separated.
void write_scope_data(std::ostream& out, const Capture& capture, const std::vector<ScopePanel>& panels);
// The gnuplot script drawing `data` (write_scope_data's file).
std::string scope_script(const std::vector<ScopePanel>& panels, const std::string& data, const std::string& title,
                         const ScopeTarget& target);

// Reads `mat` and runs gnuplot. Returns 0; throws std::runtime_error (with the file or gnuplot's
// failure) or std::invalid_argument (a signal it lacks).
int draw_scope(const std::string& mat, const std::string& spec, bool is_default, const ScopeTarget& target);

}  // namespace hsa::ctl
