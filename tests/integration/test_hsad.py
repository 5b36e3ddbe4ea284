"""End-to-end tests of the real hsad process on the simulated rig, driven with the real hsactl.

Run by ctest inside a private network namespace (LCM multicast never reaches the host network):
    python3 test_hsad.py HSAD HSACTL CONFIG
Each test starts its own hsad with a configuration derived from the example one (plus scripted
sim-plugin events for the faults), and stops it with SIGTERM. Every wait is bounded; nothing
asserts timing: conditions are polled with generous timeouts.
"""
import json
import os
import re
import signal
import subprocess
import sys
import tempfile
import time
import unittest

HSAD, HSACTL, CONFIG, TWO_AXES_CONFIG = sys.argv[1:5]
del sys.argv[1:5]

# Wire values of status_t.
ENABLED, DISABLED, FAULT, ESTOP = "ENABLED", "DISABLED", "FAULT", "ESTOP"
FAULT_SENSOR, FAULT_PRESSURE, FAULT_FOLLOWING_ERROR, FAULT_ESTOP = 1, 3, 5, 9


def config_with(events="", **replace):
    """The example configuration, with sim-plugin events appended to its driver's settings."""
    with open(CONFIG) as f:
        text = f.read()
    for key, value in replace.items():
        text, n = re.subn(rf"(?m)^{key}\s*=.*$", f"{key} = {value}", text, count=1)
        assert n == 1, f"key {key} not in {CONFIG}"
    # The events belong to the [drivers.settings] table: insert them right after it.
    if events:
        head, sep, tail = text.partition("[[axes]]")
        text = head + events + "\n" + sep + tail
    f = tempfile.NamedTemporaryFile("w", suffix=".toml", delete=False)
    f.write(text)
    f.close()
    return f.name


class Daemon:
    def __init__(self, config):
        self.config = config
        self.proc = subprocess.Popen([HSAD, "--config", config, "--duration", "60"],
                                     stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)

    def stop(self):
        if self.proc.poll() is None:
            self.proc.send_signal(signal.SIGTERM)
        out, err = self.proc.communicate(timeout=20)
        os.unlink(self.config)
        return self.proc.returncode, err


def ctl(*args, timeout=30):
    r = subprocess.run([HSACTL, *args], capture_output=True, text=True, timeout=timeout)
    return r.returncode, r.stdout + r.stderr


def status(axis="lift"):
    code, out = ctl("--axis", axis, "status", "--json")
    if code != 0:
        return None
    return json.loads(out)


def wait_for(predicate, timeout=20.0, what="condition", axis="lift"):
    deadline = time.monotonic() + timeout
    last = None
    while time.monotonic() < deadline:
        last = status(axis)
        if last is not None and predicate(last):
            return last
        time.sleep(0.1)
    raise AssertionError(f"timed out waiting for {what}; last status: {last}")


class HsadTest(unittest.TestCase):
    def start(self, **kw):
        self.daemon = Daemon(config_with(**kw))
        wait_for(lambda s: s["state"] == DISABLED, what="the axis to come up DISABLED")

    def tearDown(self):
        if hasattr(self, "daemon"):
            self.daemon.stop()

    def test_enable_and_move_settle_within_a_tenth_of_a_millimetre(self):
        self.start()
        self.assertEqual(ctl("enable")[0], 0)
        code, out = ctl("move", "150", "--tolerance", "0.1", "--timeout", "20")
        self.assertEqual(code, 0, out)
        code, out = ctl("move", "200", "--tolerance", "0.1", "--timeout", "20")
        self.assertEqual(code, 0, out)
        s = status()
        self.assertLess(abs(s["position_m"] - 0.200), 0.1e-3)

    def test_bad_setpoints_are_rejected_and_counted_without_effect(self):
        self.start()
        self.assertEqual(ctl("enable")[0], 0)
        self.assertEqual(ctl("move", "150", "--timeout", "20")[0], 0)
        before = status()
        # 500 mm is outside the axis's soft limits, nan is not a number: both must be refused.
        self.assertNotEqual(ctl("move", "500", "--timeout", "1")[0], 0)
        self.assertNotEqual(ctl("move", "nan", "--timeout", "1")[0], 0)
        s = wait_for(lambda s: s["rejected_out_of_range"] > before["rejected_out_of_range"]
                     and s["rejected_non_finite"] > before["rejected_non_finite"], what="reject counters")
        self.assertEqual(s["state"], ENABLED, s)
        self.assertLess(abs(s["position_m"] - 0.150), 0.2e-3, "a rejected setpoint moved the rod")

    def test_setpoint_silence_holds_position_without_a_fault(self):
        self.start()
        self.assertEqual(ctl("enable")[0], 0)
        self.assertEqual(ctl("move", "170", "--timeout", "20")[0], 0)
        s = wait_for(lambda s: s["holding"], what="holding after the setpoint stream stopped")
        self.assertEqual(s["state"], ENABLED)
        self.assertEqual(s["faults"], [])
        self.assertLess(abs(s["position_m"] - 0.170), 0.2e-3)

    def fault_then_reset(self, events, state, code, clear_after_s):
        self.start(events=events)
        self.assertEqual(ctl("enable")[0], 0)
        s = wait_for(lambda s: s["state"] == state, what=state)
        self.assertIn(code, [f["code"] for f in s["faults"]], s)
        self.assertTrue(all(f["reason"] for f in s["faults"]), "a fault without a reason text")
        # The cause is scripted to clear; reset must then succeed (and not before).
        time.sleep(max(0.0, clear_after_s))
        wait_for(lambda s: ctl("reset")[0] == 0, what="reset to succeed")
        s = wait_for(lambda s: s["state"] == DISABLED, what="DISABLED after reset")
        self.assertEqual(s["faults"], [])
        return s

    def test_estop_input(self):
        self.fault_then_reset('[[drivers.settings.events]]\nat_s = 5.0\nestop = true\n'
                              '[[drivers.settings.events]]\nat_s = 7.0\nestop = false\n',
                              ESTOP, FAULT_ESTOP, 1.0)

    def test_disconnected_pressure_sensor(self):
        self.fault_then_reset('[[drivers.settings.events]]\nat_s = 5.0\nsensor = "pressure_a"\nfault = "disconnected"\n'
                              '[[drivers.settings.events]]\nat_s = 7.0\nsensor = "pressure_a"\nfault = "none"\n',
                              FAULT, FAULT_SENSOR, 1.0)

    def test_lost_supply_gives_a_following_error(self):
        self.start(events='[[drivers.settings.events]]\nat_s = 5.0\nsupply_lost = true\n')
        self.assertEqual(ctl("enable")[0], 0)
        # Move up; the supply goes at 5 s (during the move or while holding) and the load sinks.
        mover = subprocess.Popen([HSACTL, "move", "250", "--timeout", "15"], stdout=subprocess.DEVNULL,
                                 stderr=subprocess.DEVNULL)
        s = wait_for(lambda s: s["state"] == FAULT, what="FAULT")
        mover.wait(timeout=20)
        self.assertIn(FAULT_FOLLOWING_ERROR, [f["code"] for f in s["faults"]], s)

    def test_overload_gives_an_over_pressure_fault(self):
        # 100 kg needs ≈ 20 bar in chamber A; the limit is set to 15 bar.
        self.start(events='[[drivers.settings.events]]\nat_s = 5.0\nload_kg = 100\n', max_pressure_pa="15e5")
        self.assertEqual(ctl("enable")[0], 0)
        s = wait_for(lambda s: s["state"] == FAULT, what="FAULT")
        self.assertIn(FAULT_PRESSURE, [f["code"] for f in s["faults"]], s)

    def test_steady_state_counters_stay_at_zero_over_ten_seconds(self):
        self.start()
        self.assertEqual(ctl("enable")[0], 0)
        code, out = ctl("sine", "10", "0.5", "--duration", "10", timeout=40)
        self.assertEqual(code, 0, out)
        s = status()
        for counter in ("rt_allocations", "rt_locks", "rt_minor_faults", "rt_major_faults"):
            self.assertEqual(s[counter], 0, f"{counter} in the RT cycle: {s}")

    def test_sigterm_exits_cleanly_in_the_safe_state(self):
        self.start()
        self.assertEqual(ctl("enable")[0], 0)
        self.assertEqual(ctl("move", "160", "--timeout", "20")[0], 0)
        code, err = self.daemon.stop()
        del self.daemon
        self.assertEqual(code, 0, err)
        self.assertIn("SIGTERM: stopping", err)


class TwoAxesTest(unittest.TestCase):
    def test_two_axes_run_independently_in_one_daemon(self):
        with open(TWO_AXES_CONFIG) as f:
            text = f.read()
        tmp = tempfile.NamedTemporaryFile("w", suffix=".toml", delete=False)
        tmp.write(text)
        tmp.close()
        daemon = Daemon(tmp.name)
        try:
            for axis in ("left", "right"):
                wait_for(lambda s: s["state"] == DISABLED, axis=axis, what=f"{axis} DISABLED")
            self.assertEqual(ctl("--axis", "left", "enable")[0], 0)
            # Only the enabled axis moves; the other stays disabled.
            self.assertEqual(ctl("--axis", "left", "move", "120", "--timeout", "20")[0], 0)
            self.assertEqual(status("right")["state"], DISABLED)
            self.assertEqual(ctl("--axis", "right", "enable")[0], 0)
            self.assertEqual(ctl("--axis", "right", "move", "180", "--timeout", "20")[0], 0)
            left, right = status("left"), status("right")
            self.assertLess(abs(left["position_m"] - 0.120), 0.2e-3, left)
            self.assertLess(abs(right["position_m"] - 0.180), 0.1e-3, right)
        finally:
            code, err = daemon.stop()
        self.assertEqual(code, 0, err)


if __name__ == "__main__":
    links = subprocess.run(["ip", "-o", "link"], capture_output=True, text=True).stdout.splitlines()
    if len(links) != 1:
        sys.exit("test_hsad.py: refusing to run outside a private network namespace (see DESIGN.md)")
    unittest.main(verbosity=2)
