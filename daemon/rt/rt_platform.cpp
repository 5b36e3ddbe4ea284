#include "daemon/rt/rt_platform.hpp"

#include <pthread.h>
#include <sched.h>
#include <sys/mman.h>

#include <cerrno>

namespace hsa::daemon {
namespace {

class LinuxRtPlatform final : public RtPlatform {
 public:
  int lock_memory() noexcept override {
    return mlockall(MCL_CURRENT | MCL_FUTURE) == 0 ? 0 : errno;
  }

  int set_fifo_priority(int priority) noexcept override {
    sched_param param{};
    param.sched_priority = priority;
    return pthread_setschedparam(pthread_self(), SCHED_FIFO, &param);
  }

  int pin_to_cpu(int cpu) noexcept override {
    if (cpu < 0 || cpu >= CPU_SETSIZE) {
      return EINVAL;
    }
    cpu_set_t set;
    CPU_ZERO(&set);
    CPU_SET(cpu, &set);
    return pthread_setaffinity_np(pthread_self(), sizeof(set), &set);
  }
};

}  // namespace

RtPlatform& linux_rt_platform() noexcept {
  static LinuxRtPlatform platform;
  return platform;
}

}  // namespace hsa::daemon
