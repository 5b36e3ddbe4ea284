// setpoint_latency: how long a setpoint takes from an LCM client to the cycle of hsad's RT loop that
// takes it, beside the raw LCM round trip measured in the same run.
//
//   setpoint_latency --axis lift [--trials 1000] [--lcm-url URL] [--json FILE]
//
// Run it inside a private network namespace, with hsad running on a configuration that publishes
// telemetry on every base tick (bench/configs/hsad-setpoint.toml); bench/setpoint-latency does both.
//
// Method. Each trial does two things, in alternating order so neither always goes first:
//   - a setpoint: a setpoint_t on HSA/<axis>/SETPOINT whose utime is the send time (CLOCK_MONOTONIC,
//     µs) and whose position alternates between two values inside the soft limits. The daemon
//     carries the utime of the setpoint its loop follows in every telemetry sample
//     (telemetry_t.setpoint_utime), and stamps the sample with the time its cycle woke
//     (telemetry_t.utime, CLOCK_MONOTONIC µs). The first sample that carries the new utime is the
//     cycle that took the setpoint off its ring; its utime minus the send time is the
//     setpoint-to-loop latency. Both clocks are CLOCK_MONOTONIC on the same host, so the difference
//     needs no synchronisation. With telemetry on every tick the first sample is that very cycle,
//     unless a telemetry sample was lost on the way back: then the seq of the sample before it is
//     not one less (after allowing for periods the RT loop skipped, telemetry_t.overruns), and the
//     trial is counted as inexact (its latency is an upper bound).
//   - a ping: a setpoint_t on HSA_BENCH/PING that a second lcm::LCM instance in this process (own
//     thread, own sockets) echoes on HSA_BENCH/PONG: the raw LCM round trip through the kernel's
//     multicast loopback, the reference the target is set against. The ping-pong uses its own
//     multicast group (--ping-url): every udpm instance on a group receives every message on it, so
//     on the daemon's group both ends would also be decoding 10 kHz of telemetry, and the round trip
//     would no longer be LCM's own.
// Between trials it waits 2-4 ms (a fixed-seed pseudo-random gap), so setpoints arrive at every
// phase of the 100 µs tick.
//
// Output: p50, p99, p99.9 and max of each, the counts of timeouts and inexact trials, on stdout and
// as JSON. Every wait is bounded (--timeout-ms per message).
#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>
#include <lcm/lcm-cpp.hpp>
#include <time.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <optional>
#include <random>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "hsa/setpoint_t.hpp"
#include "msgs/auth/message_mac.hpp"
#include "msgs/auth/status_mac.hpp"
#include "msgs/decode_exact.hpp"
#include "hsa/telemetry_t.hpp"

namespace {

constexpr const char* kPing = "HSA_BENCH/PING";
constexpr const char* kPong = "HSA_BENCH/PONG";

std::int64_t now_ns() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
}

// The echo side of the round trip: its own LCM instance, so the ping crosses the kernel twice
// exactly like a setpoint to hsad and its telemetry back.
class Echo {
 public:
  explicit Echo(const std::string& url) : lcm_(url) {
    if (!lcm_.good()) throw std::runtime_error("setpoint_latency: cannot open LCM for the echo at " + url);
    lcm_.subscribe(kPing, &Echo::on_ping, this);
    thread_ = std::thread([this] {
      while (!stop_.load()) lcm_.handleTimeout(50);
    });
  }
  ~Echo() {
    stop_.store(true);
    thread_.join();
  }

 private:
  void on_ping(const lcm::ReceiveBuffer* rbuf, const std::string&) { lcm_.publish(kPong, rbuf->data, rbuf->data_size); }

  lcm::LCM lcm_;
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

struct Client {
  std::int64_t awaited_setpoint_utime = -1;  // the setpoint whose first cycle we wait for
  std::int64_t found_cycle_utime = 0;
  std::int64_t found_at_ns = 0;              // when its telemetry arrived here
  bool found = false;
  bool exact = false;
  std::int64_t last_seq = -1;                // seq of the latest telemetry sample seen
  std::int64_t last_overruns = 0;            // and its count of skipped periods
  std::int64_t awaited_ping_seq = -1;
  std::int64_t pong_at_ns = 0;
  bool ponged = false;

  void on_telemetry(const lcm::ReceiveBuffer*, const std::string&, const hsa::telemetry_t* t) {
    if (!found && awaited_setpoint_utime >= 0 && t->setpoint_utime == awaited_setpoint_utime) {
      found = true;
      found_at_ns = now_ns();
      found_cycle_utime = t->utime;
      // The cycle before this one published too, unless the RT loop skipped periods in between
      // (telemetry_t.overruns counts the skipped periods), in which case no cycle ran there.
      exact = last_seq >= 0 && t->seq == last_seq + 1 + (t->overruns - last_overruns);
    }
    last_seq = t->seq;
    last_overruns = t->overruns;
  }
  void on_pong(const lcm::ReceiveBuffer*, const std::string&, const hsa::setpoint_t* p) {
    if (p->seq == awaited_ping_seq) {
      ponged = true;
      pong_at_ns = now_ns();
    }
  }
};

// The hsad the setpoints are for: the system and instance of the first status the key verifies
// (hsad refuses setpoints signed for another daemon).
struct DaemonLearner {
  const hsa::msgs::OperatorKey* key = nullptr;
  bool verified = false;
  std::string system;
  std::int64_t instance = 0;
  void on_status(const lcm::ReceiveBuffer* rbuf, const std::string& channel) {
    hsa::status_t s;
    if (verified || !hsa::msgs::decode_exact(s, rbuf->data, rbuf->data_size)) return;
    if (hsa::msgs::verify_status(s, *key, channel) != hsa::msgs::StatusMacCheck::verified) return;
    system = s.system;
    instance = s.instance;
    verified = true;
  }
};

struct Summary {
  std::size_t n = 0;
  double p50 = 0, p99 = 0, p999 = 0, max = 0;
};

// Nearest-rank percentiles, in µs.
Summary summarize(std::vector<double> v) {
  Summary s;
  s.n = v.size();
  if (v.empty()) return s;
  std::sort(v.begin(), v.end());
  auto at = [&](double q) {
    const auto rank = static_cast<std::size_t>(std::ceil(q * static_cast<double>(v.size()) - 1e-9));
    return v[std::clamp<std::size_t>(rank, 1, v.size()) - 1];
  };
  s.p50 = at(0.50);
  s.p99 = at(0.99);
  s.p999 = at(0.999);
  s.max = v.back();
  return s;
}

nlohmann::ordered_json json(const Summary& s) {
  return {{"n", s.n}, {"p50_us", s.p50}, {"p99_us", s.p99}, {"p99.9_us", s.p999}, {"max_us", s.max}};
}

void print(const char* what, const Summary& s) {
  std::printf("%-34s n %5zu  p50 %8.1f µs  p99 %8.1f µs  p99.9 %8.1f µs  max %8.1f µs\n", what, s.n, s.p50, s.p99, s.p999,
              s.max);
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"setpoint_latency: setpoint-to-loop latency of hsad beside the raw LCM round trip"};
  std::string axis = "lift";
  std::string url = "udpm://239.255.76.67:7667?ttl=0&recv_buf_size=2097152";
  std::string ping_url = "udpm://239.255.76.68:7668?ttl=0&recv_buf_size=2097152";
  std::string json_path;
  int trials = 1000;
  int timeout_ms = 200;
  double position_m = 0.15;
  app.add_option("--axis", axis, "axis name (channels HSA/<axis>/...)")->capture_default_str();
  app.add_option("--lcm-url", url, "LCM URL of the daemon")->capture_default_str();
  app.add_option("--ping-url", ping_url, "LCM URL of the round-trip ping-pong")->capture_default_str();
  app.add_option("--trials", trials, "setpoints (and pings) to send")->check(CLI::PositiveNumber)->capture_default_str();
  app.add_option("--timeout-ms", timeout_ms, "longest wait for one answer")->check(CLI::PositiveNumber)->capture_default_str();
  app.add_option("--position", position_m, "setpoints alternate between this and 1 mm above, m")->capture_default_str();
  app.add_option("--json", json_path, "also write the summary to this file as JSON");
  std::string key_path;
  app.add_option("--key", key_path, "operator key that signs the setpoints, as hsactl's --key")->envname("HSA_KEY");
  CLI11_PARSE(app, argc, argv);

  try {
    Echo echo(ping_url);
    lcm::LCM lcm(url);
    lcm::LCM ping_lcm(ping_url);
    std::optional<hsa::msgs::OperatorKey> key;
    if (!key_path.empty()) key = hsa::msgs::read_key_file(key_path);
    // Setpoints and pings alike are signed as an operator's client signs them (the ping is not
    // checked by its echo; it is signed so that both carry the same bytes and the same work).
    std::int64_t counter = 0;
    // The daemon the setpoints are for, learned from its verified status as hsactl learns it.
    std::string daemon_system;
    std::int64_t daemon_instance = 0;
    auto publish = [&](lcm::LCM& on, const std::string& channel, hsa::setpoint_t& msg) {
      msg.stamp_us = std::chrono::duration_cast<std::chrono::microseconds>(
                         std::chrono::system_clock::now().time_since_epoch()).count();
      msg.system = daemon_system;
      msg.instance = daemon_instance;
      if (!key) return on.publish(channel, &msg);
      msg.operator_id = key->operator_id;
      msg.counter = ++counter;
      const std::vector<std::uint8_t> bytes = hsa::msgs::encode_signed(msg, key->key, channel);
      return on.publish(channel, bytes.data(), static_cast<unsigned int>(bytes.size()));
    };
    if (!lcm.good()) throw std::runtime_error("cannot open LCM at " + url);
    if (!ping_lcm.good()) throw std::runtime_error("cannot open LCM at " + ping_url);
    Client client;
    lcm::Subscription* tsub = lcm.subscribe("HSA/" + axis + "/TELEMETRY", &Client::on_telemetry, &client);
    lcm::Subscription* psub = ping_lcm.subscribe(kPong, &Client::on_pong, &client);
    tsub->setQueueCapacity(100000);  // 10 kHz of telemetry: LCM's default (30) is 3 ms
    psub->setQueueCapacity(1000);

    // Wait for the daemon's telemetry, so the first trial does not time out on start-up.
    const std::int64_t ready_deadline = now_ns() + 5'000'000'000;
    while (client.last_seq < 0 && now_ns() < ready_deadline) lcm.handleTimeout(100);
    if (client.last_seq < 0) throw std::runtime_error("no telemetry on HSA/" + axis + "/TELEMETRY within 5 s");
    if (key) {
      DaemonLearner learner;
      learner.key = &*key;
      lcm::Subscription* ssub = lcm.subscribe("HSA/" + axis + "/STATUS", &DaemonLearner::on_status, &learner);
      while (!learner.verified && now_ns() < ready_deadline + 5'000'000'000) lcm.handleTimeout(100);
      lcm.unsubscribe(ssub);
      if (!learner.verified) throw std::runtime_error("no status of axis '" + axis + "' verified with the key");
      daemon_system = learner.system;
      daemon_instance = learner.instance;
    }

    std::mt19937 rng(12345);
    std::uniform_int_distribution<int> gap_us(2000, 4000);
    std::vector<double> to_loop, to_client, rtt;
    int setpoint_timeouts = 0, ping_timeouts = 0, inexact = 0;
    std::int64_t last_sent_utime = 0;

    auto wait_for = [&](lcm::LCM& on, const bool& flag) {
      const std::int64_t deadline = now_ns() + std::int64_t{timeout_ms} * 1'000'000;
      while (!flag && now_ns() < deadline) on.handleTimeout(std::max<int>(1, timeout_ms / 10));
      return flag;
    };
    auto do_setpoint = [&](int i) {
      hsa::setpoint_t sp{};
      std::int64_t sent_ns = now_ns();
      // Two setpoints within one µs would share a utime and could not be told apart.
      while (sent_ns / 1000 <= last_sent_utime) sent_ns = now_ns();
      sp.utime = sent_ns / 1000;
      last_sent_utime = sp.utime;
      sp.seq = i + 1;
      sp.position_m = position_m + (i % 2 == 0 ? 0.0 : 1e-3);
      client.awaited_setpoint_utime = sp.utime;
      client.found = false;
      publish(lcm, "HSA/" + axis + "/SETPOINT", sp);
      if (!wait_for(lcm, client.found)) {
        ++setpoint_timeouts;
        return;
      }
      if (!client.exact) ++inexact;
      to_loop.push_back(static_cast<double>(client.found_cycle_utime - sp.utime));
      to_client.push_back(static_cast<double>(client.found_at_ns - sent_ns) / 1e3);
    };
    auto do_ping = [&](int i) {
      hsa::setpoint_t ping{};
      ping.seq = i + 1;
      client.awaited_ping_seq = ping.seq;
      client.ponged = false;
      const std::int64_t sent_ns = now_ns();
      ping.utime = sent_ns / 1000;
      publish(ping_lcm, kPing, ping);
      if (!wait_for(ping_lcm, client.ponged)) {
        ++ping_timeouts;
        return;
      }
      rtt.push_back(static_cast<double>(client.pong_at_ns - sent_ns) / 1e3);
    };

    for (int i = 0; i < trials; ++i) {
      if (i % 2 == 0) {
        do_setpoint(i);
        do_ping(i);
      } else {
        do_ping(i);
        do_setpoint(i);
      }
      // Sleep off the gap while still draining telemetry, so LCM's queues never fill.
      const std::int64_t until = now_ns() + std::int64_t{gap_us(rng)} * 1000;
      while (now_ns() < until) lcm.handleTimeout(1);
    }

    const Summary loop_s = summarize(to_loop), client_s = summarize(to_client), rtt_s = summarize(rtt);
    print("setpoint -> cycle that took it", loop_s);
    print("setpoint -> its telemetry here", client_s);
    print("LCM round trip (ping-pong)", rtt_s);
    std::printf("timeouts: %d setpoints, %d pings; inexact (a telemetry sample lost): %d\n", setpoint_timeouts,
                ping_timeouts, inexact);
    if (!json_path.empty()) {
      std::ofstream out(json_path);
      const nlohmann::ordered_json doc = {{"setpoint_to_cycle", json(loop_s)},
                                          {"setpoint_to_client", json(client_s)},
                                          {"lcm_round_trip", json(rtt_s)},
                                          {"trials", trials},
                                          {"setpoint_timeouts", setpoint_timeouts},
                                          {"ping_timeouts", ping_timeouts},
                                          {"inexact", inexact}};
      out << doc.dump() << "\n";
      if (!out) throw std::runtime_error("cannot write " + json_path);
    }
    return setpoint_timeouts + ping_timeouts == trials * 2 ? 1 : 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "setpoint_latency: %s\n", e.what());
    return 1;
  }
}
