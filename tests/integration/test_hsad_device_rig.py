"""hsad with its simulated rig on the sim plugin's device thread (`timing = "device"`): the rig steps
on its own clock, as a rig behind a bus does, and the RT cycle only takes its latest readings and
leaves the command.

Run by ctest inside a private network namespace (hsad opens its LCM bridge):
    python3 test_hsad_device_rig.py HSAD HSACTL CONFIG
HSAD is hsad-rtcount (hsad with the counting hooks); CONFIG is systemd/hsad-sim-proportional.toml,
whose sim driver gets `timing = "device"` (SCHED_FIFO, on the CPU hsad's RT thread does not use):
  - `hsad --check-config` accepts it, and refuses it with a scenario ([[events]]), naming the file,
    the line and the key;
  - hsad runs it: the process has the plugin's device thread (named hsa-sim-device), the axis
    enables, a move of 50 mm arrives within 0.1 mm (hsactl's test) with no fault, and the RT cycle
    allocated and locked nothing. Every wait is bounded.
"""
import os
import subprocess
import sys
import tempfile
import unittest

import hsad_process

HSAD, HSACTL, CONFIG = sys.argv[1:4]
del sys.argv[1:4]

AXIS = "lift"
operator = hsad_process.Operator(HSACTL, AXIS, timeout=30)

SETTINGS = '[drivers.settings]\nvalve = "proportional"'


def device_config(extra=""):
    """The proportional example with its rig on the device thread, as a temporary file: the RT
    thread on CPU 1 and the device thread SCHED_FIFO on CPU 0, as docs/drivers.md says to run it
    (at SCHED_OTHER beside other threads the device thread is held up and then steps in bursts, and
    the held rod wanders with it)."""
    text = hsad_process.quiet_config_text(CONFIG)
    assert text.count(SETTINGS) == 1, "the example's sim driver settings moved"
    assert text.count("\ncpu = -1") == 1, "the example's [realtime] cpu moved"
    text = text.replace("\ncpu = -1", "\ncpu = 1")
    text = text.replace(SETTINGS, SETTINGS + '\ntiming = "device"\ndevice_priority = 70\ndevice_cpu = 0' + extra)
    f = tempfile.NamedTemporaryFile("w", suffix=".toml", delete=False)
    f.write(text)
    f.close()
    return f.name


def device_threads(pid):
    names = []
    for task in os.listdir(f"/proc/{pid}/task"):
        with open(f"/proc/{pid}/task/{task}/comm") as f:
            names.append(f.read().strip())
    return names.count("hsa-sim-device")


class DeviceRigTest(unittest.TestCase):
    def check(self, path):
        try:
            r = subprocess.run([HSAD, "--check-config", path, "--key-dir", hsad_process.KEY_DIR],
                               capture_output=True, text=True, timeout=60)
        finally:
            os.unlink(path)
        return r.returncode, r.stdout + r.stderr

    def test_1_check_config_accepts_it(self):
        code, out = self.check(device_config())
        self.assertEqual(code, 0, out)

    def test_2_a_scenario_is_refused_with_it(self):
        path = device_config("\n[[drivers.settings.events]]\nat_s = 1.0\nestop = true")
        code, out = self.check(path)
        self.assertNotEqual(code, 0, out)
        self.assertIn(os.path.basename(path), out)
        self.assertIn('events: expected no [[events]] with timing = "device"', out)

    def test_3_hsad_runs_the_rig_on_its_device_thread(self):
        daemon = hsad_process.Daemon(HSAD, device_config(), 40)
        try:
            operator.wait_for(lambda s: s["state"] == "DISABLED", what="hsad to come up DISABLED")
            self.assertEqual(device_threads(daemon.proc.pid), 1)
            code, out = operator.ctl("enable")
            self.assertEqual(code, 0, out)
            operator.wait_for(lambda s: s["state"] == "ENABLED", what="the axis enabled")
            operator.move_arrives_cleanly(self, 200)
        finally:
            code, err = daemon.stop()
            print(err[-2000:], file=sys.stderr)


if __name__ == "__main__":
    unittest.main(verbosity=2)
