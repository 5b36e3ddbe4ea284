#include "daemon/rt/housekeeping_affinity.hpp"

#include <pthread.h>
#include <sched.h>

#include <cerrno>
#include <cstring>
#include <utility>

namespace hsa::daemon {
namespace {

std::string cpu_list(const cpu_set_t& set) {
  std::string out;
  for (int cpu = 0; cpu < CPU_SETSIZE; ++cpu) {
    if (!CPU_ISSET(cpu, &set)) continue;
    int last = cpu;
    while (last + 1 < CPU_SETSIZE && CPU_ISSET(last + 1, &set)) ++last;
    if (!out.empty()) out += ',';
    out += std::to_string(cpu);
    if (last > cpu) out += '-' + std::to_string(last);
    cpu = last;
  }
  return out;
}

}  // namespace

HousekeepingAffinity keep_off_rt_cpu(int rt_cpu) noexcept {
  HousekeepingAffinity result;
  try {
    if (rt_cpu < 0 || rt_cpu >= CPU_SETSIZE) {
      result.reason = "no RT CPU configured";
      return result;
    }
    cpu_set_t set;
    CPU_ZERO(&set);
    if (const int err = pthread_getaffinity_np(pthread_self(), sizeof(set), &set); err != 0) {
      result.reason = std::string("cannot read the affinity: ") + std::strerror(err);
      return result;
    }
    if (!CPU_ISSET(rt_cpu, &set)) {
      result.reason = "CPU " + std::to_string(rt_cpu) + " is not among the allowed CPUs " + cpu_list(set);
      return result;
    }
    CPU_CLR(rt_cpu, &set);
    if (CPU_COUNT(&set) == 0) {
      result.reason = "CPU " + std::to_string(rt_cpu) + " is the only allowed CPU";
      return result;
    }
    std::string cpus = cpu_list(set);  // before the change: nothing below allocates
    if (const int err = pthread_setaffinity_np(pthread_self(), sizeof(set), &set); err != 0) {
      result.reason = std::string("cannot set the affinity: ") + std::strerror(err);
      return result;
    }
    result.applied = true;
    result.cpus = std::move(cpus);
  } catch (...) {  // std::string's allocation, before any change
    result.applied = false;
    result.reason = {};
  }
  return result;
}

}  // namespace hsa::daemon
