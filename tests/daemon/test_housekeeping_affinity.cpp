// keep_off_rt_cpu: the calling thread, and every thread it creates afterwards, leave the RT CPU
// to the RT thread. Each case runs in a thread of its own, so the test runner's affinity is kept.
#include <pthread.h>
#include <sched.h>

#include <thread>

#include <gtest/gtest.h>

#include "daemon/rt/housekeeping_affinity.hpp"

namespace hsa::daemon {
namespace {

cpu_set_t affinity_of_this_thread() {
  cpu_set_t set;
  CPU_ZERO(&set);
  EXPECT_EQ(pthread_getaffinity_np(pthread_self(), sizeof(set), &set), 0);
  return set;
}

int first_allowed_cpu(const cpu_set_t& set) {
  for (int cpu = 0; cpu < CPU_SETSIZE; ++cpu)
    if (CPU_ISSET(cpu, &set)) return cpu;
  return -1;
}

TEST(HousekeepingAffinity, NoRtCpuChangesNothing) {
  std::thread([] {
    const cpu_set_t before = affinity_of_this_thread();
    const HousekeepingAffinity a = keep_off_rt_cpu(-1);
    EXPECT_FALSE(a.applied);
    EXPECT_FALSE(a.reason.empty());
    const cpu_set_t after = affinity_of_this_thread();
    EXPECT_TRUE(CPU_EQUAL(&before, &after));
  }).join();
}

TEST(HousekeepingAffinity, ACpuOutsideTheAllowedSetChangesNothingAndSaysWhy) {
  std::thread([] {
    const cpu_set_t before = affinity_of_this_thread();
    int outside = -1;
    for (int cpu = CPU_SETSIZE - 1; cpu >= 0 && outside < 0; --cpu)
      if (!CPU_ISSET(cpu, &before)) outside = cpu;
    ASSERT_GE(outside, 0);
    const HousekeepingAffinity a = keep_off_rt_cpu(outside);
    EXPECT_FALSE(a.applied);
    EXPECT_NE(a.reason.find("not among the allowed CPUs"), std::string::npos) << a.reason;
    const cpu_set_t after = affinity_of_this_thread();
    EXPECT_TRUE(CPU_EQUAL(&before, &after));
  }).join();
}

TEST(HousekeepingAffinity, TheCallerAndTheThreadsItCreatesLeaveTheRtCpu) {
  std::thread([] {
    const cpu_set_t before = affinity_of_this_thread();
    const int rt_cpu = first_allowed_cpu(before);
    ASSERT_GE(rt_cpu, 0);
    const HousekeepingAffinity a = keep_off_rt_cpu(rt_cpu);
    if (CPU_COUNT(&before) == 1) {  // a one-CPU machine: nothing to move the others to
      EXPECT_FALSE(a.applied);
      EXPECT_NE(a.reason.find("only allowed CPU"), std::string::npos) << a.reason;
      return;
    }
    ASSERT_TRUE(a.applied) << a.reason;
    cpu_set_t expected = before;
    CPU_CLR(rt_cpu, &expected);
    const cpu_set_t mine = affinity_of_this_thread();
    EXPECT_TRUE(CPU_EQUAL(&mine, &expected));
    EXPECT_FALSE(a.cpus.empty());
    cpu_set_t child{};
    std::thread([&child] { child = affinity_of_this_thread(); }).join();
    EXPECT_TRUE(CPU_EQUAL(&child, &expected));
    // The RT thread pins itself afterwards: narrowing did not take the RT CPU out of reach.
    std::thread([rt_cpu] {
      cpu_set_t only;
      CPU_ZERO(&only);
      CPU_SET(rt_cpu, &only);
      EXPECT_EQ(pthread_setaffinity_np(pthread_self(), sizeof(only), &only), 0);
    }).join();
  }).join();
}

}  // namespace
}  // namespace hsa::daemon
