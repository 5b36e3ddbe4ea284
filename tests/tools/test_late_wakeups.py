"""bench/late-wakeups' classification of a late sleep timer, on traces written here in ftrace's
format: a timer served a period late on an idle CPU that did nothing meanwhile is the host's
(quiet), and with another task on it, that task's or the host's (quiet, task);
with an interrupt or another task in between it is the guest's (busy); with only the woken thread
finishing its previous cycle, its own; a timer served on time is counted but not listed."""
import importlib.machinery
import importlib.util
import os
import sys
import unittest

ROOT = sys.argv.pop(1)
sys.path.insert(0, os.path.join(ROOT, "bench"))
_loader = importlib.machinery.SourceFileLoader("late_wakeups", os.path.join(ROOT, "bench", "late-wakeups"))
_spec = importlib.util.spec_from_loader("late_wakeups", _loader)
late_wakeups = importlib.util.module_from_spec(_spec)
_loader.exec_module(late_wakeups)

DEADLINE_NS = 5_000_000_000


def line(comm_pid, t_s, event, rest):
    return f"{comm_pid:>24s} [001] d.h1. {t_s:.6f}: {event}: {rest}"


def trace(lateness_us, between=()):
    """cyclictest arms its timer at 100 s (trace clock) for DEADLINE_NS (timer clock); the timer
    interrupt serves it lateness_us after the deadline, which in trace time is 100.001 s + lateness;
    `between` are (t_s, event, rest, comm) lines between the deadline and the interrupt."""
    irq_s = 100.001 + lateness_us * 1e-6
    lines = [line("cyclictest-101", 100.0, "hrtimer_start",
                  f"hrtimer=00000000aaaa function=hrtimer_wakeup expires={DEADLINE_NS} softexpires={DEADLINE_NS} mode=ABS was_armed=0"),
             line("cyclictest-101", 100.000002, "sched_switch",
                  "prev_comm=cyclictest prev_pid=101 prev_prio=19 prev_state=S ==> next_comm=swapper/1 next_pid=0 next_prio=120")]
    lines += [line(comm, t, e, r) for t, e, r, comm in between]
    lines += [line("<idle>-0", irq_s, "local_timer_entry", "vector=236"),
              line("<idle>-0", irq_s + 1e-6, "hrtimer_expire_entry",
                   f"hrtimer=00000000aaaa function=hrtimer_wakeup now={DEADLINE_NS + int(lateness_us * 1000)}"),
              line("<idle>-0", irq_s + 2e-6, "sched_waking", "comm=cyclictest pid=101 prio=19 target_cpu=001")]
    return lines


class Classify(unittest.TestCase):
    def classify(self, lines):
        return late_wakeups.classify(lines, 100e3)

    def test_a_timer_on_time_is_served_but_not_late(self):
        served, late = self.classify(trace(20))
        self.assertEqual((served, late), (1, []))

    def test_a_late_timer_on_a_quiet_cpu_is_the_hosts(self):
        served, late = self.classify(trace(250))
        self.assertEqual(served, 1)
        self.assertEqual(len(late), 1)
        self.assertEqual(late[0]["task"], "cyclictest")
        self.assertAlmostEqual(late[0]["lateness_us"], 250.0)
        self.assertEqual(late[0]["kind"], "quiet")

    def test_a_silence_with_another_task_on_the_cpu_is_told_apart(self):
        # stress-ng took the CPU before the deadline and nothing was traced after it: its kernel
        # code with interrupts off, or the host; not the idle CPU's plain silence.
        switch = (100.0005, "sched_switch",
                  "prev_comm=swapper/1 prev_pid=0 prev_prio=120 prev_state=R ==> next_comm=stress-ng-vm next_pid=9 next_prio=120",
                  "<idle>-0")
        (_, late) = self.classify(trace(250, [switch]))
        self.assertEqual(late[0]["kind"], "quiet, task")
        self.assertEqual(late[0]["on_cpu"], "stress-ng-vm")
        (_, late) = self.classify(trace(250))
        self.assertEqual(late[0]["on_cpu"], "swapper/1")

    def test_an_interrupt_after_the_deadline_makes_it_busy(self):
        irq = (100.00105, "irq_handler_entry", "irq=11 name=virtio0", "<idle>-0")
        (_, late) = self.classify(trace(250, [irq]))
        self.assertEqual(late[0]["kind"], "busy")
        self.assertIn("irq_handler_entry", late[0]["before"][-1])

    def test_an_interrupt_before_the_deadline_does_not(self):
        irq = (100.0005, "irq_handler_entry", "irq=11 name=virtio0", "<idle>-0")
        (_, late) = self.classify(trace(250, [irq]))
        self.assertEqual(late[0]["kind"], "quiet")

    def test_the_woken_thread_finishing_its_last_cycle_is_its_own(self):
        own = (100.0011, "sched_switch",
               "prev_comm=cyclictest prev_pid=101 prev_prio=19 prev_state=S ==> next_comm=swapper/1 next_pid=0 next_prio=120",
               "cyclictest-101")
        (_, late) = self.classify(trace(250, [own]))
        self.assertEqual(late[0]["kind"], "own")
        other = (100.0011, "sched_switch",
                 "prev_comm=kworker/1:1 prev_pid=54 prev_prio=120 prev_state=I ==> next_comm=swapper/1 next_pid=0 next_prio=120",
                 "kworker/1:1-54")
        (_, late) = self.classify(trace(250, [other]))
        self.assertEqual(late[0]["kind"], "busy")


if __name__ == "__main__":
    unittest.main(verbosity=2)
