#include "tools/hsactl/capture_scope.hpp"

#include <spawn.h>
#include <stdlib.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "tools/hsactl/capture_list.hpp"

extern char** environ;

namespace hsa::ctl {
namespace {

// A gnuplot single-quoted string: only the quote is special, doubled.
std::string quoted(const std::string& s) {
  std::string out = "'";
  for (const char ch : s) out += ch == '\'' ? std::string("''") : std::string(1, ch);
  return out + "'";
}

bool position_mode_throughout(const Capture& c) {
  const CaptureSignal* mode = c.signal("mode");
  return mode != nullptr && !mode->values.empty() &&
         std::all_of(mode->values.begin(), mode->values.end(), [](double m) { return m == 0.0; });
}

ScopeTrace trace_of(const CaptureSignal& s, bool position_mode) {
  std::string unit = s.unit;
  if (unit == "m or opening" && position_mode) unit = "m";
  if (unit == "m") return {s.name, 1e3, "mm"};
  if (unit == "m/s") return {s.name, 1e3, "mm/s"};
  if (unit == "Pa") return {s.name, 1e-5, "bar"};
  return {s.name, 1.0, unit};
}

// Removes the temporary folder on every path out.
struct TempDir {
  std::string path;
  TempDir() {
    const char* base = std::getenv("TMPDIR");
    std::string tmpl = std::string(base != nullptr && *base != '\0' ? base : "/tmp") + "/hsactl-scope-XXXXXX";
    if (mkdtemp(tmpl.data()) == nullptr) throw std::runtime_error(tmpl + ": cannot make it: " + std::strerror(errno));
    path = tmpl;
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  ~TempDir() {
    std::error_code ec;
    std::filesystem::remove_all(path, ec);
  }
};

void run_gnuplot(const std::string& script) {
  char* argv[] = {const_cast<char*>("gnuplot"), const_cast<char*>(script.c_str()), nullptr};
  pid_t pid = 0;
  const int rc = posix_spawnp(&pid, "gnuplot", nullptr, nullptr, argv, environ);
  if (rc == ENOENT) throw std::runtime_error("scope: gnuplot not found (Debian: apt install gnuplot-nox)");
  if (rc != 0) throw std::runtime_error(std::string("scope: cannot run gnuplot: ") + std::strerror(rc));
  int status = 0;
  while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0)
    throw std::runtime_error("scope: gnuplot failed (its message is above)");
}

}  // namespace

std::vector<ScopePanel> scope_panels(const Capture& c, const std::string& spec, bool is_default) {
  const bool position_mode = position_mode_throughout(c);
  std::vector<ScopePanel> panels;
  std::istringstream groups(spec);
  for (std::string group; std::getline(groups, group, ',');) {
    ScopePanel panel;
    std::istringstream names(group);
    for (std::string name; std::getline(names, name, '+');) {
      if (name.empty()) continue;
      const CaptureSignal* s = c.signal(name);
      if (s == nullptr) {
        std::string known;
        for (const CaptureSignal& k : c.signals) known += (known.empty() ? "" : ", ") + k.name;
        throw std::invalid_argument("scope: the capture has no signal '" + name + "' (it has " + known + ")");
      }
      // The default's setpoint is an opening in open loop: it would not share the mm panel.
      if (is_default && name == "setpoint" && !position_mode) continue;
      panel.push_back(trace_of(*s, position_mode));
    }
    if (!panel.empty()) panels.push_back(std::move(panel));
  }
  if (panels.empty()) throw std::invalid_argument("scope: no signal to draw in '" + spec + "'");
  return panels;
}

void write_scope_data(std::ostream& out, const Capture& c, const std::vector<ScopePanel>& panels) {
  const CaptureSignal* t = c.signal("t");
  std::vector<std::pair<const std::vector<double>*, double>> columns;
  for (const ScopePanel& p : panels)
    for (const ScopeTrace& tr : p) columns.emplace_back(&c.signal(tr.name)->values, tr.scale);
  char number[64];
  const auto put = [&](double v) {
    const auto r = std::to_chars(number, number + sizeof number, v);
    out.write(number, r.ptr - number);
  };
  const double rate = c.sample_rate_hz > 0 ? c.sample_rate_hz : 1.0;
  for (std::size_t k = 0; k < c.rows; ++k) {
    // The file's t when it has one; else rows from the trigger over the rate.
    put(t != nullptr ? t->values[k] : (static_cast<double>(k + 1) - static_cast<double>(c.trigger_index)) / rate);
    for (const auto& [values, scale] : columns) {
      out.put(' ');
      put((*values)[k] * scale);
    }
    out.put('\n');
  }
}

std::string scope_script(const std::vector<ScopePanel>& panels, const std::string& data, const std::string& title,
                         const ScopeTarget& target) {
  std::ostringstream s;
  const int n = static_cast<int>(panels.size());
  if (target.png.empty()) {
    s << "set terminal dumb noenhanced size " << target.columns << "," << target.lines << "\n";
  } else {
    s << "set terminal pngcairo noenhanced size 1000," << 80 + 220 * n << " font ',10'\n";
    s << "set output " << quoted(target.png) << "\n";
  }
  s << "set multiplot layout " << n << ",1 title " << quoted(title) << "\n";
  // x spans the data exactly; a margin above and below, so a flat trace is not drawn on the border.
  s << "set grid\nset key top left opaque\nset lmargin 12\nset autoscale xfix\nset offsets 0, 0, graph 0.05, graph 0.05\n";
  s << "set arrow 1 from 0, graph 0 to 0, graph 1 nohead dashtype 2 linewidth 2 linecolor rgb 'red'\n";
  int column = 2;
  for (int p = 0; p < n; ++p) {
    const ScopePanel& panel = panels[static_cast<std::size_t>(p)];
    std::string unit = panel.front().unit;
    for (const ScopeTrace& tr : panel)
      if (tr.unit != unit) unit = "mixed units";
    s << "set ylabel " << quoted(unit) << "\n";
    s << (p + 1 == n ? "set xlabel 's from the trigger'\n" : "unset xlabel\n");
    s << "plot ";
    for (std::size_t i = 0; i < panel.size(); ++i) {
      const ScopeTrace& tr = panel[i];
      s << (i ? ", " : "") << quoted(data) << " using 1:" << column++ << " with lines title "
        << quoted(tr.name + (tr.unit.empty() ? "" : " [" + tr.unit + "]"));
    }
    s << "\n";
  }
  s << "unset multiplot\n";
  return s.str();
}

int draw_scope(const std::string& mat, const std::string& spec, bool is_default, const ScopeTarget& target) {
  const Capture c = read_capture(mat);
  const std::vector<ScopePanel> panels = scope_panels(c, spec, is_default);
  bool from_name = false;
  const std::string when = capture_time_utc(mat, &from_name);
  std::string title = (c.axis.empty() ? std::string("?") : c.axis) + ": " + (c.reason.empty() ? c.trigger : c.reason);
  if (!c.trigger_state.empty()) title += " (" + c.trigger_state + ")";
  title += ", " + when + " UTC" + (from_name ? "" : " (file time)");
  TempDir dir;
  const std::string data = dir.path + "/capture.dat";
  const std::string script = dir.path + "/scope.gp";
  {
    std::ofstream out(data);
    write_scope_data(out, c, panels);
    std::ofstream gp(script);
    gp << scope_script(panels, data, title, target);
    if (!out || !gp) throw std::runtime_error(dir.path + ": cannot write gnuplot's files (disk full?)");
  }
  run_gnuplot(script);
  return 0;
}

}  // namespace hsa::ctl
