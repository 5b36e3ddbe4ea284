"""`hsactl excite` on the real hsad: a closed-loop identification run made by hsad's RT loop,
recorded by hsactl, identified by hsa-analyze, against the simulated rig's own linearization.

Run by ctest inside a private network namespace (hsad opens its LCM bridge):
    python3 test_hsad_excite.py HSAD HSACTL HSA_ANALYZE CONFIG
HSAD is hsad-rtcount (hsad with the counting hooks): the RT cycle allocates and locks nothing.
CONFIG is systemd/hsad-sim.toml (the papers' rig, no load, the rod at 150 mm at start, telemetry at
the cylinder loop's 1 kHz). One hsad serves both tests, in this order:
  - an excitation outside the soft limits is refused before it starts, with hsad's reason, and the
    axis stays ENABLED where it was;
  - the paper's identification run (Puglisi et al. 2015, section 3.1.1) at 150 mm: ±1 mm PRMS of 5
    levels switching every 0.3 s, P control of 0.2 per mm, 25 s, recorded with --record; hsactl
    exits 0 when it ends, the axis holds 150 mm with its PI gains back, and `hsa-analyze identify`
    on the record gives b0, b1 and k01 within 5 % of `hsa-analyze calibration --config CONFIG` at
    150 mm, 0 kg, with a fit index of at least 85 %. The identification needs every sample on its
    loop period: when the host kept hsad's RT thread off its deadlines (samples skipped or taken
    late), the comparison is skipped, saying how many.
Every wait is bounded.
"""
import csv
import json
import os
import shutil
import subprocess
import sys
import tempfile
import unittest

import hsad_process

HSAD, HSACTL, ANALYZE, CONFIG = sys.argv[1:5]
del sys.argv[1:5]

AXIS = "lift"
WORKING_POINT_MM = 150.0
DURATION_S = 25.0
operator = hsad_process.Operator(HSACTL, AXIS, timeout=DURATION_S + 30)


def analyze(*args):
    r = subprocess.run([ANALYZE, *args, "--json"], capture_output=True, text=True, timeout=120)
    if r.returncode != 0:
        raise AssertionError(f"hsa-analyze {' '.join(args)}: {r.stderr}")
    return json.loads(r.stdout)


class ExciteTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.daemon = hsad_process.Daemon(HSAD, hsad_process.quiet_config_copy(CONFIG), 120)
        operator.wait_for(lambda s: s["state"] == "DISABLED", what="hsad to come up DISABLED")
        code, out = operator.ctl("enable")
        assert code == 0, out
        cls.record = tempfile.NamedTemporaryFile(suffix=".csv", delete=False).name

    @classmethod
    def tearDownClass(cls):
        code, err = cls.daemon.stop()
        os.unlink(cls.record)
        print(err[-2000:], file=sys.stderr)

    def test_1_an_excitation_outside_the_soft_limits_is_refused_and_changes_nothing(self):
        before = operator.wait_for(lambda s: s["state"] == "ENABLED", what="ENABLED")
        # 289.5 mm ± 1 mm reaches 290.5 mm, over the soft limit of 290 mm.
        code, out = operator.ctl("excite", "--at", "289.5", "--amplitude", "1", "--duration", "5")
        self.assertEqual(code, 1, out)
        self.assertIn("excite refused: excitation 288.500..290.500 mm", out)
        self.assertIn("outside the soft limits [10.00, 290.00] mm", out)
        after = operator.status()
        self.assertEqual(after["state"], "ENABLED")
        self.assertFalse(after["exciting"])
        self.assertEqual((after["kp"], after["ki"]), (before["kp"], before["ki"]))
        self.assertLess(abs(after["status_position_m"] - before["status_position_m"]), 5e-5)

    def test_2_the_papers_run_identifies_the_rigs_plant(self):
        code, out = operator.ctl("excite", "--at", str(WORKING_POINT_MM), "--amplitude", "1", "--switching", "0.3",
                                 "--levels", "5", "--duration", str(DURATION_S), "--seed", "3", "--kp", "200",
                                 "--record", self.record)
        print(out)
        self.assertEqual(code, 0, out)
        s = operator.status()
        self.assertEqual(s["state"], "ENABLED")
        self.assertFalse(s["exciting"])
        self.assertEqual((s["kp"], s["ki"]), (85.0, 460.0))  # hsad-sim.toml's PI, back
        self.assertAlmostEqual(s["status_setpoint_m"] * 1e3, WORKING_POINT_MM, places=6)  # holding the working point
        # The run, its start and its end allocated and locked nothing on the RT thread.
        self.assertEqual((s["rt_allocations"], s["rt_locks"]), (0, 0))

        if os.environ.get("HSA_KEEP_RECORD"):  # for a look at a failed run
            shutil.copy(self.record, os.environ["HSA_KEEP_RECORD"])
        with open(self.record) as f:
            rows = list(csv.DictReader(f))
        # The run's samples and nothing else: one per 1 ms telemetry window it touched (a window whose
        # first ticks an overrun skipped may publish the run's first cycle, so one more at most).
        self.assertGreater(len(rows), 0.9 * DURATION_S * 1000)
        self.assertLessEqual(len(rows), DURATION_S * 1000 + 1)
        self.assertTrue(all(r["exciting"] == "1" and r["state"] == "2" for r in rows))

        # The identification assumes one sample per loop period. A host that keeps hsad's RT thread
        # from its deadlines (a stock kernel beside a parallel build: periods skipped, wake-ups
        # 100-600 µs late) takes samples off their period or skips them. `identify` takes such a
        # record (each period from its nearest sample, counted), but its figures then move with the
        # host: through hsad on the custom rig, within 2.5 % in three runs and 12.5 % on b0 in a
        # fourth. The 5 % comparison is asserted on a record with every sample on its period;
        # otherwise it is reported and skipped.
        steps = [int(b["seq"]) - int(a["seq"]) for a, b in zip(rows, rows[1:])]
        gaps = [int(b["utime_us"]) - int(a["utime_us"]) for a, b in zip(rows, rows[1:])]
        off_period = sum(1 for g in gaps if abs(g - 1000) > 100)
        missed = (int(rows[-1]["seq"]) - int(rows[0]["seq"])) // 10 + 1 - len(rows)
        if any(d != steps[0] for d in steps) or off_period:
            self.skipTest(f"the host kept hsad off its RT deadlines: {missed} telemetry samples missed, "
                          f"{sum(1 for d in steps if d != 10)} taken off their base tick, {off_period} more than "
                          f"10 % off their 1 ms period ({s['rt_overruns']} RT overruns so far); the comparison "
                          f"needs every sample on its period")
        # Every sample of the run, at the cylinder loop's rate, to within the start's and end's cycle.
        self.assertGreaterEqual(len(rows), DURATION_S * 1000 - 2)
        identified = analyze("identify", self.record)
        rig = analyze("calibration", "--config", CONFIG, "--points", f"{WORKING_POINT_MM / 1000}:0")[0]
        print(f"identified b0 {identified['b0']['value']:.0f}, b1 {identified['b1']['value']:.1f}, "
              f"k01 {identified['k01']['value']:.1f} mm/s, fit {identified['fit_index']:.3f}, "
              f"kp {identified['kp_per_m']:.1f} /m; calibration b0 {rig['b0']:.0f}, b1 {rig['b1']:.1f}, "
              f"k01 {rig['k01']:.1f} mm/s")
        for name in ("b0", "b1", "k01"):
            with self.subTest(name=name):
                self.assertLess(abs(identified[name]["value"] / rig[name] - 1), 0.05)
        self.assertGreaterEqual(identified["fit_index"], 0.85)


if __name__ == "__main__":
    unittest.main(verbosity=2)
