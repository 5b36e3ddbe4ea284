// A keyless host on the LAN that answers for hsad: the forger the integration tests play against
// hsactl (test_hsad_trust.py). It reads every command on HSA/<axis>/COMMAND, as anyone can, and
// publishes on HSA/<axis>/STATUS what the sender waits for: its counter acknowledged, its command
// carried out, the state it asked for (ENABLED, DISABLED; --state until the first command), the
// gains it asked for applied. Every 50 ms it also
// publishes a status that claims the axis's lease for --lease-holder. It builds each from the last
// status it overheard from hsad, so the forgery carries hsad's system, instance and MACs: what it
// lacks is the operator's key, so those MACs no longer match.
//
//   hsa-status-forger URL AXIS [--state DISABLED|ENABLED] [--lease-holder NAME] --duration S
#include <lcm/lcm-cpp.hpp>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <optional>
#include <string>

#include "hsa/command_t.hpp"
#include "hsa/status_t.hpp"
#include "msgs/decode_exact.hpp"

namespace {

struct Forger {
  lcm::LCM* lcm = nullptr;
  std::string status_channel;
  std::int8_t state = hsa::status_t::STATE_DISABLED;
  std::string lease_holder;
  std::optional<hsa::status_t> heard;  // hsad's last status before the first forgery
  bool forging = false;
  long answered = 0;

  std::int64_t wall_us() const {
    return std::chrono::duration_cast<std::chrono::microseconds>(std::chrono::system_clock::now().time_since_epoch())
        .count();
  }

  void publish(hsa::status_t s) {
    forging = true;
    s.state = state;
    s.num_faults = 0;
    s.fault_code.clear();
    s.fault_reason.clear();
    s.lease_holder = lease_holder;
    s.lease_remaining_s = lease_holder.empty() ? 0.0 : 30.0;
    s.stamp_us = wall_us();
    lcm->publish(status_channel, &s);
  }

  void on_status(const lcm::ReceiveBuffer* rbuf, const std::string&) {
    hsa::status_t s;
    if (!forging && hsa::msgs::decode_exact(s, rbuf->data, rbuf->data_size)) heard = s;
  }

  void on_command(const lcm::ReceiveBuffer* rbuf, const std::string&) {
    hsa::command_t c;
    if (!heard || !hsa::msgs::decode_exact(c, rbuf->data, rbuf->data_size)) return;
    hsa::status_t s = *heard;
    s.num_acks = 1;
    s.ack_operator = {c.operator_id};
    s.ack_counter = {c.counter};
    s.num_results = 1;
    s.result_operator = {c.operator_id};
    s.result_counter = {c.counter};
    s.result_accepted = {true};
    s.result_reason = {""};
    if (c.command == hsa::command_t::GAINS) {
      s.kp = c.kp;
      s.ki = c.ki;
      s.gain_changes_applied = heard->gain_changes_applied + 1;
    }
    if (c.command == hsa::command_t::ACQUIRE) lease_holder = c.operator_id;
    // What the sender hopes to hear: the state its command asks for.
    if (c.command == hsa::command_t::ENABLE) state = hsa::status_t::STATE_ENABLED;
    if (c.command == hsa::command_t::DISABLE || c.command == hsa::command_t::RESET) {
      state = hsa::status_t::STATE_DISABLED;
    }
    for (int i = 0; i < 3; ++i) publish(s);
    ++answered;
    std::printf("answered command %d of '%s'\n", c.command, c.operator_id.c_str());
    std::fflush(stdout);
  }
};

}  // namespace

int main(int argc, char** argv) {
  if (argc < 3) {
    std::fprintf(stderr, "usage: %s URL AXIS [--state DISABLED|ENABLED] [--lease-holder NAME] [--duration S]\n",
                 argv[0]);
    return 2;
  }
  lcm::LCM lcm(argv[1]);
  if (!lcm.good()) return 2;
  const std::string axis = argv[2];
  Forger forger;
  forger.lcm = &lcm;
  forger.status_channel = "HSA/" + axis + "/STATUS";
  double duration_s = 30.0;
  for (int i = 3; i + 1 < argc; i += 2) {
    const std::string option = argv[i];
    if (option == "--state") {
      forger.state = std::strcmp(argv[i + 1], "ENABLED") == 0 ? hsa::status_t::STATE_ENABLED
                                                               : hsa::status_t::STATE_DISABLED;
    } else if (option == "--lease-holder") {
      forger.lease_holder = argv[i + 1];
    } else if (option == "--duration") {
      duration_s = std::atof(argv[i + 1]);
    }
  }
  lcm.subscribe(forger.status_channel, &Forger::on_status, &forger);
  lcm.subscribe("HSA/" + axis + "/COMMAND", &Forger::on_command, &forger);
  std::printf("forging\n");
  std::fflush(stdout);
  const auto start = std::chrono::steady_clock::now();
  auto next = start;
  while (std::chrono::steady_clock::now() - start < std::chrono::duration<double>(duration_s)) {
    lcm.handleTimeout(10);
    if (forger.heard && std::chrono::steady_clock::now() >= next) {
      forger.publish(*forger.heard);
      next += std::chrono::milliseconds(50);
    }
  }
  std::printf("answered %ld commands in all\n", forger.answered);
  return 0;
}
