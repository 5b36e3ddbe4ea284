// The VM's environment check, run first inside the real-kernel VM (tests/kernel/run-in-vm). It uses
// only the kernel interfaces and can-utils, never hsa code, so when it fails the harness is at
// fault, and when it passes while a driver test fails the driver is.
//
// What it checks:
//   - vcan0 carries a classic frame from one raw CAN socket to another, and one sent by can-utils'
//     `cansend` (which the driver tests also use);
//   - the gpio-sim chip at HSA_GPIO_SIM_CHIP has the 8 lines with the names the harness gave them;
//   - a pull written to the chip's sysfs `pull` file is read back through libgpiod 1.6 on an input,
//     and a value driven through libgpiod on an output shows in the sysfs `value` file.
// Without the HSA_* environment it exits 77 (environment missing); run-in-vm counts that as a failure.

#include <gpiod.h>
#include <gtest/gtest.h>
#include <linux/can.h>
#include <linux/can/raw.h>
#include <net/if.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <string>

namespace {

std::string env(const char* name) {
  const char* value = std::getenv(name);
  return value == nullptr ? std::string() : std::string(value);
}

// A raw CAN socket bound to the test interface; closed on scope exit.
class CanSocket {
 public:
  explicit CanSocket(const std::string& iface) : fd_(socket(PF_CAN, SOCK_RAW, CAN_RAW)) {
    if (fd_ < 0) return;
    sockaddr_can addr{};
    addr.can_family = AF_CAN;
    addr.can_ifindex = static_cast<int>(if_nametoindex(iface.c_str()));
    if (addr.can_ifindex == 0 || bind(fd_, reinterpret_cast<sockaddr*>(&addr), sizeof addr) != 0) {
      close(fd_);
      fd_ = -1;
    }
  }
  ~CanSocket() {
    if (fd_ >= 0) close(fd_);
  }
  CanSocket(const CanSocket&) = delete;
  CanSocket& operator=(const CanSocket&) = delete;
  int fd() const { return fd_; }

  // Waits at most 2 s for one frame; false when none came.
  bool receive(can_frame& frame) const {
    pollfd p{fd_, POLLIN, 0};
    if (poll(&p, 1, 2000) != 1) return false;
    return read(fd_, &frame, sizeof frame) == static_cast<ssize_t>(sizeof frame);
  }

 private:
  int fd_;
};

std::string read_file(const std::string& path) {
  std::ifstream in(path);
  std::string word;
  in >> word;
  return word;
}

bool write_file(const std::string& path, const std::string& text) {
  std::ofstream out(path);
  out << text;
  out.flush();
  return static_cast<bool>(out);
}

TEST(Vcan, FrameGoesFromOneRawSocketToAnother) {
  const CanSocket sender(env("HSA_CAN_IFACE"));
  const CanSocket receiver(env("HSA_CAN_IFACE"));
  ASSERT_GE(sender.fd(), 0) << "raw CAN socket on " << env("HSA_CAN_IFACE") << ": " << std::strerror(errno);
  ASSERT_GE(receiver.fd(), 0) << std::strerror(errno);

  can_frame sent{};
  sent.can_id = 0x181;
  sent.len = 4;
  const unsigned char payload[4] = {0x11, 0x22, 0x33, 0x44};
  std::memcpy(sent.data, payload, sizeof payload);
  ASSERT_EQ(write(sender.fd(), &sent, sizeof sent), static_cast<ssize_t>(sizeof sent)) << std::strerror(errno);

  can_frame got{};
  ASSERT_TRUE(receiver.receive(got)) << "no frame within 2 s";
  EXPECT_EQ(got.can_id, 0x181u);
  ASSERT_EQ(got.len, 4);
  EXPECT_EQ(std::memcmp(got.data, payload, sizeof payload), 0);
}

TEST(Vcan, CansendFrameReachesARawSocket) {
  const CanSocket receiver(env("HSA_CAN_IFACE"));
  ASSERT_GE(receiver.fd(), 0) << std::strerror(errno);
  const std::string command = "cansend " + env("HSA_CAN_IFACE") + " 2A5#0102A0B0";
  ASSERT_EQ(std::system(command.c_str()), 0) << command;

  can_frame got{};
  ASSERT_TRUE(receiver.receive(got)) << "no frame within 2 s";
  EXPECT_EQ(got.can_id, 0x2A5u);
  ASSERT_EQ(got.len, 4);
  EXPECT_EQ(got.data[0], 0x01);
  EXPECT_EQ(got.data[3], 0xB0);
}

class GpioSim : public ::testing::Test {
 protected:
  void SetUp() override {
    chip_ = gpiod_chip_open(env("HSA_GPIO_SIM_CHIP").c_str());
    ASSERT_NE(chip_, nullptr) << "gpiod_chip_open(" << env("HSA_GPIO_SIM_CHIP") << "): " << std::strerror(errno);
  }
  void TearDown() override {
    if (chip_ != nullptr) gpiod_chip_close(chip_);  // releases the requested lines too
  }
  std::string sim_file(unsigned offset, const char* name) const {
    return env("HSA_GPIO_SIM_SYSFS") + "/sim_gpio" + std::to_string(offset) + "/" + name;
  }
  gpiod_chip* chip_ = nullptr;
};

TEST_F(GpioSim, ChipHasEightLinesWithTheHarnessNames) {
  EXPECT_EQ(gpiod_chip_num_lines(chip_), 8u);
  const char* names[] = {"hsa-estop", "hsa-valve-enable", "hsa-pump-enable", "hsa-limit-low"};
  for (unsigned offset = 0; offset < 4; ++offset) {
    gpiod_line* line = gpiod_chip_find_line(chip_, names[offset]);
    ASSERT_NE(line, nullptr) << names[offset];
    EXPECT_EQ(gpiod_line_offset(line), offset) << names[offset];
  }
}

TEST_F(GpioSim, PullWrittenInSysfsIsReadThroughLibgpiod) {
  gpiod_line* line = gpiod_chip_get_line(chip_, 3);
  ASSERT_NE(line, nullptr);
  ASSERT_EQ(gpiod_line_request_input(line, "hsa-kernel-smoke"), 0) << std::strerror(errno);

  ASSERT_TRUE(write_file(sim_file(3, "pull"), "pull-up"));
  EXPECT_EQ(gpiod_line_get_value(line), 1);
  ASSERT_TRUE(write_file(sim_file(3, "pull"), "pull-down"));
  EXPECT_EQ(gpiod_line_get_value(line), 0);
}

TEST_F(GpioSim, OutputDrivenThroughLibgpiodShowsInSysfs) {
  gpiod_line* line = gpiod_chip_get_line(chip_, 1);
  ASSERT_NE(line, nullptr);
  ASSERT_EQ(gpiod_line_request_output(line, "hsa-kernel-smoke", 1), 0) << std::strerror(errno);
  EXPECT_EQ(read_file(sim_file(1, "value")), "1");
  ASSERT_EQ(gpiod_line_set_value(line, 0), 0);
  EXPECT_EQ(read_file(sim_file(1, "value")), "0");
}

}  // namespace

int main(int argc, char** argv) {
  for (const char* name : {"HSA_CAN_IFACE", "HSA_GPIO_SIM_CHIP", "HSA_GPIO_SIM_SYSFS"}) {
    if (env(name).empty()) {
      std::fprintf(stderr, "kernel_smoke: %s is not set; this runs inside tests/kernel/run-in-vm\n", name);
      return 77;
    }
  }
  ::testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
