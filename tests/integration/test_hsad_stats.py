"""hsad --stats-json: the run statistics a script sets beside cyclictest's.

Run by ctest inside a private network namespace (hsad opens its LCM bridge):
    python3 test_hsad_stats.py HSAD_RTCOUNT HSAD CONFIG
CONFIG is systemd/hsad-sim.toml. HSAD_RTCOUNT (hsad with the counting hooks) runs for a few
seconds on the simulated rig, idle, and writes the document at exit. The checks are on its
consistency, never on timing: the histograms hold one sample per cycle, the percentiles come out
of them in order, and the steady-state counters of the RT cycle (allocations, locks, page faults)
are zero. HSAD, the daemon as installed, must say that it carries no counting hooks.
"""
import json
import os
import subprocess
import sys
import tempfile
import tomllib
import unittest

import hsad_process

HSAD, INSTALLED_HSAD, CONFIG = sys.argv[1:4]
del sys.argv[1:4]


class StatsJson(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.dir = tempfile.TemporaryDirectory()
        cls.path = os.path.join(cls.dir.name, "stats.json")
        cls.result = subprocess.run([HSAD, "--config", CONFIG, "--duration", "3", "--stats-json", cls.path,
                                     "--key-dir", hsad_process.KEY_DIR], capture_output=True, text=True, timeout=60)
        with open(CONFIG, "rb") as f:
            cls.config = tomllib.load(f)

    @classmethod
    def tearDownClass(cls):
        cls.dir.cleanup()

    def stats(self):
        self.assertEqual(self.result.returncode, 0, self.result.stderr)
        with open(self.path) as f:
            return json.load(f)

    def test_describes_the_configured_thread_and_axes(self):
        s = self.stats()
        self.assertEqual(s["period_ns"], self.config["realtime"]["base_period_us"] * 1000)
        self.assertEqual(s["priority"], self.config["realtime"]["priority"])
        self.assertEqual([a["name"] for a in s["axes"]], [a["name"] for a in self.config["axes"]])
        self.assertGreater(s["axes"][0]["telemetry_published"], 0)
        self.assertEqual(s["axes"][0]["telemetry_ring_drops"], 0)

    def test_histograms_hold_every_cycle_and_give_the_percentiles(self):
        s = self.stats()
        self.assertGreater(s["cycles"], 0)
        self.assertLessEqual(s["overruns"], s["cycles"])
        for name in ("lateness", "execution"):
            bins = s[f"{name}_histogram"]
            self.assertEqual(sum(count for _, _, count in bins), s["cycles"], name)
            lowers = [lower for lower, _, _ in bins]
            self.assertEqual(lowers, sorted(lowers), f"{name} bins out of order")
            p = s[f"{name}_ns"]
            self.assertLessEqual(p["p50"], p["p99"])
            self.assertLessEqual(p["p99"], p["p99.9"])
            self.assertLessEqual(p["p99.9"], p["max"])
            # Each percentile is a bin's lower edge: the bin that holds it must exist.
            for key in ("p50", "p99", "p99.9"):
                self.assertIn(p[key], lowers, f"{name} {key}")

    def test_the_steady_state_cycle_allocates_locks_and_faults_nothing(self):
        s = self.stats()
        self.assertTrue(s["counters_linked"], "hsad-rtcount links the RT counters")
        self.assertTrue(s["steady"]["reached"])
        for key in hsad_process.RT_COUNTERS_ASSERTED:
            self.assertEqual(s["steady"][key], 0, key)

    def test_the_installed_hsad_carries_no_counting_hooks(self):
        path = os.path.join(self.dir.name, "installed.json")
        run = subprocess.run([INSTALLED_HSAD, "--config", CONFIG, "--duration", "1", "--stats-json", path,
                              "--key-dir", hsad_process.KEY_DIR], capture_output=True, text=True, timeout=60)
        self.assertEqual(run.returncode, 0, run.stderr)
        with open(path) as f:
            s = json.load(f)
        self.assertFalse(s["counters_linked"], "the installed hsad must not replace operator new or pthread locks")
        self.assertEqual(s["steady"]["allocations"], 0)  # not counted, not a measurement
        self.assertGreater(s["cycles"], 0)

    def test_an_unwritable_path_is_refused_before_the_run(self):
        bad = os.path.join(self.dir.name, "no-such-dir", "stats.json")
        run = subprocess.run([HSAD, "--config", CONFIG, "--duration", "30", "--stats-json", bad],
                             capture_output=True, text=True, timeout=20)
        self.assertNotEqual(run.returncode, 0)
        self.assertIn(bad, run.stderr)
        self.assertNotIn("running at", run.stderr, "hsad started a run it could not report")


if __name__ == "__main__":
    unittest.main(verbosity=2)
