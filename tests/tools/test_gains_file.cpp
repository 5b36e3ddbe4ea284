// `hsactl gains --from FILE`: the gains file `hsa-analyze tune --out` writes is read back as it
// was written, and a file without usable gains is refused naming the file, line and key.
#include "tools/hsactl/gains_file.hpp"

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>

namespace hsa::ctl {
namespace {

std::string write(const std::string& name, const std::string& text) {
  const std::string path = (std::filesystem::temp_directory_path() / name).string();
  std::ofstream(path) << text;
  return path;
}

std::string refusal(const std::string& path) {
  try {
    (void)read_gains_file(path);
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "(not refused)";
}

TEST(GainsFile, ReadsTheGainsOfATuningAndIgnoresItsPrediction) {
  const std::string path = write("hsa-gains-ok.toml",
                                 "# from hsa-analyze tune\nkp = 62.82  # m^-1\nki = 339.98\n\n[prediction]\n"
                                 "plants = \"Table A3\"\nworst_settling_s = 0.549\n");
  const GainsFromFile g = read_gains_file(path);
  EXPECT_EQ(g.kp, 62.82);
  EXPECT_EQ(g.ki, 339.98);
  EXPECT_EQ(read_gains_file(write("hsa-gains-p.toml", "kp = 80\nki = 0\n")).ki, 0.0);  // a P loop
}

TEST(GainsFile, RefusesWhatCannotBeGainsNamingFileLineAndKey) {
  const std::string missing = write("hsa-gains-missing.toml", "kp = 80.0\n");
  EXPECT_EQ(refusal(missing), missing + ": ki: missing (expected a number, >= 0)");
  const std::string text = write("hsa-gains-text.toml", "ki = 3.0\nkp = \"fast\"\n");
  EXPECT_EQ(refusal(text), text + ":2:6: kp: expected a number > 0, got a string");
  const std::string negative = write("hsa-gains-negative.toml", "kp = 80.0\nki = -1.0\n");
  EXPECT_EQ(refusal(negative), negative + ":2:6: ki: expected a number >= 0, got -1");
  const std::string zero = write("hsa-gains-zero.toml", "kp = 0\nki = 1.0\n");
  EXPECT_EQ(refusal(zero), zero + ":1:6: kp: expected a number > 0, got 0");
  const std::string nan = write("hsa-gains-nan.toml", "kp = nan\nki = 1.0\n");
  EXPECT_NE(refusal(nan).find(":1:6: kp: expected a number > 0"), std::string::npos) << refusal(nan);
  const std::string broken = write("hsa-gains-broken.toml", "kp = = 3\n");
  EXPECT_EQ(refusal(broken).rfind(broken + ":1:", 0), 0u) << refusal(broken);
  EXPECT_NE(refusal("/nonexistent/gains.toml").find("/nonexistent/gains.toml"), std::string::npos);
}

}  // namespace
}  // namespace hsa::ctl
