#include "tools/hsactl/capture_reader.hpp"

#include <matio.h>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <memory>
#include <set>
#include <sstream>

namespace hsa::ctl {
namespace {

// libmatio reports a file it cannot parse on stderr as well as by its return values; hsactl names
// the file itself, once, so the library's own lines are dropped.
void quiet(int, char*) {}

struct MatCloser {
  void operator()(mat_t* m) const { Mat_Close(m); }
};
struct VarFreer {
  void operator()(matvar_t* v) const { Mat_VarFree(v); }
};
using MatPtr = std::unique_ptr<mat_t, MatCloser>;
using VarPtr = std::unique_ptr<matvar_t, VarFreer>;

// The scalars a capture holds beside its signals (all 1x1 doubles).
const std::set<std::string> kScalars = {"trigger_index", "trigger_tick", "sample_rate_hz", "merged_triggers"};

bool is_column(const matvar_t* v) {
  return v->class_type == MAT_C_DOUBLE && v->rank == 2 && v->dims[1] == 1 && v->isComplex == 0 &&
         kScalars.count(v->name != nullptr ? v->name : "") == 0;
}

void append_utf8(std::string& out, std::uint32_t cp) {
  if (cp < 0x80) {
    out += static_cast<char>(cp);
  } else if (cp < 0x800) {
    out += static_cast<char>(0xC0 | (cp >> 6));
    out += static_cast<char>(0x80 | (cp & 0x3F));
  } else if (cp < 0x10000) {
    out += static_cast<char>(0xE0 | (cp >> 12));
    out += static_cast<char>(0x80 | ((cp >> 6) & 0x3F));
    out += static_cast<char>(0x80 | (cp & 0x3F));
  } else {
    out += static_cast<char>(0xF0 | (cp >> 18));
    out += static_cast<char>(0x80 | ((cp >> 12) & 0x3F));
    out += static_cast<char>(0x80 | ((cp >> 6) & 0x3F));
    out += static_cast<char>(0x80 | (cp & 0x3F));
  }
}

// A char variable as UTF-8: UTF-16 (what the recorder writes, surrogate pairs joined) or 8-bit.
// "" when the variable is missing or not text.
std::string read_text(mat_t* mat, const char* name) {
  VarPtr v(Mat_VarRead(mat, name));
  if (!v || v->class_type != MAT_C_CHAR || v->rank != 2 || v->data == nullptr) return "";
  const std::size_t n = v->dims[0] * v->dims[1];
  std::string out;
  if (v->data_type == MAT_T_UTF16 || v->data_type == MAT_T_UINT16) {
    const auto* u = static_cast<const std::uint16_t*>(v->data);
    for (std::size_t i = 0; i < n; ++i) {
      std::uint32_t cp = u[i];
      if (cp >= 0xD800 && cp < 0xDC00 && i + 1 < n && u[i + 1] >= 0xDC00 && u[i + 1] < 0xE000) {
        cp = 0x10000 + ((cp - 0xD800) << 10) + (u[i + 1] - 0xDC00);
        ++i;
      }
      append_utf8(out, cp);
    }
  } else if (v->data_type == MAT_T_UTF8 || v->data_type == MAT_T_UINT8 || v->data_type == MAT_T_INT8) {
    out.assign(static_cast<const char*>(v->data), n);
  }
  return out;
}

// A 1x1 double, or NaN when missing or not one.
double read_scalar(mat_t* mat, const char* name) {
  VarPtr v(Mat_VarRead(mat, name));
  if (!v || v->class_type != MAT_C_DOUBLE || v->rank != 2 || v->dims[0] * v->dims[1] != 1 || v->data == nullptr)
    return std::nan("");
  return *static_cast<const double*>(v->data);
}

// `units`: one "name: unit" line per signal.
std::string unit_of(const std::string& units, const std::string& name) {
  std::istringstream lines(units);
  for (std::string line; std::getline(lines, line);) {
    if (line.size() > name.size() + 1 && line.compare(0, name.size(), name) == 0 && line[name.size()] == ':')
      return line.substr(line.find_first_not_of(' ', name.size() + 1));
  }
  return "";
}

Capture read(const std::string& path, bool values) {
  static const int log_once = Mat_LogInitFunc("hsactl", quiet);
  (void)log_once;
  // libmatio says only that it could not open it: a missing or unreadable file is named as such.
  if (std::FILE* f = std::fopen(path.c_str(), "rb"); f == nullptr) {
    throw CaptureFileError(path + ": cannot read it: " + std::strerror(errno));
  } else {
    std::fclose(f);
  }
  MatPtr mat(Mat_Open(path.c_str(), MAT_ACC_RDONLY));
  if (!mat) throw CaptureFileError(path + ": not a MAT-file");
  if (Mat_GetVersion(mat.get()) != MAT_FT_MAT5)
    throw CaptureFileError(path + ": a MAT-file, but not level 5 as the flight recorder writes");

  Capture c;
  // Every variable's name, class and dimensions, in the file's order, without its data.
  std::vector<std::string> names;
  while (VarPtr info{Mat_VarReadNextInfo(mat.get())}) {
    if (info->name == nullptr || !is_column(info.get())) continue;
    if (!names.empty() && info->dims[0] != c.rows)
      throw CaptureFileError(path + ": not a capture: its vectors differ in length ('" + names.front() + "' has " +
                             std::to_string(c.rows) + " rows, '" + info->name + "' " +
                             std::to_string(info->dims[0]) + ")");
    c.rows = info->dims[0];
    names.emplace_back(info->name);
  }
  const double trigger_index = read_scalar(mat.get(), "trigger_index");
  if (std::isnan(trigger_index)) throw CaptureFileError(path + ": not a flight recorder capture (no trigger_index)");
  if (names.empty() || c.rows == 0) throw CaptureFileError(path + ": not a flight recorder capture (no signals)");
  if (trigger_index < 1 || trigger_index > static_cast<double>(c.rows) || trigger_index != std::floor(trigger_index))
    throw CaptureFileError(path + ": trigger_index " + std::to_string(trigger_index) + " is not a row of its " +
                           std::to_string(c.rows) + " rows (1-based)");
  c.trigger_index = static_cast<std::size_t>(trigger_index);
  c.trigger_tick = read_scalar(mat.get(), "trigger_tick");
  const double rate = read_scalar(mat.get(), "sample_rate_hz");
  c.sample_rate_hz = std::isfinite(rate) && rate > 0 ? rate : 0.0;
  const double merged = read_scalar(mat.get(), "merged_triggers");
  c.merged_triggers = std::isnan(merged) ? 0.0 : merged;
  c.axis = read_text(mat.get(), "axis");
  c.trigger = read_text(mat.get(), "trigger");
  c.trigger_state = read_text(mat.get(), "trigger_state");
  c.fault = read_text(mat.get(), "fault");
  c.reason = read_text(mat.get(), "reason");
  c.gains = read_text(mat.get(), "gains");
  c.law = read_text(mat.get(), "law");
  if (c.sample_rate_hz > 0) {
    c.duration_s = static_cast<double>(c.rows) / c.sample_rate_hz;
    VarPtr t(Mat_VarRead(mat.get(), "t"));
    if (t && is_column(t.get()) && t->dims[0] == c.rows && t->data != nullptr) {
      const auto* d = static_cast<const double*>(t->data);
      c.duration_s = d[c.rows - 1] - d[0] + 1.0 / c.sample_rate_hz;
    }
  }
  const std::string units = read_text(mat.get(), "units");
  for (const std::string& name : names) {
    CaptureSignal s{name, unit_of(units, name), {}};
    if (values) {
      VarPtr v(Mat_VarRead(mat.get(), name.c_str()));
      if (!v || v->data == nullptr) throw CaptureFileError(path + ": cannot read '" + name + "' (a damaged file?)");
      const auto* d = static_cast<const double*>(v->data);
      s.values.assign(d, d + c.rows);
    }
    c.signals.push_back(std::move(s));
  }
  return c;
}

}  // namespace

const CaptureSignal* Capture::signal(const std::string& name) const {
  for (const CaptureSignal& s : signals)
    if (s.name == name) return &s;
  return nullptr;
}

Capture read_capture_header(const std::string& path) { return read(path, false); }
Capture read_capture(const std::string& path) { return read(path, true); }

}  // namespace hsa::ctl
