// hsa-simdev, the simulated rig served over Modbus TCP: answered correctly by mbpoll (a Modbus
// master nobody here wrote), and driven end to end by the modbus plugin: a command through the
// plugin moves the simulated rod, and a position loop closed through both reaches its setpoint.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <regex>
#include <string>

#include <toml++/toml.h>

#include "drivers/driver_handle.hpp"
#include "drivers/plugin_loader.hpp"
#include "tests/drivers/modbus_driver_loop.hpp"
#include "tests/drivers/test_modbus_support.hpp"
#include "tools/hsa_simdev/register_map.hpp"

namespace hsa::io {
namespace {

using namespace std::chrono_literals;
using modbus_test::ChildProcess;
using modbus_test::DriverLoop;
using modbus_test::wait_until;
namespace map = hsa::simdev;

// hsa-simdev on a free port, for at most 60 s whatever happens to the test.
class Simdev {
 public:
  Simdev() : process_({HSA_SIMDEV, "--port", "0", "--duration", "60"}) {
    const auto line = process_.read_line(10s);
    std::smatch m;
    if (line && std::regex_search(*line, m, std::regex("listening on 127\\.0\\.0\\.1:([0-9]+)"))) {
      port_ = std::stoi(m[1]);
    }
  }
  [[nodiscard]] int port() const { return port_; }

 private:
  ChildProcess process_;
  int port_ = 0;
};

// mbpoll's output and exit status.
struct Poll {
  int status = -1;
  std::string output;
};

// mbpoll [options] host [values to write]
Poll mbpoll(int port, const std::vector<std::string>& args, const std::vector<std::string>& write = {}) {
  std::vector<std::string> argv{HSA_MBPOLL, "-m", "tcp", "-a", "1", "-0", "-1", "-o", "2"};
  argv.insert(argv.end(), args.begin(), args.end());
  argv.insert(argv.end(), {"-p", std::to_string(port), "127.0.0.1"});
  argv.insert(argv.end(), write.begin(), write.end());
  ChildProcess p(argv);
  Poll result;
  result.output = p.read_all(10s);
  result.status = p.wait_exit(5s).value_or(-1);
  return result;
}

// The value mbpoll printed for `reference` ("[2]: \t1.1082e+06"), or NaN.
double value_at(const std::string& output, int reference) {
  std::smatch m;
  const std::regex line("\\[" + std::to_string(reference) + "\\]:\\s+(-?[0-9.eE+-]+)");
  return std::regex_search(output, m, line) ? std::stod(m[1]) : std::nan("");
}

TEST(ModbusSimdev, AnswersMbpoll) {
  if (std::string(HSA_MBPOLL).empty()) GTEST_SKIP() << "mbpoll is not installed";
  Simdev simdev;
  ASSERT_NE(simdev.port(), 0) << "hsa-simdev did not report its port";

  // Float32 input registers, high word first (-B): position, pressures A and B.
  const Poll floats = mbpoll(simdev.port(), {"-B", "-t", "3:float", "-r", std::to_string(map::input_register::position_m), "-c", "3"});
  ASSERT_EQ(floats.status, 0) << floats.output;
  EXPECT_NEAR(value_at(floats.output, 0), 0.150, 1e-3) << floats.output;  // the initial position
  for (const int ref : {2, 4}) {
    const double p = value_at(floats.output, ref);
    EXPECT_GT(p, 1e5) << floats.output;  // a rod held against gravity by pressurised chambers
    EXPECT_LT(p, 2.6e6) << floats.output;  // never above the relief setting of 25 bar
  }

  // The same position as a scaled int32 (1 µm per count).
  const Poll ints = mbpoll(simdev.port(), {"-B", "-t", "3:int", "-r", std::to_string(map::input_register::position_um_i32)});
  ASSERT_EQ(ints.status, 0) << ints.output;
  EXPECT_NEAR(value_at(ints.output, 20), 150000, 1000) << ints.output;

  // Writes: press the e-stop button through its coil; the e-stop loop input opens.
  const Poll closed = mbpoll(simdev.port(), {"-t", "1", "-r", "0"});
  ASSERT_EQ(closed.status, 0) << closed.output;
  EXPECT_EQ(value_at(closed.output, 0), 1.0) << closed.output;
  ASSERT_EQ(mbpoll(simdev.port(), {"-t", "0", "-r", std::to_string(map::coil::estop_button)}, {"1"}).status, 0);
  double loop = 1.0;
  wait_until([&] {
    loop = value_at(mbpoll(simdev.port(), {"-t", "1", "-r", "0"}).output, 0);
    return loop == 0.0;
  }, 3s);
  EXPECT_EQ(loop, 0.0);
}

std::string simdev_settings(int port) {
  return "transport = \"tcp\"\nhost = \"127.0.0.1\"\nport = " + std::to_string(port) + R"(
poll_period_s = 0.002
response_timeout_s = 0.1
max_age_s = 0.05
[[channels]]
name = "encoder"
kind = "encoder_input"
table = "input_register"
address = 0
type = "float32"
unit = "m"
[[channels]]
name = "pressure_a"
kind = "analog_input"
table = "input_register"
address = 22
type = "int32"
unit = "Pa"
[[channels]]
name = "opening_cmd"
kind = "analog_output"
table = "holding_register"
address = 0
type = "float32"
[[channels]]
name = "valve_enable"
kind = "digital_output"
table = "coil"
address = 0
[[channels]]
name = "estop"
kind = "digital_input"
table = "discrete_input"
address = 0
)";
}

TEST(ModbusSimdev, PluginCommandMovesTheRodAndClosesAPositionLoop) {
  Simdev simdev;
  ASSERT_NE(simdev.port(), 0) << "hsa-simdev did not report its port";
  DriverLoop loop(simdev_settings(simdev.port()));

  ASSERT_TRUE(loop.run_until([&] { return loop.slot("encoder").status == SampleStatus::ok; }, 3s));
  EXPECT_EQ(loop.slot("estop").value, 1.0);  // loop closed: not pressed
  EXPECT_GT(loop.slot("pressure_a").value, 1e5);
  const double start = loop.slot("encoder").value;
  EXPECT_NEAR(start, 0.150, 1e-3);

  // Open loop: a positive opening extends the rod, a negative one retracts it.
  ASSERT_TRUE(loop.driver->activate().ok());
  loop.slot("valve_enable").value = 1.0;
  loop.slot("opening_cmd").value = 0.2;
  ASSERT_TRUE(loop.run_until([&] { return loop.slot("encoder").value > start + 0.005; }, 5s))
      << "rod at " << loop.slot("encoder").value;
  loop.slot("opening_cmd").value = -0.2;
  ASSERT_TRUE(loop.run_until([&] { return loop.slot("encoder").value < start; }, 5s)) << "rod at " << loop.slot("encoder").value;

  // Closed loop through the bus: proportional position control to 20 mm above the start.
  const double setpoint = start + 0.020;
  const auto settled = [&] {
    const double x = loop.slot("encoder").value;
    loop.slot("opening_cmd").value = std::clamp(25.0 * (setpoint - x), -0.3, 0.3);
    return std::abs(setpoint - x) < 1e-3 && loop.slot("encoder").status == SampleStatus::ok;
  };
  ASSERT_TRUE(loop.run_until(settled, 8s)) << "rod at " << loop.slot("encoder").value << ", setpoint " << setpoint;
  // And it stays there.
  loop.run_until([&] { (void)settled(); return false; }, 500ms);
  EXPECT_NEAR(loop.slot("encoder").value, setpoint, 2e-3);

  // Deactivation: amplifier off, command 0, confirmed on the device before it returns.
  ASSERT_TRUE(loop.driver->deactivate().ok());
  EXPECT_EQ(loop.slot("link_errors").value, 0.0);
  EXPECT_EQ(loop.slot("transaction_errors").value, 0.0);
}

}  // namespace
}  // namespace hsa::io
