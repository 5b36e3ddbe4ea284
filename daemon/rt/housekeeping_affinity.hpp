#pragma once

// Keeps hsad's other threads off the RT thread's CPU.
//
// The RT thread pins itself to [realtime] cpu, and SCHED_FIFO lets nothing in user space preempt
// it there. What still delays its wake-up is the kernel work its neighbours on that CPU start: a
// system call that runs with preemption off, and above all the network softirq of a packet sent
// from that CPU (loopback delivers LCM multicast in the sender's softirq, which no RT priority
// preempts on a non-PREEMPT_RT kernel). The LCM thread sends 1 kHz telemetry per axis, the operator
// thread status, the recorder and the metrics writers write files, the drivers' bus threads talk
// to their buses: run on the RT CPU, each of them adds to the RT thread's lateness what a lone
// cyclictest never sees. Called by the main thread before it creates any other thread, this
// narrows the calling thread's affinity to its allowed CPUs minus `rt_cpu`; every thread created
// afterwards inherits it, and the RT thread then pins itself to `rt_cpu` alone.
//
// The same as `CPUAffinity=` minus one CPU in the unit, but it follows the configuration's cpu,
// and stays right when the operator changes it.

#include <string>

namespace hsa::daemon {

struct HousekeepingAffinity {
  bool applied = false;   // the calling thread's affinity now excludes rt_cpu
  std::string cpus;       // the CPUs the other threads may use, as a list ("0,2-3"), when applied
  std::string reason;     // why not, when not applied (no CPU left, rt_cpu not allowed, an error)
};

// Does nothing (applied = false, with the reason) when rt_cpu < 0, when rt_cpu is not among the
// allowed CPUs, or when it is the only one.
HousekeepingAffinity keep_off_rt_cpu(int rt_cpu) noexcept;

}  // namespace hsa::daemon
