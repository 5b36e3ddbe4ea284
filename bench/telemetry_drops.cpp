// telemetry_drops: a TELEMETRY subscriber that counts what it receives per channel and the samples
// it never saw.
//
//   telemetry_drops [--channels REGEX] [--decimation 10] [--quiet-s 2] [--max-s 900] [--json FILE]
//
// Run it inside the daemon's network namespace before hsad starts; it stops once the channels have
// been silent for --quiet-s after the first message (the daemon has exited), or after --max-s.
//
// telemetry_t.seq is the RT base-tick index of the sample, and the daemon publishes one sample per
// window of `decimation` ticks (rt rate / telemetry rate). A sample lost anywhere (a full ring in
// the daemon, LCM's queues, a socket buffer, or an RT stall long enough to skip a whole window)
// leaves a window with no sample: missing = window(seq) − window(previous seq) − 1, summed. The
// subscriber's own socket buffer and LCM queue are made large (recv_buf_size in the URL, queue
// capacity 100000) so that it does not count its own slowness as the daemon's drops.
#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>
#include <lcm/lcm-cpp.hpp>
#include <time.h>

#include <cstdint>
#include <cstdio>
#include <fstream>
#include <map>
#include <string>

#include "hsa/telemetry_t.hpp"

namespace {

std::int64_t now_ns() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
}

struct ChannelCount {
  std::uint64_t received = 0;
  std::uint64_t missing_windows = 0;  // windows between the first and last sample with no sample
  std::uint64_t backwards = 0;        // seq not increasing (a restarted daemon, or reordering)
  std::uint64_t undecodable = 0;
  std::int64_t first_seq = -1;
  std::int64_t last_seq = -1;
};

struct Counter {
  std::int64_t decimation = 10;
  std::map<std::string, ChannelCount> channels;
  std::int64_t last_rx_ns = 0;

  void on_message(const lcm::ReceiveBuffer* rbuf, const std::string& channel) {
    last_rx_ns = now_ns();
    ChannelCount& c = channels[channel];
    hsa::telemetry_t t;
    if (t.decode(rbuf->data, 0, static_cast<int>(rbuf->data_size)) < 0) {
      ++c.undecodable;
      return;
    }
    ++c.received;
    if (c.last_seq >= 0) {
      const std::int64_t gap = t.seq / decimation - c.last_seq / decimation - 1;
      if (t.seq <= c.last_seq) {
        ++c.backwards;
      } else if (gap > 0) {
        c.missing_windows += static_cast<std::uint64_t>(gap);
      }
    } else {
      c.first_seq = t.seq;
    }
    c.last_seq = t.seq;
  }
};

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"telemetry_drops: count received and missing TELEMETRY samples per channel"};
  std::string url = "udpm://239.255.76.67:7667?ttl=0&recv_buf_size=8388608";
  std::string regex = "HSA/.*/TELEMETRY";
  std::string json_path;
  double quiet_s = 2.0, max_s = 900.0;
  Counter counter;
  app.add_option("--lcm-url", url, "LCM URL")->capture_default_str();
  app.add_option("--channels", regex, "channel regex")->capture_default_str();
  app.add_option("--decimation", counter.decimation, "base ticks per published sample")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  app.add_option("--quiet-s", quiet_s, "stop after this long without a message")->capture_default_str();
  app.add_option("--max-s", max_s, "stop after this long in any case")->capture_default_str();
  app.add_option("--json", json_path, "also write the counts to this file as JSON");
  CLI11_PARSE(app, argc, argv);

  lcm::LCM lcm(url);
  if (!lcm.good()) {
    std::fprintf(stderr, "telemetry_drops: cannot open LCM at %s\n", url.c_str());
    return 1;
  }
  lcm::Subscription* sub = lcm.subscribe(regex, &Counter::on_message, &counter);
  sub->setQueueCapacity(100000);

  const std::int64_t start = now_ns();
  const auto quiet_ns = static_cast<std::int64_t>(quiet_s * 1e9);
  const auto max_ns = static_cast<std::int64_t>(max_s * 1e9);
  for (;;) {
    lcm.handleTimeout(100);
    const std::int64_t now = now_ns();
    if (now - start > max_ns) break;
    if (counter.last_rx_ns != 0 && now - counter.last_rx_ns > quiet_ns) break;
  }

  std::uint64_t received = 0, missing = 0;
  nlohmann::ordered_json per_channel = nlohmann::ordered_json::array();
  for (const auto& [name, c] : counter.channels) {
    received += c.received;
    missing += c.missing_windows;
    std::printf("%-24s received %8llu  missing %6llu  backwards %llu  undecodable %llu  seq %lld..%lld\n", name.c_str(),
                static_cast<unsigned long long>(c.received), static_cast<unsigned long long>(c.missing_windows),
                static_cast<unsigned long long>(c.backwards), static_cast<unsigned long long>(c.undecodable),
                static_cast<long long>(c.first_seq), static_cast<long long>(c.last_seq));
    per_channel.push_back({{"channel", name},
                           {"received", c.received},
                           {"missing_windows", c.missing_windows},
                           {"backwards", c.backwards},
                           {"undecodable", c.undecodable},
                           {"first_seq", c.first_seq},
                           {"last_seq", c.last_seq}});
  }
  std::printf("total: %zu channels, received %llu, missing %llu\n", counter.channels.size(),
              static_cast<unsigned long long>(received), static_cast<unsigned long long>(missing));
  if (!json_path.empty()) {
    std::ofstream out(json_path);
    const nlohmann::ordered_json doc = {{"decimation", counter.decimation},
                                        {"received", received},
                                        {"missing_windows", missing},
                                        {"channels", std::move(per_channel)}};
    out << doc.dump(2) << "\n";
    if (!out) {
      std::fprintf(stderr, "telemetry_drops: cannot write %s\n", json_path.c_str());
      return 1;
    }
  }
  return 0;
}
