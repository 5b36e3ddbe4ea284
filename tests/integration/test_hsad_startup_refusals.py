"""What hsad refuses at start, `hsad --check-config` refuses too, in the same words.

Run by ctest inside a private network namespace (a start that is not refused opens LCM):
    python3 test_hsad_startup_refusals.py HSAD CONFIG
CONFIG is systemd/hsad-sim.toml. For each case of the table, a copy of it is changed (or the keys
or the locks are), then both `hsad --check-config` and `hsad --config ... --duration 1` run: both
must refuse, the start's refusal (its last line) must be among the check's, and it must say what
the case is about. The simulated rig needs no device, so every refusal here is one the check can
make without opening anything, among them a max_speed_m_s over what the axis's plant set can follow.
The lock too: an hsad whose LCM URL differs from a running one's
only in `ttl` is refused, by both, naming the running one's pid.
"""
import os
import shutil
import signal
import subprocess
import sys
import tempfile
import time
import unittest

import hsad_process

HSAD, CONFIG = sys.argv[1:3]
del sys.argv[1:3]


def edited(text, old, new):
    assert old in text, f"{old!r} not in {CONFIG}"
    return text.replace(old, new, 1)


ESTOP = '[axes.signals.estop]       # digital input, true while the e-stop is pressed (optional)\ndriver = "rig"\nchannel = "estop"'
# Each case: (what it is, how the configuration text changes, what the refusal must say).
CASES = [
    ("an e-stop bound to the valve-enable output",
     lambda t: edited(t, ESTOP, ESTOP.replace('channel = "estop"', 'channel = "valve_enable"')),
     "kind mismatch: the signal is digital input, the channel is digital output"),
    ("a signal bound to a channel the driver does not have",
     lambda t: edited(t, 'channel = "pressure_b"', 'channel = "pressure_c"'),
     "channel 'pressure_c': no such channel"),
    ("the position bound to an analog input",
     lambda t: edited(t, 'channel = "encoder"', 'channel = "pressure_a"'),
     "kind mismatch: the signal is encoder input, the channel is analog input"),
    ("a signal bound to a driver that does not exist",
     lambda t: edited(t, '[axes.signals.pressure_a]  # analog input, Pa (required)\ndriver = "rig"',
                      '[axes.signals.pressure_a]  # analog input, Pa (required)\ndriver = "nope"'),
     "nope"),
    ("settings the plugin refuses",
     lambda t: edited(t, 'valve = "servo"', 'valve = "banana"'),
     "valve: expected"),
    ("a proportional drive on a rig without a spool channel",
     lambda t: edited(t, 'valve = "servo"', 'valve = "proportional"'),
     "opening_cmd"),
    # The gain gate: kp 400 closes an unstable loop on plants of Table A3 (max_kp raised so that
    # the bounds let it by); the refusal names the file's key and the worst plant.
    ("configured gains the gain gate refuses",
     lambda t: edited(edited(t, "max_kp = 170.0", "max_kp = 800.0"), "kp = 85.0 ", "kp = 400.0 "),
     "axes[0].pi.kp: expected gains that pass the gain gate (with ki 460 they are refused: unstable on plant "
     "6 kg / 290 mm (GM -1.19 dB)"),
]


class StartupRefusalsTest(unittest.TestCase):
    def setUp(self):
        self.dir = tempfile.mkdtemp()
        self.lock_dir = os.path.join(self.dir, "locks")
        self.text = hsad_process.quiet_config_text(CONFIG)
        self.daemons = []

    def tearDown(self):
        for d in self.daemons:
            if d.poll() is None:
                d.send_signal(signal.SIGTERM)
            d.communicate(timeout=20)
        shutil.rmtree(self.dir)

    def config(self, text, name="hsad.toml"):
        path = os.path.join(self.dir, name)
        with open(path, "w") as f:
            f.write(text)
        return path

    def hsad(self, *args, key_dir=hsad_process.KEY_DIR):
        r = subprocess.run([HSAD, *args, "--lock-dir", self.lock_dir, "--key-dir", key_dir],
                           capture_output=True, text=True, timeout=60)
        return r.returncode, r.stderr

    def assert_both_refuse(self, config, says, key_dir=hsad_process.KEY_DIR):
        """Both refuse `config`; the start's refusal is among the check's and contains `says`.
        Returns that refusal."""
        start_code, start_err = self.hsad("--config", config, "--duration", "1", key_dir=key_dir)
        check_code, check_err = self.hsad("--check-config", config, key_dir=key_dir)
        self.assertNotEqual(start_code, 0, f"the start was not refused: {start_err}")
        refusal = start_err.strip().splitlines()[-1]
        self.assertIn(says, refusal, f"the start refused for another reason: {start_err}")
        self.assertNotEqual(check_code, 0, f"--check-config passed what the start refuses ({refusal}): {check_err}")
        self.assertIn(refusal, check_err.splitlines(), f"--check-config refused in other words: {check_err}")
        return refusal

    def test_each_start_up_refusal_is_made_by_check_config_in_the_same_words(self):
        for what, change, says in CASES:
            with self.subTest(what):
                self.assert_both_refuse(self.config(change(self.text)), says)

    def test_a_weak_operator_key_is_refused_by_both(self):
        weak = os.path.join(self.dir, "keys")
        os.mkdir(weak, 0o700)
        with os.fdopen(os.open(os.path.join(weak, "zero.key"), os.O_WRONLY | os.O_CREAT, 0o600), "w") as f:
            f.write("0" * 64 + "\n")
        self.assert_both_refuse(self.config(self.text), "zero.key: is a weak key (all zero)", key_dir=weak)

    def test_a_speed_the_plant_set_cannot_follow_is_refused_by_both(self):
        # The custom rig's identified set (tests/daemon/data) beside the configuration, named by a
        # relative path: it retracts at most 0.0914 m/s, under the example's max_speed_m_s 0.15.
        source = os.path.dirname(os.path.dirname(os.path.abspath(CONFIG)))
        plants = os.path.join(self.dir, "plants.toml")
        shutil.copy(os.path.join(source, "tests", "daemon", "data", "custom-rig-plants.toml"), plants)
        named = edited(self.text, '# plants = "plants.toml"', 'plants = "plants.toml"')
        self.assert_both_refuse(self.config(named),
                                "axes[0].pi.max_speed_m_s: expected at most 0.09137842756 m/s, what the plant can "
                                f"follow retracting (capability.retract.speed_limit_m_s of {plants}), got 0.15")
        # Within it, the check passes and shows the capability the moves are bounded by.
        slower = edited(named, "max_speed_m_s = 0.15 ", "max_speed_m_s = 0.09 ")
        r = subprocess.run([HSAD, "--check-config", self.config(slower), "--lock-dir", self.lock_dir, "--key-dir",
                            hsad_process.KEY_DIR], capture_output=True, text=True, timeout=60)
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertIn(f"retracting 0.09137842756 m/s, 7.056949882 m/s² ({plants})", r.stdout)

    def start_running(self, text, name):
        d = subprocess.Popen([HSAD, "--config", self.config(text, name), "--duration", "60", "--lock-dir",
                              self.lock_dir, "--key-dir", hsad_process.KEY_DIR],
                             stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
        self.daemons.append(d)
        deadline = time.monotonic() + 30
        while time.monotonic() < deadline and not os.path.isdir(self.lock_dir):
            time.sleep(0.05)
        time.sleep(1.0)  # not a timing assertion: the first hsad has taken its locks by now
        self.assertIsNone(d.poll(), "the first hsad did not start")
        return d

    def test_urls_that_differ_only_in_ttl_are_one_network(self):
        ttl0 = self.text
        first = self.start_running(ttl0, "first.toml")
        ttl1 = edited(ttl0, 'lcm_url = "udpm://239.255.76.67:7667?ttl=0"', 'lcm_url = "udpm://239.255.76.67:7667?ttl=1"')
        refusal = self.assert_both_refuse(self.config(ttl1, "second.toml"),
                                          f"another hsad (pid {first.pid}) already drives axis lift on LCM group "
                                          "239.255.76.67 port 7667")
        self.assertIsNone(first.poll(), f"the refused start disturbed the first hsad ({refusal})")


if __name__ == "__main__":
    unittest.main(verbosity=2)
