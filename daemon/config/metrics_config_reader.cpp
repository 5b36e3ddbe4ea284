#include "daemon/config/metrics_config_reader.hpp"

#include <string_view>

namespace hsa::daemon {

// Prometheus scrapes every 15 s by default; a file rewritten much faster than any scrape reads it
// costs the host writes for nothing, and one a scrape finds an hour old says nothing of now.
constexpr double kMinIntervalS = 0.1;
constexpr double kMaxIntervalS = 3600.0;

MetricsConfig parse_metrics(const io::TableReader& root) {
  MetricsConfig c;
  const auto t = root.table("metrics", false, "a table [metrics]");
  if (!t) return c;
  t->reject_unknown_keys({"textfile", "interval_s"});
  // The node exporter's textfile collector reads only *.prom files of its folder; a relative path
  // would depend on hsad's working directory, which systemd sets to /.
  constexpr std::string_view expected =
      "an absolute path ending in \".prom\" in the node exporter's --collector.textfile.directory, such as "
      "\"/var/lib/prometheus/node-exporter/hsad.prom\"";
  c.textfile = t->string("textfile", expected);
  const std::string_view suffix = ".prom";
  const std::string_view name = std::string_view(c.textfile).substr(c.textfile.rfind('/') + 1);
  if (c.textfile.empty() || c.textfile.front() != '/' || name.size() <= suffix.size() || !name.ends_with(suffix)) {
    t->fail("textfile", expected);
  }
  c.interval_s = t->number("interval_s", {.min = kMinIntervalS, .max = kMaxIntervalS}, c.interval_s);
  return c;
}

}  // namespace hsa::daemon
