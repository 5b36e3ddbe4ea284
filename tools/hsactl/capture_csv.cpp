#include "tools/hsactl/capture_csv.hpp"

#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <stdexcept>

namespace hsa::ctl {
namespace {

// RFC 4180: a field with a comma, a quote or a line break goes in quotes, its quotes doubled.
std::string csv_field(const std::string& s) {
  if (s.find_first_of(",\"\r\n") == std::string::npos) return s;
  std::string out = "\"";
  for (const char ch : s) out += ch == '"' ? std::string("\"\"") : std::string(1, ch);
  return out + "\"";
}

}  // namespace

void write_capture_csv(std::ostream& out, const Capture& c) {
  for (const CaptureSignal& s : c.signals) out << csv_field(s.unit.empty() ? s.name : s.name + " [" + s.unit + "]") << ',';
  out << "trigger\n";
  char number[64];
  for (std::size_t k = 0; k < c.rows; ++k) {
    for (const CaptureSignal& s : c.signals) {
      // Counts and times in ns are whole numbers: written as such, not as 1.03e+09.
      const double v = s.values.at(k);
      const auto r = v == std::trunc(v) && std::fabs(v) < 1e15
                         ? std::to_chars(number, number + sizeof number, static_cast<long long>(v))
                         : std::to_chars(number, number + sizeof number, v);
      out.write(number, r.ptr - number);
      out.put(',');
    }
    out << (k + 1 == c.trigger_index ? "1\n" : "0\n");
  }
}

void export_capture_csv(const std::string& mat, const std::string& csv, bool overwrite) {
  std::error_code ec;
  if (!overwrite && std::filesystem::exists(csv, ec))
    throw std::runtime_error(csv + " exists: not overwritten (--force overwrites it)");
  const Capture c = read_capture(mat);
  const std::string part = csv + ".part";
  try {
    {
      std::ofstream out(part, std::ios::trunc);
      if (!out) throw std::runtime_error(csv + ": cannot write it: " + std::strerror(errno));
      write_capture_csv(out, c);
      out.flush();
      if (!out) throw std::runtime_error(csv + ": cannot write it (disk full?)");
    }
    std::filesystem::rename(part, csv);
  } catch (...) {
    std::filesystem::remove(part, ec);
    throw;
  }
}

}  // namespace hsa::ctl
