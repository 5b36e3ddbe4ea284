"""The flight recorder end to end: the real hsad (with the RT counting hooks) on the simulated rig,
an encoder jump scripted by the sim plugin while the axis is enabled, telemetry recorded by hsactl
meanwhile; the capture file it leaves is opened with Debian's python3-scipy (scipy.io.loadmat), as
a user would, and checked against the fault and the telemetry of the same run. A folder hsad cannot
write costs the capture, is counted and logged, and the axis runs on.

Run with /usr/bin/python3 (python3-scipy, python3-numpy) inside a private network namespace.
"""
import csv
import glob
import json
import os
import re
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

RATE_HZ = 10_000       # hsad-sim.toml's base rate
RING_ROWS = 20_000     # [axes.recorder] seconds = 2 (default) at that rate
POST_ROWS = 5_000      # post_trigger_s = 0.5 (default)
STATE_FAULT = 3        # the file's state codes (its `codes` string says so, checked below)
JUMP_AT_S = 5.0        # the sim's clock: 5 s after start, so the ring is full by then


def config_text(folder):
    """hsad-sim.toml, quiet about VM overruns, an encoder jump at JUMP_AT_S, captures into `folder`."""
    text = hsad_process.quiet_config_text(CONFIG)
    head, sep, tail = text.partition("[[axes]]")
    event = f"[[drivers.settings.events]]\nat_s = {JUMP_AT_S}\nencoder_jump_m = 0.01\n\n"
    return head + event + sep + tail + f'\n[recorder]\nfolder = "{folder}"\n'


class Run:
    """hsad with `folder` as its recorder folder, enabled, telemetry recorded over the fault."""

    def __init__(self, folder):
        self.dir = tempfile.TemporaryDirectory()
        self.config = os.path.join(self.dir.name, "hsad.toml")
        with open(self.config, "w") as f:
            f.write(config_text(folder))
        self.stats_path = os.path.join(self.dir.name, "stats.json")
        self.csv = os.path.join(self.dir.name, "telemetry.csv")
        self.proc = subprocess.Popen([HSAD, "--config", self.config, "--duration", "60", "--key-dir",
                                      hsad_process.KEY_DIR, "--stats-json", self.stats_path],
                                     stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        self.stderr = ""

    def stop(self):
        if self.proc.poll() is None:
            self.proc.terminate()
        _, self.stderr = self.proc.communicate(timeout=30)
        with open(self.stats_path) as f:
            return json.load(f)


class FlightRecorder(unittest.TestCase):
    def tearDown(self):
        if hasattr(self, "run_") and self.run_.proc.poll() is None:
            self.run_.proc.kill()
            self.run_.proc.communicate()

    def fault_while_recording(self, folder):
        self.run_ = Run(folder)
        wait_for(lambda s: s["state"] == "DISABLED", what="the axis to come up DISABLED")
        self.assertEqual(ctl("enable")[0], 0)
        record = subprocess.Popen([HSACTL, "record", self.run_.csv, "--duration", "9"],
                                  stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        s = wait_for(lambda s: s["state"] == "FAULT", timeout=30, what="the encoder-jump fault")
        self.assertEqual(record.wait(timeout=30), 0, record.stderr.read())
        return s

    def test_a_fault_leaves_a_capture_scipy_opens_matching_the_fault_and_the_telemetry(self):
        with tempfile.TemporaryDirectory() as folder:
            s = self.fault_while_recording(folder)
            self.assertIn("encoder jumped", " ".join(f["reason"] for f in s["faults"]), s)
            deadline = time.monotonic() + 10
            while not glob.glob(os.path.join(folder, "*.mat")) and time.monotonic() < deadline:
                time.sleep(0.1)
            after_fault = status()
            stats = self.run_.stop()
            files = glob.glob(os.path.join(folder, "*.mat"))
            self.assertEqual(len(files), 1, (files, self.run_.stderr))
            name = os.path.basename(files[0])
            self.assertRegex(name, r"^lift-\d{8}T\d{6}\.\d{3}Z-encoder_jump\.mat$")
            self.assertEqual(glob.glob(os.path.join(folder, "*.part")), [])
            m = scipy.io.loadmat(files[0], squeeze_me=True)
            with open(self.run_.config, encoding="utf-8") as f:
                config = f.read()

            # Self-described: the state codes, the axis, the reason, the configuration as read.
            self.assertIn(f"{STATE_FAULT} FAULT", m["codes"])
            self.assertEqual(m["axis"], "lift")
            self.assertEqual(m["fault"], "encoder_jump")
            self.assertIn("encoder jumped 10.00 mm", m["reason"])
            self.assertEqual(m["configuration"], config)  # UTF-8 (µ, α) and all
            self.assertRegex(m["gains"], r"kp = 85 /m, ki = 460 ")
            self.assertEqual(m["sample_rate_hz"], RATE_HZ)

            # The trigger is the cycle the axis entered FAULT.
            tick, state = m["tick"], m["state"]
            k = int(m["trigger_index"]) - 1  # 1-based in the file (MATLAB's convention)
            self.assertEqual(state[k], STATE_FAULT)
            self.assertNotEqual(state[k - 1], STATE_FAULT)
            self.assertEqual(tick[k], m["trigger_tick"])
            self.assertEqual(m["t"][k], 0.0)
            # The whole ring: the fault came 5 s in, so 1.5 s before it and the 0.5 s after.
            self.assertEqual(len(tick), RING_ROWS)
            self.assertEqual(k, RING_ROWS - POST_ROWS - 1)
            # Every RT cycle, no row missing: 10 kHz, except where the executive skipped base ticks
            # (overruns on a loaded VM), which each row counts: then the tick advances by 1 + skipped.
            self.assertTrue(np.all(np.diff(m["seq"]) == 1), "a row missing")
            self.assertTrue(np.all(np.diff(tick) == 1 + m["skipped"][1:]), "a tick gap no overrun explains")
            self.assertEqual(tick[-1] - tick[0] + 1, RING_ROWS + np.sum(m["skipped"][1:]))
            for column in ("position_m", "pressure_a_pa", "pressure_b_pa", "valve_opening", "lateness_ns", "exec_ns",
                           "pi_integral", "rod_setpoint_m"):
                self.assertEqual(len(m[column]), RING_ROWS, column)
            self.assertTrue(np.all(m["exec_ns"] > 0), "a row without its cycle's execution time")
            self.assertTrue(np.any(m["pi_integral"][:k] != 0.0), "the PI integral never moved while enabled")
            # The encoder read 10 mm more from the trigger's cycle on.
            self.assertGreater(m["position_m"][k] - m["position_m"][k - 1], 0.009)

            # The telemetry of the same run (1 kHz, seq = the base tick) holds the same values.
            with open(self.run_.csv) as f:
                telemetry = {int(r["seq"]): r for r in csv.DictReader(f)}
            row_of = {int(t): i for i, t in enumerate(tick)}
            matched = 0
            for seq, r in telemetry.items():
                i = row_of.get(seq)
                if i is None:
                    continue
                matched += 1
                # Compared as hsactl's CSV prints them (telemetry_csv.cpp: 9, 8 and 6 significant digits).
                self.assertEqual(float(r["position_m"]), float(f"{m['position_m'][i]:.9g}"), seq)
                self.assertEqual(float(r["pressure_a_pa"]), float(f"{m['pressure_a_pa'][i]:.8g}"), seq)
                self.assertEqual(float(r["valve_opening"]), float(f"{m['valve_opening'][i]:.6g}"), seq)
                self.assertEqual(int(r["lateness_ns"]), m["lateness_ns"][i], seq)
                self.assertEqual(int(r["utime_us"]), m["utime_us"][i], seq)
            # 2 s of 1 kHz telemetry lies in the window; LCM may drop a few of them.
            self.assertGreater(matched, 1900, f"{matched} telemetry samples in the capture's window")

            # Counted; and the RT cycle stayed clean with the recorder writing all along.
            rec = stats["axes"][0]["recorder"]
            self.assertEqual((rec["triggers"], rec["captures"], rec["files_written"], rec["write_failures"]),
                             (1, 1, 1, 0), rec)
            self.assertEqual(rec["bytes_written"], os.path.getsize(files[0]))
            for counter in hsad_process.RT_COUNTERS_ASSERTED:
                self.assertEqual(after_fault["rt_" + counter], 0, f"rt_{counter}: {after_fault}")
                self.assertEqual(stats["steady"][counter], 0, counter)
            self.assertIn(f"flight recorder: axis 'lift': {files[0]}", self.run_.stderr)

            # hsactl reads the same file: listed with the reason and rows, and its CSV holds scipy's values.
            r = subprocess.run([HSACTL, "captures", "--dir", folder], capture_output=True, text=True, timeout=60)
            self.assertEqual(r.returncode, 0, r.stderr)
            listed = r.stdout.splitlines()[1]
            self.assertTrue(listed.startswith(name), listed)
            self.assertIn(f" {RING_ROWS} ", listed)
            self.assertIn("encoder jumped 10.00 mm", listed)
            out = os.path.join(folder, "capture.csv")
            r = subprocess.run([HSACTL, "capture", "export", files[0], out], capture_output=True, text=True, timeout=60)
            self.assertEqual((r.returncode, r.stderr), (0, ""))
            with open(out) as f:
                exported = list(csv.reader(f))
            header = exported[0]
            position = header.index("position_m [m]")
            self.assertEqual(len(exported) - 1, RING_ROWS)
            self.assertEqual([i for i, row in enumerate(exported[1:]) if row[-1] == "1"], [k])
            self.assertTrue(all(float(row[position]) == m["position_m"][i] for i, row in enumerate(exported[1:])),
                            "the CSV's position differs from scipy's")

    def test_an_unwritable_folder_costs_the_capture_is_counted_and_the_axis_runs_on(self):
        folder = "/nonexistent-hsa-recorder-folder"
        self.fault_while_recording(folder)
        time.sleep(1.5)  # the post-trigger rows and the writer's poll
        wait_for(lambda s: ctl("reset")[0] == 0, what="reset to succeed")
        wait_for(lambda s: s["state"] == "DISABLED", what="DISABLED after reset")
        self.assertEqual(ctl("enable")[0], 0)
        wait_for(lambda s: s["state"] == "ENABLED", what="ENABLED again")
        stats = self.run_.stop()
        rec = stats["axes"][0]["recorder"]
        self.assertEqual((rec["captures"], rec["files_written"], rec["write_failures"]), (1, 0, 1), rec)
        self.assertIn(f"not writable", self.run_.stderr)
        self.assertRegex(self.run_.stderr, r"flight recorder: axis 'lift': capture not written: "
                                           + re.escape(folder) + r"/lift-.*\.mat\.part: cannot create it")


if __name__ == "__main__":
    unittest.main(verbosity=2)
