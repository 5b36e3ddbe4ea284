#include "tools/hsactl/driver_report.hpp"

namespace hsa::ctl {
namespace {

const char* link_name(std::int8_t link) {
  switch (link) {
    case hsa::driver_status_t::LINK_UP: return "link up";
    case hsa::driver_status_t::LINK_DOWN: return "LINK DOWN";
    case hsa::driver_status_t::LINK_NOT_ANSWERING: return "NOT ANSWERING";
    default: return "no link";
  }
}

}  // namespace

std::string driver_report(const hsa::driver_status_t& d) {
  std::string line = d.name + " (" + d.plugin + "): " + d.state + ", " + link_name(d.link);
  for (int i = 0; i < d.num_counters; ++i) {
    line += (i == 0 ? "; " : ", ") + d.counter_name[static_cast<std::size_t>(i)] + " " +
            std::to_string(d.counter_value[static_cast<std::size_t>(i)]);
  }
  if (!d.last_error.empty()) line += "\n    last error: " + d.last_error;
  if (!d.failure.empty()) line += "\n    failure: " + d.failure;
  return line;
}

nlohmann::ordered_json driver_json(const hsa::driver_status_t& d) {
  nlohmann::ordered_json o;
  o["name"] = d.name;
  o["plugin"] = d.plugin;
  o["state"] = d.state;
  o["failure"] = d.failure;
  o["link"] = d.link == hsa::driver_status_t::LINK_UP            ? "up"
              : d.link == hsa::driver_status_t::LINK_DOWN          ? "down"
              : d.link == hsa::driver_status_t::LINK_NOT_ANSWERING ? "not answering"
                                                                   : "none";
  o["last_error"] = d.last_error;
  nlohmann::ordered_json counters = nlohmann::ordered_json::object();
  for (int i = 0; i < d.num_counters; ++i) {
    counters[d.counter_name[static_cast<std::size_t>(i)]] = d.counter_value[static_cast<std::size_t>(i)];
  }
  o["counters"] = std::move(counters);
  return o;
}

}  // namespace hsa::ctl
