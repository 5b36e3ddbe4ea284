"""`hsa-analyze identify --set` and `hsa-analyze loop --plants`, run as built, on runs of the
simulated rig written as `hsactl record` writes them (make_identification_run): the plant-set file
is written with one plant per run, the nominal and the capability; loop reads it back and gives
margins on every plant; bad input is refused naming what was expected.

    python3 test_identify_set_command.py HSA_ANALYZE MAKE_RUN
"""
import json
import os
import subprocess
import sys
import tempfile
import tomllib
import unittest

ANALYZE, MAKE_RUN = sys.argv[1:3]
del sys.argv[1:3]


def analyze(*args):
    return subprocess.run([ANALYZE, *args], capture_output=True, text=True, timeout=120)


class IdentifySetCommandTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.dir = tempfile.TemporaryDirectory()
        cls.runs = []
        for position, load, seed in ((0.05, 0, 61), (0.15, 3, 62), (0.25, 6, 63)):
            path = os.path.join(cls.dir.name, f"run-{int(position * 1000)}mm.csv")
            subprocess.run([MAKE_RUN, path, str(position), str(load), str(seed), "12"], check=True, timeout=60)
            cls.runs.append((path, load))
        cls.plants = os.path.join(cls.dir.name, "plants.toml")
        cls.result = analyze("identify", "--set", *[f"{p}@{l}kg" for p, l in cls.runs], "--out", cls.plants)

    @classmethod
    def tearDownClass(cls):
        cls.dir.cleanup()

    def test_the_set_has_a_plant_per_run_a_nominal_and_the_capability(self):
        self.assertEqual(self.result.returncode, 0, self.result.stderr)
        print(self.result.stdout)
        with open(self.plants, "rb") as f:
            doc = tomllib.load(f)
        self.assertEqual((doc["format"], doc["version"]), ("hsa-plant-set", 1))
        self.assertEqual([p["name"] for p in doc["plant"]], ["run-50mm.csv@0kg", "run-150mm.csv@3kg", "run-250mm.csv@6kg"])
        for plant, (_, load), position in zip(doc["plant"], self.runs, (0.05, 0.15, 0.25)):
            self.assertEqual(plant["load_kg"], load)
            self.assertAlmostEqual(plant["position_m"], position, delta=1e-3)
            self.assertGreater(plant["b0_per_s2"], 5000)
            self.assertLess(plant["k01_m_s"], 1.0)  # m/s, not the paper's mm/s
        scores = [p["nominal_score"] for p in doc["plant"]]
        self.assertEqual(doc["nominal"], scores.index(max(scores)))
        self.assertIn("nominal", self.result.stdout.splitlines()[1 + doc["nominal"]])
        for direction in ("extend", "retract"):
            c = doc["capability"][direction]
            self.assertAlmostEqual(c["speed_limit_m_s"], doc["capability"]["margin"] * c["max_speed_m_s"])
            self.assertGreater(c["max_speed_m_s"], 0.1)

    def test_loop_reads_the_set_and_gives_margins_on_every_plant(self):
        r = analyze("loop", "--plants", self.plants, "--plant", "all", "--json")
        self.assertEqual(r.returncode, 0, r.stderr)
        results = json.loads(r.stdout)
        self.assertEqual(len(results), 4)  # three plants and the worst case
        for a in results:
            print(f"{a['plant']}: gain margin {a['gain_margin_db']:.2f} dB, phase margin {a['phase_margin_deg']:.2f} deg")
            self.assertGreater(a["gain_margin_db"], 6)
            self.assertGreater(a["phase_margin_deg"], 30)
        nominal = analyze("loop", "--plants", self.plants, "--json")
        self.assertEqual(nominal.returncode, 0, nominal.stderr)
        with open(self.plants, "rb") as f:
            doc = tomllib.load(f)
        p = doc["plant"][doc["nominal"]]
        self.assertEqual(json.loads(nominal.stdout)[0]["plant"], f"{p['position_m']:g}:{p['load_kg']:g}")
        one = analyze("loop", "--plants", self.plants, "--plant", "0.25:6", "--json")
        self.assertEqual(one.returncode, 0, one.stderr)
        self.assertEqual(len(json.loads(one.stdout)), 1)
        missing = analyze("loop", "--plants", self.plants, "--plant", "0.12:6")
        self.assertNotEqual(missing.returncode, 0)
        self.assertIn("no plant of", missing.stderr)
        # Without --plants the default stays Table A3.
        table = analyze("loop", "--plant", "all", "--json")
        self.assertEqual(len(json.loads(table.stdout)), 34)

    def test_a_run_without_its_load_is_refused(self):
        r = analyze("identify", "--set", self.runs[0][0], "--out", os.path.join(self.dir.name, "x.toml"))
        self.assertNotEqual(r.returncode, 0)
        self.assertIn("@<load>kg", r.stderr)
        self.assertFalse(os.path.exists(os.path.join(self.dir.name, "x.toml")))

    def test_a_bad_plant_file_is_refused_with_file_line_and_key(self):
        with open(self.plants) as f:
            text = f.read()
        bad = os.path.join(self.dir.name, "bad.toml")
        with open(bad, "w") as f:
            f.write(text.replace("margin = 0.7", "margin = 7"))
        line = text[: text.index("margin = 0.7")].count("\n") + 1
        r = analyze("loop", "--plants", bad)
        self.assertNotEqual(r.returncode, 0)
        self.assertIn(f"{bad}:{line}:", r.stderr)
        self.assertIn("capability.margin: expected a finite number in (0, 1], got 7", r.stderr)

    def test_a_single_run_reports_its_capability(self):
        r = analyze("identify", self.runs[1][0], "--json")
        self.assertEqual(r.returncode, 0, r.stderr)
        c = json.loads(r.stdout)["capability"]
        self.assertEqual(c["margin"], 0.7)
        self.assertGreater(c["retract"]["max_acceleration_m_s2"], 1)


if __name__ == "__main__":
    unittest.main(verbosity=2)
