#include "daemon/recorder/capture_file.hpp"

#include "daemon/recorder/capture_condition.hpp"

#include <matio.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <stdexcept>
#include <vector>

namespace hsa::daemon {
namespace {

// UTF-8 to UTF-16; a byte that is not part of a valid sequence becomes U+FFFD.
std::vector<std::uint16_t> utf16(const std::string& s) {
  std::vector<std::uint16_t> out;
  out.reserve(s.size());
  for (std::size_t i = 0; i < s.size();) {
    const auto b = static_cast<unsigned char>(s[i]);
    const int extra = b < 0x80 ? 0 : (b >> 5) == 0x6 ? 1 : (b >> 4) == 0xE ? 2 : (b >> 3) == 0x1E ? 3 : -1;
    std::uint32_t cp = extra == 0 ? b : extra == 1 ? (b & 0x1Fu) : extra == 2 ? (b & 0x0Fu) : (b & 0x07u);
    bool ok = extra >= 0 && i + static_cast<std::size_t>(extra) < s.size();
    for (int k = 1; ok && k <= extra; ++k) {
      const auto c = static_cast<unsigned char>(s[i + static_cast<std::size_t>(k)]);
      ok = (c & 0xC0u) == 0x80u;
      cp = (cp << 6) | (c & 0x3Fu);
    }
    if (!ok || cp > 0x10FFFF) {
      out.push_back(0xFFFD);
      ++i;
      continue;
    }
    i += static_cast<std::size_t>(extra) + 1;
    if (cp >= 0x10000) {
      cp -= 0x10000;
      out.push_back(static_cast<std::uint16_t>(0xD800 + (cp >> 10)));
      out.push_back(static_cast<std::uint16_t>(0xDC00 + (cp & 0x3FF)));
    } else {
      out.push_back(static_cast<std::uint16_t>(cp));
    }
  }
  return out;
}

class MatFile {
 public:
  explicit MatFile(const std::string& path) : path_(path), mat_(Mat_CreateVer(path.c_str(), nullptr, MAT_FT_MAT5)) {
    if (mat_ == nullptr) fail("cannot create it");
  }
  MatFile(const MatFile&) = delete;
  MatFile& operator=(const MatFile&) = delete;
  ~MatFile() {
    if (mat_ != nullptr) Mat_Close(mat_);
  }

  void vector(const char* name, std::vector<double>& v) {
    std::size_t dims[2] = {v.size(), 1};
    write(Mat_VarCreate(name, MAT_C_DOUBLE, MAT_T_DOUBLE, 2, dims, v.data(), MAT_F_DONT_COPY_DATA), name);
  }
  void scalar(const char* name, double value) {
    std::size_t dims[2] = {1, 1};
    write(Mat_VarCreate(name, MAT_C_DOUBLE, MAT_T_DOUBLE, 2, dims, &value, MAT_F_DONT_COPY_DATA), name);
  }
  // As UTF-16, MATLAB's own char type: the dimensions count characters, which UTF-8 bytes would not
  // (scipy refuses a UTF-8 text with more bytes than characters).
  void text(const char* name, const std::string& s) {
    std::vector<std::uint16_t> units = utf16(s);
    std::size_t dims[2] = {1, units.size()};
    write(Mat_VarCreate(name, MAT_C_CHAR, MAT_T_UTF16, 2, dims, units.data(), MAT_F_DONT_COPY_DATA), name);
  }
  void close() {
    const int rc = Mat_Close(mat_);
    mat_ = nullptr;
    if (rc != 0) fail("cannot finish it");
  }

 private:
  void write(matvar_t* var, const char* name) {
    if (var == nullptr) fail(std::string("cannot build ") + name);
    const int rc = Mat_VarWrite(mat_, var, MAT_COMPRESSION_ZLIB);
    Mat_VarFree(var);
    if (rc != 0) fail(std::string("cannot write ") + name + " (disk full?)");
  }
  [[noreturn]] void fail(const std::string& what) const {
    const int e = errno;
    throw std::runtime_error(path_ + ": " + what + (e != 0 ? std::string(": ") + std::strerror(e) : ""));
  }
  std::string path_;
  mat_t* mat_;
};

std::string units() {
  std::string text;
#define HSA_RECORDER_UNIT(name, unit, expr) text += std::string(name) + ": " + unit + "\n";
  HSA_RECORDER_SIGNALS(HSA_RECORDER_UNIT)
#undef HSA_RECORDER_UNIT
  text += "t: s from the trigger row\nutime_us: CLOCK_MONOTONIC us (telemetry_t.utime)\n";
  return text;
}

// What the numbers of the state, mode and fault_reason columns mean, and the bit of fault_bits
// each reason sets (fault_bit(reason) = 1 << reason).
std::string codes() {
  std::string text = "state:";
  for (const AxisState s : {AxisState::init, AxisState::disabled, AxisState::enabled, AxisState::fault,
                            AxisState::estop}) {
    text += " " + std::to_string(static_cast<int>(s)) + " " + std::string(to_string(s));
  }
  text += "\nmode:";
  for (const ControlMode m : {ControlMode::position, ControlMode::open_loop}) {
    text += " " + std::to_string(static_cast<int>(m)) + " " + std::string(to_string(m));
  }
  text += "\nfault_reason:";
  for (std::size_t r = 0; r < kFaultReasonCount; ++r) {
    text += " " + std::to_string(r) + " " + std::string(to_string(static_cast<FaultReason>(r)));
  }
  return text + "\n";
}

void write_all(const std::string& path, const Capture& c, const CaptureContext& ctx) {
  MatFile f(path);
  const std::size_t n = c.size();
  std::vector<double> v(n);
  const auto column = [&](auto value) {
    for (std::size_t k = 0; k < n; ++k) v[k] = value(c.row(k));
  };
#define HSA_RECORDER_COLUMN(name, unit, expr)                                      \
  column([](const RecorderRow& r) { return expr; });                               \
  f.vector(name, v);
  HSA_RECORDER_SIGNALS(HSA_RECORDER_COLUMN)
#undef HSA_RECORDER_COLUMN
  const std::int64_t t0 = c.why.t_ns;
  column([t0](const RecorderRow& r) { return static_cast<double>(r.t_ns - t0) * 1e-9; });
  f.vector("t", v);
  const std::int64_t epoch = ctx.epoch_ns;
  column([epoch](const RecorderRow& r) { return static_cast<double>((epoch + r.t_ns) / 1000); });
  f.vector("utime_us", v);

  f.scalar("trigger_index", static_cast<double>(c.trigger_offset() + 1));
  f.scalar("trigger_tick", static_cast<double>(c.why.tick));
  f.scalar("sample_rate_hz", ctx.sample_rate_hz);
  f.scalar("merged_triggers", static_cast<double>(c.merged));
  f.text("axis", ctx.axis);
  f.text("trigger", capture_trigger_word(c.why));
  f.text("condition", c.why.kind == TriggerKind::condition ? capture_condition(c.why) : "");
  f.text("trigger_state", std::string(to_string(c.why.state)));
  f.text("fault", std::string(to_string(c.why.fault.reason)));
  f.text("reason", capture_reason(c.why));
  char gains[96];
  std::snprintf(gains, sizeof gains, "kp = %.9g /m, ki = %.9g /(m s)", c.why.kp, c.why.ki);
  f.text("gains", gains);
  f.text("law", ctx.law);
  f.text("units", units());
  f.text("codes", codes());
  f.text("configuration", ctx.configuration);
  f.close();
}

}  // namespace

std::string capture_trigger_word(const CaptureTrigger& why) {
  switch (why.kind) {
    case TriggerKind::fault: return "fault";
    case TriggerKind::request: return "operator";
    case TriggerKind::condition: return "condition";
  }
  return "?";
}

std::string capture_condition(const CaptureTrigger& why) {
  return describe(ConditionSpec{.signal = why.signal, .crossing = why.crossing, .level = why.level});
}

std::string capture_reason(const CaptureTrigger& why) {
  if (why.kind == TriggerKind::request) return "operator request";
  if (why.kind == TriggerKind::condition) return "condition " + capture_condition(why);
  if (why.fault.reason != FaultReason::none) return describe(why.fault);
  return std::string(to_string(why.state));
}

std::string capture_reason_word(const CaptureTrigger& why) {
  if (why.kind == TriggerKind::request) return "operator";
  if (why.kind == TriggerKind::condition) return capture_condition(why);  // capture_file_name makes it a word
  if (why.fault.reason != FaultReason::none) return std::string(to_string(why.fault.reason));
  return why.state == AxisState::estop ? "estop" : "fault";
}

std::uint64_t write_capture_mat(const std::string& path, const Capture& capture, const CaptureContext& context) {
  const std::string part = path + ".part";
  try {
    errno = 0;
    write_all(part, capture, context);
    std::error_code ec;
    std::filesystem::rename(part, path, ec);
    if (ec) throw std::runtime_error(path + ": cannot rename " + part + ": " + ec.message());
    return std::filesystem::file_size(path, ec);
  } catch (...) {
    std::error_code ignored;
    std::filesystem::remove(part, ignored);
    throw;
  }
}

}  // namespace hsa::daemon
