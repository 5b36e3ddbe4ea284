// Prints each hsa type's LCM fingerprint as C++ computes it ("hsa.status_t 1234..."), for
// test_java_types.py to compare with the Java types lcm-spy decodes with.
#include <cstdio>

#include "hsa/command_t.hpp"
#include "hsa/driver_status_t.hpp"
#include "hsa/setpoint_t.hpp"
#include "hsa/status_t.hpp"
#include "hsa/telemetry_t.hpp"

namespace {

template <typename Message>
void print(const char* name) {
  std::printf("%s %lld\n", name, static_cast<long long>(Message::getHash()));
}

}  // namespace

int main() {
  print<hsa::setpoint_t>("hsa.setpoint_t");
  print<hsa::command_t>("hsa.command_t");
  print<hsa::telemetry_t>("hsa.telemetry_t");
  print<hsa::driver_status_t>("hsa.driver_status_t");
  print<hsa::status_t>("hsa.status_t");
  return 0;
}
