"""`hsa-analyze calibration`, run as built: --config on a shipped example of the papers' rig gives
the numbers of the command without it; a configured rig gives its own; --points and --driver pick
what is linearized, and bad input is refused, naming what was expected.

    python3 test_calibration_command.py HSA_ANALYZE SOURCE_DIR
"""
import json
import os
import subprocess
import sys
import tempfile
import unittest

ANALYZE, SOURCE = sys.argv[1:3]
del sys.argv[1:3]
SIM = f"{SOURCE}/systemd/hsad-sim.toml"
CUSTOM = f"{SOURCE}/systemd/hsad-sim-custom-rig.toml"


def run(*args):
    return subprocess.run([ANALYZE, "calibration", *args], capture_output=True, text=True, timeout=120)


def rows(*args):
    r = run(*args, "--json")
    if r.returncode != 0:
        raise AssertionError(r.stderr)
    return json.loads(r.stdout)


class CalibrationCommandTest(unittest.TestCase):
    def test_a_shipped_example_of_the_papers_rig_gives_the_numbers_of_the_papers_rig(self):
        plain = run("--json")
        self.assertEqual(plain.returncode, 0, plain.stderr)
        self.assertEqual(len(json.loads(plain.stdout)), 33)
        for config in (SIM, f"{SOURCE}/systemd/hsad-sim-proportional.toml"):
            configured = run("--config", config, "--json")
            self.assertEqual((configured.returncode, configured.stdout), (0, plain.stdout), configured.stderr)

    def test_points_pick_the_working_points_and_keep_table_a3_where_it_has_them(self):
        got = rows("--points", "0.15:3,0.2:4.5")
        self.assertEqual(list(got[0].keys()),
                         ["position_m", "load_kg", "b0", "b1", "k01", "b0_table", "b1_table", "k01_table"])
        paper = {(r["position_m"], r["load_kg"]): r for r in rows()}
        self.assertEqual(got[0], paper[(0.15, 3)])
        self.assertEqual((got[1]["position_m"], got[1]["load_kg"]), (0.2, 4.5))
        self.assertIsNone(got[1]["b0_table"])  # not one of Table A3's points
        self.assertGreater(got[1]["b0"], 0)

    def test_a_configured_rig_gives_its_own_plant(self):
        paper = rows("--points", "0.15:0")[0]
        custom = rows("--config", CUSTOM, "--points", "0.15:0")[0]
        # A 32 mm bore on the paper's oil and valve: a stiffer spring, a slower rod (k01 ∝ 1/Ap).
        self.assertGreater(custom["b0"], 1.4 * paper["b0"])
        self.assertLess(custom["k01"], 0.7 * paper["k01"])
        # The paper's mass and damping: b1 = σ_eff/m, plus the chambers' small leakage relaxation,
        # which the larger volumes change by about 0.1 % (tests/sim/test_small_signal.cpp).
        self.assertLess(abs(custom["b1"] / paper["b1"] - 1), 0.005)
        self.assertIsNone(custom["b0_table"])  # Table A3 is the paper's rig, not this one
        # The stroke is the configured one: 0.39 m exists on this rig only.
        self.assertEqual(len(rows("--config", CUSTOM, "--points", "0.39:0")), 1)
        r = run("--points", "0.39:0")
        self.assertNotEqual(r.returncode, 0)
        self.assertIn("--points: expected <position_m>:<load_kg> with the position in [0, 0.304] m", r.stderr)

    def test_bad_input_is_refused_naming_what_was_expected(self):
        for args, says in (
            (["--points", "0.15"], "--points: expected <position_m>:<load_kg>"),
            (["--points", "0.15:-1"], "and the load >= 0 kg, got '0.15:-1'"),
            (["--config", f"{SOURCE}/systemd/hsad-modbus-simdev.toml"], "has no driver with plugin = \"sim\""),
            (["--config", SIM, "--driver", "bus"], "has no driver named \"bus\""),
            (["--driver", "rig"], "--driver requires --config"),
        ):
            with self.subTest(args=args):
                r = run(*args)
                self.assertNotEqual(r.returncode, 0)
                self.assertIn(says, r.stderr)

    def test_a_refused_rig_is_refused_with_the_plugins_words(self):
        with open(SIM) as f:
            text = f.read()
        text = text.replace("\n[[axes]]", "\n[drivers.settings.rig.cylinder]\nrod_m = 0.03\n\n[[axes]]", 1)
        line = text.splitlines().index("rod_m = 0.03") + 1
        with tempfile.TemporaryDirectory() as d:
            path = os.path.join(d, "bad.toml")
            with open(path, "w") as f:
                f.write(text)
            r = run("--config", path)
        self.assertNotEqual(r.returncode, 0)
        self.assertIn(f"{path}:{line}:9: rig.cylinder.rod_m: expected a rod diameter below the bore, "
                      "rig.cylinder.bore_m = 0.025 m, got 0.03", r.stderr)


if __name__ == "__main__":
    unittest.main(verbosity=2)
