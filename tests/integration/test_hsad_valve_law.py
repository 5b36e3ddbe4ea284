"""hsad running the valve law identified offline: the model-inverse step (Canuto et al. 2014, eq 31,
with the model-inverse feed-forward of the reference) and the time-optimal step (the same law behind
the predictor driven by the identified model, its K_v, K_a chosen on that model, and full-effort moves
on a jump of the reference) set from a valve-excite record by `hsa-analyze valve-law`, pasted into
systemd/hsad-sim-proportional.toml in place of its preset [axes.valve_law] table; and the predictive
law (control/valve_predictive.hpp) that replaces eq 31 and its predictor, set the same way.

Run by ctest inside a private network namespace (hsad opens its LCM bridge):
    python3 test_hsad_valve_law.py HSAD HSACTL HSA_ANALYZE CONFIG
HSAD is hsad-rtcount (hsad with the counting hooks). CONFIG is systemd/hsad-sim-proportional.toml.
  - `hsa-analyze experiment valve-excite --csv` records the simulated valve open loop, and
    `hsa-analyze valve-law RECORD --step model-inverse|time-optimal|predictive` prints the table (the
    time-optimal one with its [axes.valve_law.model] and [axes.valve_law.time_optimal] sub-tables,
    the predictive one with its [axes.valve_law.predictive] sub-table);
  - `hsad --check-config` on the pasted configuration passes and prints the feed-forward settings
    (and for time-optimal the model predictor and the moves);
  - hsad runs it: the axis enables, a move of 50 mm arrives within 0.1 mm, no fault, and the RT
    cycle allocated and locked nothing.
The spool's tracking error is not compared with the preset's here: hsad publishes the spool's
position but not its reference, and on this shared VM skipped periods alone move a holding rod by
tenths of a millimetre (test_hsad.py), so there is no fair, deterministic measure through the
daemon; `hsa-analyze experiment valve` compares the laws on the lockstep rig. Every wait is bounded.
"""
import os
import re
import subprocess
import sys
import tempfile
import tomllib
import unittest

import hsad_process

HSAD, HSACTL, ANALYZE, CONFIG = sys.argv[1:5]
del sys.argv[1:5]

AXIS = "lift"
operator = hsad_process.Operator(HSACTL, AXIS, timeout=30)


def run(*args, timeout=60):
    r = subprocess.run(list(args), capture_output=True, text=True, timeout=timeout)
    return r.returncode, r.stdout, r.stderr


_record = None


def valve_record():
    """One valve-excite record of the simulated valve, for every step's table."""
    global _record
    if _record is None:
        _record = tempfile.NamedTemporaryFile(suffix=".csv", delete=False).name
        code, out, err = run(ANALYZE, "experiment", "valve-excite", "--csv", _record)
        assert code == 0, err
    return _record


def identified_table(step):
    """The [axes.valve_law] table hsa-analyze prints for `step` from a simulated record."""
    code, table, err = run(ANALYZE, "valve-law", valve_record(), "--step", step)
    assert code == 0, err
    return table


def pasted(config_text, table):
    """`config_text` with its [axes.valve_law] table (header to the next table) replaced by `table`."""
    text, n = re.subn(r"(?ms)^\[axes\.valve_law\]\n.*?(?=^\[)", lambda _: table + "\n", config_text, count=1)
    assert n == 1, "no [axes.valve_law] in the configuration"
    return text


class IdentifiedValveLawTest(unittest.TestCase):
    STEP = "model-inverse"

    @classmethod
    def setUpClass(cls):
        cls.table = identified_table(cls.STEP)
        print(cls.table, file=sys.stderr)
        cls.text = pasted(hsad_process.quiet_config_text(CONFIG), cls.table)

    def write(self):
        f = tempfile.NamedTemporaryFile("w", suffix=".toml", delete=False)
        f.write(self.text)
        f.close()
        return f.name

    def test_1_the_table_is_the_model_inverse_law_and_parses(self):
        law = tomllib.loads(self.text)["axes"][0]["valve_law"]
        self.assertIs(law["track_filtered_reference"], True)
        self.assertEqual(law["reference_filter_hz"], 300.0)
        for key in ("reference_velocity_a_per_m_s", "reference_acceleration_a_per_m_s2", "reference_jerk_a_per_m_s3"):
            self.assertGreater(law[key], 0.0, key)
        # The simulated valve is the paper's: its I_max, and its null current within the safe band
        # hsad-sim-proportional.toml's safe_valve_command is checked against.
        self.assertAlmostEqual(law["max_current_a"], 3.0, delta=0.03)
        self.assertAlmostEqual(law["bias_current_a"], 1.5208, delta=0.02)

    def test_2_check_config_prints_the_new_settings(self):
        path = self.write()
        try:
            code, out, err = run(HSAD, "--check-config", path, "--key-dir", hsad_process.KEY_DIR)
        finally:
            os.unlink(path)
        self.assertEqual(code, 0, err)
        self.check_summary(out + err)

    def check_summary(self, summary):
        self.assertIn("feed-forward  reference filter 300 Hz, K_rv ", summary)
        self.assertIn("tracks the filtered reference", summary)

    def test_3_hsad_runs_it_and_the_axis_moves_without_fault(self):
        daemon = hsad_process.Daemon(HSAD, self.write(), 40)
        try:
            operator.wait_for(lambda s: s["state"] == "DISABLED", what="hsad to come up DISABLED")
            code, out = operator.ctl("enable")
            self.assertEqual(code, 0, out)
            operator.wait_for(lambda s: s["state"] == "ENABLED" and abs(s["spool_position_m"]) < 0.5e-3,
                              what="the spool near its null while enabled")
            operator.move_arrives_cleanly(self, 200)
        finally:
            code, err = daemon.stop()
            print(err[-2000:], file=sys.stderr)


class TimeOptimalValveLawTest(IdentifiedValveLawTest):
    """The time-optimal step: the model predictor and the moves through the daemon's own reader."""
    STEP = "time-optimal"

    def test_1_the_table_is_the_model_inverse_law_and_parses(self):
        super().test_1_the_table_is_the_model_inverse_law_and_parses()
        law = tomllib.loads(self.text)["axes"][0]["valve_law"]
        # The model predictor runs in the paper's predictor's place: its eigenvalues are the model's.
        self.assertNotIn("predictor_gamma", law)
        model = law["model"]
        self.assertEqual(model["predictor_gamma"], [0.2, 0.2, 0.02, 0.02])
        self.assertAlmostEqual(model["natural_frequency_hz"], 50.0, delta=0.5)
        self.assertAlmostEqual(model["delay_s"], 0.5e-3, delta=0.05e-3)
        # d_on = g I_max w0 T with the paper valve's figures: 1.82 mm/A, 3 A, 50 Hz, 100 us.
        self.assertAlmostEqual(law["time_optimal"]["trigger_m"], 1.72e-4, delta=0.05e-4)
        # The damped step's K_v above the preset's 7.5 A/(m/s).
        self.assertGreater(law["velocity_a_per_m_s"], 7.5)

    def check_summary(self, summary):
        super().check_summary(summary)
        self.assertIn("predictor     the identified model's: g ", summary)
        self.assertIn("time-optimal  on: trigger ", summary)


class PredictiveValveLawTest(IdentifiedValveLawTest):
    """The predictive step: the constrained model-predictive law (control/valve_predictive.hpp) in
    the valve loop's place, its matrices built by hsad from the identified valve and the settings
    the design chose on the fit's model (hsa-analyze valve-law --step predictive)."""
    STEP = "predictive"

    def test_1_the_table_is_the_model_inverse_law_and_parses(self):
        law = tomllib.loads(self.text)["axes"][0]["valve_law"]
        self.assertAlmostEqual(law["max_current_a"], 3.0, delta=0.03)
        self.assertAlmostEqual(law["bias_current_a"], 1.5208, delta=0.02)
        # Eq 31 does not run: none of its gains is there to look configured.
        for key in ("proportional_a_per_m", "integral_a_per_m_s", "velocity_a_per_m_s", "dither_amplitude_a",
                    "reference_filter_hz", "predictor_gamma", "model", "time_optimal"):
            self.assertNotIn(key, law)
        predictive = law["predictive"]
        self.assertAlmostEqual(predictive["natural_frequency_hz"], 50.0, delta=0.5)
        self.assertAlmostEqual(predictive["dead_band_a"], 0.3, delta=0.03)
        self.assertIn(predictive["preview_samples"], (16, 28))  # the design's grid

    def check_summary(self, summary):
        self.assertIn("predictive", summary)
        self.assertNotIn("feed-forward  reference filter", summary)


def tearDownModule():
    if _record is not None:
        os.unlink(_record)

if __name__ == "__main__":
    unittest.main(verbosity=2)
