"""The flight recorder's operator triggers end to end: the real hsad (with the RT counting hooks) on
the simulated rig and hsactl, as an operator uses them. `hsactl capture` writes a capture whose
trigger row is the cycle that took the request; a condition `following_error_m --above X` fires on a
move, and its trigger row is the first row where the signal crosses X (checked in the file with
Debian's python3-scipy); single-shot fires once, repeat again; a window the ring cannot hold is
refused with the reason; `hsactl status` counts it all; `hsactl scope --live` draws what it
triggered. The RT cycle allocates and locks nothing meanwhile.

Run with /usr/bin/python3 (python3-scipy, python3-numpy) inside a private network namespace.
"""
import glob
import os
import subprocess
import sys
import tempfile
import time
import unittest

import numpy as np
import scipy.io

import hsad_process

HSAD, HSACTL, CONFIG = sys.argv[1:4]
del sys.argv[1:4]

_operator = hsad_process.Operator(HSACTL)
ctl, status, wait_for = _operator.ctl, _operator.status, _operator.wait_for

RATE_HZ = 10_000   # hsad-sim.toml's base rate
# The condition's level: 0.4 mm of following error, which a streamed 100 mm move up on the simulated
# rig crosses while the limiter accelerates it (test b checks the crossing in its capture); at rest
# the error stays within 0.03 mm. A move down need not cross it: test c watches the rod setpoint.
LEVEL_M = 0.0004
CONDITION_WORD = "following_error_m_above_0_0004"
LOW, HIGH = "150", "250"  # mm, within the soft limits
MID_M = 0.2               # between them, m


def move(target):
    return ctl("move", target, "--stream", "--timeout", "20")


def captures(folder):
    return sorted(glob.glob(os.path.join(folder, "lift-*.mat")))


def wait_for_files(folder, n, timeout=10.0):
    """The folder's captures once there are at least n (or the timeout)."""
    deadline = time.monotonic() + timeout
    while len(captures(folder)) < n and time.monotonic() < deadline:
        time.sleep(0.1)
    return captures(folder)


class RecorderTriggers(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.dir = tempfile.TemporaryDirectory()
        cls.folder = os.path.join(cls.dir.name, "captures")
        os.mkdir(cls.folder)
        config = os.path.join(cls.dir.name, "hsad.toml")
        with open(config, "w") as f:
            f.write(hsad_process.quiet_config_text(CONFIG) + f'\n[recorder]\nfolder = "{cls.folder}"\n')
        cls.daemon = hsad_process.Daemon(HSAD, config, 300)
        wait_for(lambda s: s["state"] == "DISABLED", what="the axis to come up DISABLED")
        assert ctl("enable")[0] == 0
        assert move(LOW)[0] == 0

    @classmethod
    def tearDownClass(cls):
        cls.daemon.stop()
        cls.dir.cleanup()

    def setUp(self):
        self.before = captures(self.folder)

    def new_files(self, n, timeout=10.0):
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            fresh = [f for f in captures(self.folder) if f not in self.before]
            if len(fresh) >= n:
                return fresh
            time.sleep(0.1)
        return [f for f in captures(self.folder) if f not in self.before]

    def assert_rt_clean(self):
        s = status()
        for counter in hsad_process.RT_COUNTERS_ASSERTED:
            self.assertEqual(s["rt_" + counter], 0, f"rt_{counter}: {s}")

    def test_a_an_operators_capture_has_its_trigger_row_within_the_request(self):
        started_us = time.monotonic() * 1e6  # CLOCK_MONOTONIC, hsad's utime clock
        code, out = ctl("capture", "lift", "--pre", "0.2", "--post", "0.1")
        returned_us = time.monotonic() * 1e6
        self.assertEqual(code, 0, out)
        self.assertIn("lift: capture taken", out)
        files = self.new_files(1)
        self.assertEqual(len(files), 1, files)
        self.assertRegex(os.path.basename(files[0]), r"^lift-\d{8}T\d{6}\.\d{3}Z-operator\.mat$")
        m = scipy.io.loadmat(files[0], squeeze_me=True)
        self.assertEqual(m["trigger"], "operator")
        self.assertEqual(m["reason"], "operator request")
        k = int(m["trigger_index"]) - 1
        # The windows asked for, at the base rate: 0.2 s before the trigger row, 0.1 s after it.
        self.assertEqual(k, 2000)
        self.assertEqual(len(m["tick"]) - k - 1, 1000)
        self.assertEqual(m["t"][k], 0.0)
        # The trigger's cycle lies between hsactl's start and its return (it waited for hsad's answer);
        # the cycle-exact choice of that row is tested in tests/daemon/test_recorder_cycle.cpp.
        trigger_us = m["utime_us"][k]
        self.assertGreaterEqual(trigger_us, started_us)
        self.assertLessEqual(trigger_us, returned_us)
        s = status()
        self.assertGreaterEqual(s["recorder"]["captures_written"], 1)
        self.assertEqual(s["recorder"]["write_failures"], 0)
        self.assert_rt_clean()

    def test_b_a_condition_fires_on_the_first_row_crossing_its_level_and_single_fires_once(self):
        code, out = ctl("capture", "lift", "--when", "following_error_m", "--above", str(LEVEL_M),
                        "--pre", "0.5", "--post", "0.3")
        self.assertEqual(code, 0, out)
        self.assertIn("armed: following_error_m above 0.0004 (single, 0.5 s before, 0.3 s after)", out)
        self.assertEqual(status()["recorder"]["condition"],
                         "following_error_m above 0.0004 (single, 0.5 s before, 0.3 s after)")
        self.assertEqual(move(HIGH)[0], 0)
        files = self.new_files(1)
        self.assertEqual(len(files), 1, files)
        self.assertTrue(files[0].endswith(f"-{CONDITION_WORD}.mat"), files[0])
        m = scipy.io.loadmat(files[0], squeeze_me=True)
        self.assertEqual(m["trigger"], "condition")
        self.assertEqual(m["condition"], "following_error_m above 0.0004")
        e = m["following_error_m"]
        k = int(m["trigger_index"]) - 1
        self.assertEqual(k, 5000)
        self.assertEqual(len(e) - k - 1, 3000)
        # The trigger row is the first that crosses the level: over it, every row before it not.
        self.assertGreater(e[k], LEVEL_M)
        self.assertTrue(np.all(e[:k] <= LEVEL_M), f"a row over the level before the trigger: {np.max(e[:k])}")
        self.assertGreater(np.max(np.abs(e[:k])), 0.0, "no following error before the trigger at all")
        self.assertEqual(status()["recorder"]["condition"], "", "single-shot still armed after it fired")

        # Single: a second crossing (either move crosses the level) leaves no capture.
        self.assertEqual(move(LOW)[0], 0)
        self.assertEqual(move(HIGH)[0], 0)
        time.sleep(1.0)  # the post-trigger rows and the writer's poll, were there a capture
        self.assertEqual(len(self.new_files(1, timeout=0.5)), 1)
        self.assert_rt_clean()

    def test_c_repeat_fires_again_and_disarm_ends_it(self):
        # The rod setpoint rising through 200 mm: every move up crosses it, no move down does, and
        # how closely the loop follows does not matter (the following error depends on the
        # feed-forward; a move down may stay under any level worth setting).
        code, out = ctl("capture", "lift", "--when", "rod_setpoint_m", "--above", str(MID_M), "--repeat",
                        "--pre", "0.1", "--post", "0.1")
        self.assertEqual(code, 0, out)
        # The rod is at 250 mm (the last test's last move): down first, which must not fire.
        for n, target in ((0, LOW), (1, HIGH), (1, LOW), (2, HIGH)):
            self.assertEqual(move(target)[0], 0)
            time.sleep(0.5)  # the post-trigger rows and the writer's poll, were there a capture
            files = self.new_files(n)
            self.assertEqual(len(files), n, files)
            if n == 0:
                continue
            m = scipy.io.loadmat(files[-1], squeeze_me=True)
            r, k = m["rod_setpoint_m"], int(m["trigger_index"]) - 1
            self.assertGreater(r[k], MID_M)
            self.assertLessEqual(r[k - 1], MID_M)
        self.assertIn("(repeat", status()["recorder"]["condition"])
        self.assertEqual(ctl("capture", "lift", "--disarm")[0], 0)
        self.assertEqual(status()["recorder"]["condition"], "")
        self.assertEqual(move(LOW)[0], 0)
        self.assertEqual(move(HIGH)[0], 0)
        time.sleep(1.0)
        self.assertEqual(len(self.new_files(3, timeout=0.5)), 2, "a disarmed condition fired")
        self.assert_rt_clean()

    def test_d_a_window_the_ring_cannot_hold_or_an_unknown_signal_is_refused_and_changes_nothing(self):
        code, out = ctl("capture", "lift", "--pre", "1.8", "--post", "0.5")
        self.assertEqual(code, 1, out)
        self.assertIn("capture refused: pre-trigger 1.8 s and post-trigger 0.5 s do not fit the axis's recorder "
                      "ring of 2 s", out)
        code, out = ctl("capture", "lift", "--when", "following_error", "--above", "0.001")
        self.assertEqual(code, 2, out)
        self.assertIn("unknown signal 'following_error'", out)
        code, out = ctl("capture", "lift", "--when", "following_error_m", "--above", "nan")
        self.assertEqual(code, 2, out)
        self.assertIn("finite", out)
        time.sleep(0.5)
        self.assertEqual(self.new_files(1, timeout=0.3), [])
        self.assertEqual(status()["recorder"]["condition"], "")

    def test_e_status_counts_what_the_folder_holds(self):
        s = status()
        r = s["recorder"]
        self.assertEqual(r["captures_written"], len(captures(self.folder)))
        self.assertEqual((r["triggers_dropped"], r["write_failures"]), (0, 0))
        code, out = ctl("status")
        self.assertEqual(code, 0, out)
        self.assertIn(f"flight recorder: {r['captures_written']} captures written, {r['triggers_merged']} triggers "
                      f"merged, 0 dropped, 0 write failures; condition: none armed", out)

    def test_f_scope_live_draws_the_capture_it_triggered(self):
        png = os.path.join(self.dir.name, "live.png")
        code, out = ctl("scope", "--live", "lift", "--now", "--pre", "0.1", "--post", "0.05", "--dir", self.folder,
                        "--out", png, "--timeout", "20")
        self.assertEqual(code, 0, out)
        files = self.new_files(1)
        self.assertEqual(len(files), 1, files)
        self.assertIn(files[0], out)
        with open(png, "rb") as f:
            self.assertEqual(f.read(8), b"\x89PNG\r\n\x1a\n")
        # Nothing comes: said so within the timeout, exit 1.
        started = time.monotonic()
        code, out = ctl("scope", "--live", "lift", "--when", "position_m", "--above", "10", "--dir", self.folder,
                        "--out", png, "--timeout", "1")
        self.assertEqual(code, 1, out)
        self.assertIn("no new capture of axis 'lift'", out)
        self.assertLess(time.monotonic() - started, 15)
        self.assertEqual(ctl("capture", "lift", "--disarm")[0], 0)


if __name__ == "__main__":
    unittest.main(verbosity=2)
