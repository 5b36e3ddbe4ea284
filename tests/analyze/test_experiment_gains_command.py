"""`hsa-analyze experiment step` with the PI's gains given: --kp/--ki, or --gains-from a file as
`hsa-analyze tune --out` writes it (the reader hsactl uses), run as built. The gains reach the
run (JSON's kp/ki and a different step), the prediction follows them, the CSV takes the predicted
step beside the measured one, and bad input is refused naming the file, line and key.

    python3 test_experiment_gains_command.py HSA_ANALYZE
"""
import csv
import json
import os
import subprocess
import sys
import tempfile
import tomllib
import unittest

ANALYZE = sys.argv[1]
del sys.argv[1]
ONE_CASE = ("--position", "0.15", "--load", "3")


def analyze(*args):
    return subprocess.run([ANALYZE, *args], capture_output=True, text=True, timeout=300)


def step(*args):
    r = analyze("experiment", "step", *ONE_CASE, "--json", *args)
    if r.returncode != 0:
        raise AssertionError(r.stderr)
    return json.loads(r.stdout)[0]


class ExperimentGainsCommandTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.dir = tempfile.TemporaryDirectory()
        cls.gains = os.path.join(cls.dir.name, "gains.toml")
        r = analyze("tune", "--out", cls.gains)
        if r.returncode != 0:
            raise AssertionError(r.stderr)
        with open(cls.gains, "rb") as f:
            cls.tuned = tomllib.load(f)

    @classmethod
    def tearDownClass(cls):
        cls.dir.cleanup()

    def test_default_is_the_papers_gains(self):
        s = step()
        self.assertEqual((s["kp"], s["ki"]), (85, 460))
        # The keys the step always had are still there.
        for key in ("position_m", "load_kg", "step_m", "overshoot_pct", "settling_s", "rest_peak_to_peak_m",
                    "rest_error_m", "oscillating"):
            self.assertIn(key, s)
        self.assertEqual(s["predicted_plant"], "3 kg / 150 mm")

    def test_gains_from_a_tune_file_run_as_the_same_gains_given_by_hand(self):
        from_file = step("--gains-from", self.gains)
        by_hand = step("--kp", repr(self.tuned["kp"]), "--ki", repr(self.tuned["ki"]))
        print(f"tuned kp {from_file['kp']:.2f}, ki {from_file['ki']:.1f}: overshoot {from_file['overshoot_pct']:.2f} % "
              f"(predicted {from_file['predicted_overshoot_pct']:.2f} %), settling {from_file['settling_s']:.3f} s "
              f"(predicted {from_file['predicted_settling_s']:.3f} s)")
        self.assertAlmostEqual(from_file["kp"], self.tuned["kp"])
        self.assertAlmostEqual(from_file["ki"], self.tuned["ki"])
        self.assertEqual(from_file, by_hand)
        paper = step()
        self.assertNotEqual(from_file["overshoot_pct"], paper["overshoot_pct"])
        self.assertNotEqual(from_file["predicted_overshoot_pct"], paper["predicted_overshoot_pct"])

    def test_the_csv_takes_the_predicted_step_beside_the_measured(self):
        path = os.path.join(self.dir.name, "step.csv")
        r = analyze("experiment", "step", *ONE_CASE, "--csv", path, "--csv-prediction")
        self.assertEqual(r.returncode, 0, r.stderr)
        with open(path) as f:
            rows = list(csv.DictReader(f))
        cases = {row["case"] for row in rows}
        self.assertEqual(cases, {"150mm_3kg", "150mm_3kg_predicted"})
        predicted = [row for row in rows if row["case"] == "150mm_3kg_predicted"]
        self.assertEqual(len(predicted), 3000)
        self.assertAlmostEqual(float(predicted[-1]["position_m"]), 0.16, delta=1e-6)  # settled on the target
        self.assertEqual(predicted[0]["opening"], "nan")

    def test_bad_gains_are_refused_naming_file_line_and_key(self):
        bad = os.path.join(self.dir.name, "bad.toml")
        with open(bad, "w") as f:
            f.write("kp = 62.8\nki = -3\n")
        r = analyze("experiment", "step", *ONE_CASE, "--gains-from", bad)
        self.assertNotEqual(r.returncode, 0)
        self.assertIn(f"{bad}:2:", r.stderr)
        self.assertIn("ki: expected a number >= 0, got -3", r.stderr)
        both = analyze("experiment", "step", "--gains-from", self.gains, "--kp", "60")
        self.assertNotEqual(both.returncode, 0)
        self.assertIn("excludes", both.stderr)
        valve = analyze("experiment", "valve", "--kp", "60")
        self.assertNotEqual(valve.returncode, 0)
        self.assertIn("gains do not apply", valve.stderr)
        csv_only = analyze("experiment", "step", "--csv-prediction")
        self.assertNotEqual(csv_only.returncode, 0)
        self.assertIn("with --csv", csv_only.stderr)


if __name__ == "__main__":
    unittest.main(verbosity=2)
