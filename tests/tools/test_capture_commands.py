"""hsactl's capture commands as built, on captures the flight recorder's own writer makes:
`captures` lists them newest first and a file that is no capture as such; `capture export` writes
the CSV (header with units, one row per sample, the trigger row marked), refuses a file that is no
capture and an existing CSV (exit 2, nothing changed) unless --force; `scope` writes a PNG through
gnuplot, and refuses a signal the capture lacks.

    python3 test_capture_commands.py HSACTL WRITE_TEST_CAPTURE
"""
import csv
import os
import subprocess
import sys
import tempfile
import unittest

HSACTL, WRITER = sys.argv[1:3]
del sys.argv[1:3]

ROWS, TRIGGER_ROW = 400, 300  # write_test_capture.cpp's capture: 0-based trigger row


def run(*args, cwd=None):
    return subprocess.run([HSACTL, *args], capture_output=True, text=True, timeout=60, cwd=cwd)


class CaptureCommandsTest(unittest.TestCase):
    def setUp(self):
        self._dir = tempfile.TemporaryDirectory()
        self.dir = self._dir.name
        self.older = self.capture(1795000000)
        self.newer = self.capture(1795000100)
        with open(os.path.join(self.dir, "notes.mat"), "w") as f:
            f.write("not a MAT-file\n")

    def tearDown(self):
        self._dir.cleanup()

    def capture(self, utc_s):
        r = subprocess.run([WRITER, self.dir, str(utc_s)], capture_output=True, text=True, timeout=60, check=True)
        return r.stdout.strip()

    def test_captures_lists_newest_first_and_names_a_file_that_is_no_capture(self):
        r = run("captures", "--dir", self.dir)
        self.assertEqual(r.returncode, 0, r.stderr)
        lines = r.stdout.splitlines()
        self.assertTrue(lines[0].startswith("FILE"), lines)
        names = [line.split()[0] for line in lines[1:4]]
        self.assertEqual(names, ["notes.mat", os.path.basename(self.newer), os.path.basename(self.older)])
        self.assertIn("unreadable: not a MAT-file", lines[1])
        self.assertIn("2026-11-18 11:08:20.000", lines[2])
        for line in lines[2:4]:
            self.assertIn(" lift ", line)
            self.assertIn(" 400 ", line)
            self.assertIn("0.040 s", line)
            self.assertIn("following error 5.15 mm over limit 5.00 mm", line)

    def test_captures_defaults_to_state_directory_and_refuses_a_missing_folder(self):
        env = dict(os.environ, STATE_DIRECTORY=self.dir + ":/elsewhere")
        r = subprocess.run([HSACTL, "captures"], capture_output=True, text=True, timeout=60, env=env)
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertIn(os.path.basename(self.newer), r.stdout)
        r = run("captures", "--dir", os.path.join(self.dir, "missing"))
        self.assertEqual(r.returncode, 2)
        self.assertIn("missing: cannot list it", r.stderr)

    def test_export_writes_one_row_per_sample_with_the_trigger_marked(self):
        out = os.path.join(self.dir, "c.csv")
        r = run("capture", "export", self.newer, out)
        self.assertEqual((r.returncode, r.stderr), (0, ""))
        with open(out) as f:
            rows = list(csv.reader(f))
        header = rows[0]
        self.assertEqual(header[:2], ["seq [rows]", "tick [base ticks]"])
        self.assertIn("position_m [m]", header)
        self.assertEqual(header[-1], "trigger")
        self.assertEqual(len(rows) - 1, ROWS)
        marked = [k for k, row in enumerate(rows[1:]) if row[-1] == "1"]
        self.assertEqual(marked, [TRIGGER_ROW])
        t = header.index("t [s from the trigger row]")
        state = header.index("state [AxisState]")
        self.assertEqual(float(rows[1 + TRIGGER_ROW][t]), 0.0)
        self.assertEqual(rows[1 + TRIGGER_ROW][state], "3")  # FAULT
        self.assertEqual(rows[TRIGGER_ROW][state], "2")  # ENABLED the cycle before
        self.assertEqual([int(row[0]) for row in rows[1:]], list(range(ROWS)))

    def test_export_refuses_a_file_that_is_no_capture_and_an_existing_csv(self):
        out = os.path.join(self.dir, "c.csv")
        r = run("capture", "export", os.path.join(self.dir, "notes.mat"), out)
        self.assertEqual(r.returncode, 2)
        self.assertIn("notes.mat: not a MAT-file", r.stderr)
        self.assertFalse(os.path.exists(out))
        with open(out, "w") as f:
            f.write("mine\n")
        r = run("capture", "export", self.newer, out)
        self.assertEqual(r.returncode, 2)
        self.assertIn("c.csv exists", r.stderr)
        with open(out) as f:
            self.assertEqual(f.read(), "mine\n")
        r = run("capture", "export", self.newer, out, "--force")
        self.assertEqual((r.returncode, r.stderr), (0, ""))
        with open(out) as f:
            self.assertEqual(sum(1 for _ in f), ROWS + 1)

    def test_scope_writes_a_png(self):
        png = os.path.join(self.dir, "s.png")
        r = run("scope", self.newer, "--out", png)
        self.assertEqual((r.returncode, r.stderr), (0, ""))
        with open(png, "rb") as f:
            data = f.read()
        self.assertTrue(data.startswith(b"\x89PNG\r\n\x1a\n"))
        self.assertGreater(len(data), 5000)
        # Not a terminal and no --out: FILE.png in the current folder.
        r = run("scope", self.newer, "--signals", "pressure_a_pa+pressure_b_pa,state", cwd=self.dir)
        self.assertEqual(r.returncode, 0, r.stderr)
        name = os.path.basename(self.newer)[: -len(".mat")] + ".png"
        self.assertEqual(r.stdout.strip(), name)
        self.assertGreater(os.path.getsize(os.path.join(self.dir, name)), 5000)

    def test_scope_refuses_a_signal_the_capture_lacks_and_a_file_that_is_no_capture(self):
        png = os.path.join(self.dir, "s.png")
        r = run("scope", self.newer, "--signals", "position_m,bogus", "--out", png)
        self.assertEqual(r.returncode, 2)
        self.assertIn("no signal 'bogus'", r.stderr)
        r = run("scope", os.path.join(self.dir, "notes.mat"), "--out", png)
        self.assertEqual(r.returncode, 2)
        self.assertIn("not a MAT-file", r.stderr)
        r = run("scope", os.path.join(self.dir, "missing.mat"), "--out", png)
        self.assertEqual(r.returncode, 2)
        self.assertIn("missing.mat: cannot read it: No such file or directory", r.stderr)
        self.assertFalse(os.path.exists(png))


if __name__ == "__main__":
    unittest.main(verbosity=2)
