"""The flight recorder against every kind of fault the simulated rig can script: the real hsad on the
sim plugin, one run per scenario, each fault injected by the plugin's [[events]] at a known time of
the rig's simulated time. Each capture file (opened with Debian's python3-scipy) must have its
trigger on the fault's own cycle, and the rows before it must be every RT cycle, at the base rate,
covering the configured pre-trigger window (or, after an earlier capture, all there was since it).

The rig runs in lockstep timing with its step equal to the base period: every RT cycle reads it once
and advances it by one step, so the read of the cycle with row `seq` (the recorder's row count
since hsad started, one row per cycle) takes the rig from seq·step to (seq + 1)·step. An event at
at_s = E·step is applied in that read of the cycle seq = E − 1 (drivers/sim/sim_driver.cpp,
apply_due_events: due once the rig's time is within half a step of it, after the step): what the
read returns shows it in that cycle (an encoder jump, an e-stop, a bus that stops answering); a
sensor fault changes the sample taken in the rig's next step, so it shows in cycle E. A fault that
has to develop (a stuck valve, a lost supply: the rod stops following) is judged on the capture's
own rows instead: the supervisor's following-error streak is recomputed from them.

Set HSA_RECORDER_FAULTS_KEEP=DIR to keep the capture files of the run in DIR (the README's picture
is drawn from the stuck valve's with `hsactl scope`).

Run with /usr/bin/python3 (python3-scipy, python3-numpy) inside a private network namespace.
"""
import glob
import math
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time
import tomllib
import unittest

import numpy as np
import scipy.io

import hsad_process

HSAD, HSACTL, CONFIG = sys.argv[1:4]
del sys.argv[1:4]

_operator = hsad_process.Operator(HSACTL)
ctl, wait_for = _operator.ctl, _operator.wait_for

STEP_S = 1e-4        # the rig's step = hsad-sim.toml's base period (100 µs), so row seq ↔ simulated time
EVENT_AT_S = 6.0     # after start-up, the enable and a tracked sine: a full pre-trigger window (3.5 s)
RING_S, POST_S = 4.0, 0.5  # written into [axes.recorder]; the checks read them back from the file
FOLLOWING_ERROR_S = 0.010  # [axes.safety] following_error_s's default (hsad-sim.toml leaves it out)
# A stuck valve also holds the valve loop's current at its limit, and the current_saturated fault
# (hsad-sim.toml: 0.5 s) races the following error. With the spool stuck, the rod's error behind
# the 30 mm, 0.5 Hz sine reaches the 20 mm limit 0.40-0.47 s after an event at a turning point
# (measured; the event lands there, the sine starting a fixed time after the enable) and about
# 0.54 s after one at mid-stroke (estimated: the rod coasting on at the sine's top speed). With
# 0.5 s either could trip first, so the following-error captures run with the saturation limit
# past the sine's period.
SINE_SATURATION_S = 2.0


def seq_of(at_s):
    """The row (cycle) whose rig read applies an event at `at_s` (the module's docstring)."""
    return round(at_s / STEP_S) - 1


def config_text(folder, events, saturation_s=None):
    """hsad-sim.toml in lockstep timing, quiet about VM overruns, with `events` (dicts of the sim's
    [[events]] keys), the recorder's ring and folder, and `saturation_s` as current_saturation_s
    when given."""
    text = hsad_process.quiet_config_text(CONFIG)
    if saturation_s is not None:
        text, n = re.subn(r"(?m)^current_saturation_s\s*=.*$", f"current_saturation_s = {saturation_s}", text, count=1)
        assert n == 1, f"current_saturation_s not in {CONFIG}"
    old = 'timing = "cycle"'
    assert text.count(old) == 1, f"{old} not in {CONFIG}"
    text = text.replace(old, f'timing = "lockstep"\nstep_s = {STEP_S}')
    head, sep, tail = text.partition("[[axes]]")

    def value(v):
        return ("true" if v else "false") if isinstance(v, bool) else f'"{v}"' if isinstance(v, str) else repr(v)

    script = "".join("[[drivers.settings.events]]\n" + "".join(f"{k} = {value(v)}\n" for k, v in e.items()) + "\n"
                     for e in events)
    return (head + script + sep + tail + f"\n[axes.recorder]\nseconds = {RING_S}\npost_trigger_s = {POST_S}\n"
            + f'\n[recorder]\nfolder = "{folder}"\n')


def codes_of(text):
    """The file's `codes` string ("state: 0 INIT 1 DISABLED ...") as {section: {name: code}}."""
    out = {}
    for line in text.strip().splitlines():
        section, _, rest = line.partition(":")
        words = rest.split()
        out[section] = {name: int(code) for code, name in zip(words[::2], words[1::2])}
    return out


class Scenario:
    """One hsad run with `events` scripted, captures into a folder of its own; `sine` streams a
    tracked sine (hsactl sine) from just after the enable."""

    def __init__(self, events, sine=False):
        self.folder = tempfile.mkdtemp(prefix="hsa-captures-")
        with tempfile.NamedTemporaryFile("w", suffix=".toml", delete=False) as f:
            f.write(config_text(self.folder, events, SINE_SATURATION_S if sine else None))
        # A lock folder of its own: the simulated rig in a private network namespace is no device
        # another hsad on this host could be driving.
        self.lock_dir = tempfile.mkdtemp(prefix="hsa-lock-")
        self.daemon = hsad_process.Daemon(HSAD, f.name, 60, args=("--lock-dir", self.lock_dir))
        self.sine = None
        self.stderr = None
        try:
            wait_for(lambda s: s["state"] == "DISABLED", what="the axis to come up DISABLED")
            code, out = ctl("enable")
            assert code == 0, out
            wait_for(lambda s: s["state"] == "ENABLED", what="ENABLED")
            if sine:
                # 30 mm at 0.5 Hz around 150 mm: 94 mm/s at most, well inside max_speed_m_s.
                self.sine = subprocess.Popen([HSACTL, "sine", "30", "0.5", "--duration", "30"],
                                             stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        except BaseException as e:
            self.close()
            shutil.rmtree(self.folder, ignore_errors=True)
            raise AssertionError(f"{e}\nhsad's stderr:\n{self.stderr}") from e

    def captures(self, count, timeout=15.0):
        """Waits for `count` capture files; stops hsad; returns them opened, oldest trigger first."""
        deadline = time.monotonic() + timeout
        while len(glob.glob(os.path.join(self.folder, "*.mat"))) < count and time.monotonic() < deadline:
            time.sleep(0.1)
        self.close()
        files = sorted(glob.glob(os.path.join(self.folder, "*.mat")))  # named by the trigger's UTC time
        assert len(files) == count, (files, self.stderr)
        keep = os.environ.get("HSA_RECORDER_FAULTS_KEEP")
        if keep:
            os.makedirs(keep, exist_ok=True)
            for f in files:
                shutil.copy(f, keep)
        return [scipy.io.loadmat(f, squeeze_me=True) for f in files]

    def close(self):
        """Stops the sine and hsad (once); hsad's stderr goes to self.stderr."""
        if self.sine is not None and self.sine.poll() is None:
            self.sine.kill()
            self.sine.communicate()
        if self.stderr is None:
            _, self.stderr = self.daemon.stop()
            shutil.rmtree(self.lock_dir, ignore_errors=True)


class FaultCaptures(unittest.TestCase):
    def tearDown(self):
        if hasattr(self, "scenario"):
            self.scenario.close()
            shutil.rmtree(self.scenario.folder, ignore_errors=True)

    def check_capture(self, m, fault, state, history_rows=None):
        """What every capture must show: its trigger is the first cycle of `fault` (the file's
        identifier) entering `state`, and its rows are every RT cycle at the base rate, with the
        configured pre-trigger window before the trigger (or `history_rows`, when an earlier capture
        left less). Returns the trigger's row index (0-based) and the decoded codes."""
        codes = codes_of(m["codes"])
        states, reasons = codes["state"], codes["fault_reason"]
        k = int(m["trigger_index"]) - 1  # 1-based in the file
        where = f"{m['fault']} capture, trigger row {k}"

        # The trigger's cycle, and the cycle before it free of any fault.
        self.assertEqual(m["trigger"], "fault")
        self.assertEqual(m["trigger_state"], state)
        self.assertEqual(m["fault"], fault)
        self.assertEqual(m["state"][k], states[state], where)
        self.assertNotIn(m["state"][k - 1], (states["FAULT"], states["ESTOP"]), where)
        self.assertEqual(m["fault_bits"][k - 1], 0, where)
        self.assertEqual(m["fault_reason"][k - 1], reasons["none"], where)
        self.assertEqual(m["fault_reason"][k], reasons[fault], where)
        self.assertTrue(int(m["fault_bits"][k]) & (1 << reasons[fault]), f"{where}: bits {m['fault_bits'][k]}")
        self.assertEqual(m["tick"][k], m["trigger_tick"])
        self.assertEqual(m["t"][k], 0.0)
        self.assertEqual(m["merged_triggers"], 0)

        # Every cycle, at the base rate: consecutive rows, the tick advancing by one plus the periods
        # the executive skipped (which the file counts); the cycle times one period apart apart from
        # the difference of the two cycles' wake-up lateness, which the file holds too
        # (t_ns = scheduled + lateness, scheduled = the first deadline + tick · period).
        rate = float(m["sample_rate_hz"])
        self.assertEqual(rate, 10_000.0)
        period_ns = 1e9 / rate
        seq, tick, skipped = m["seq"], m["tick"], m["skipped"]
        t_ns, lateness, utime = m["t_ns"], m["lateness_ns"], m["utime_us"]
        self.assertTrue(np.all(np.diff(seq) == 1), f"{where}: a row missing")
        self.assertTrue(np.all(np.diff(tick) == 1 + skipped[1:]), f"{where}: a tick gap no overrun explains")
        step_ns = np.diff(t_ns) - period_ns * (1 + skipped[1:]) - np.diff(lateness)
        self.assertEqual(np.abs(step_ns).max(), 0.0, f"{where}: cycle times off the base tick's grid")
        # utime_us is CLOCK_MONOTONIC in whole µs (rounded down), so each step is within 1 µs of t_ns's.
        self.assertLess(np.abs(np.diff(utime) * 1000 - np.diff(t_ns)).max(), 1000, f"{where}: utime_us")
        np.testing.assert_allclose(m["t"], (t_ns - t_ns[k]) * 1e-9, rtol=0, atol=1e-12)

        # The configured window, read back from the configuration the file carries.
        recorder = tomllib.loads(m["configuration"])["axes"][0]["recorder"]
        ring_rows = round(recorder["seconds"] * rate)
        post_rows = round(recorder["post_trigger_s"] * rate)
        # The trigger's row closes the window before it; post_trigger_s of rows come after it.
        pre_rows = ring_rows - post_rows - 1
        if history_rows is None:
            self.assertEqual(k, pre_rows, f"{where}: rows before the trigger")
        else:
            self.assertLess(history_rows, pre_rows)
            self.assertEqual(k, history_rows, f"{where}: rows before the trigger")
        self.assertEqual(len(seq) - k - 1, post_rows, f"{where}: rows after the trigger")
        self.assertGreaterEqual(tick[k] - tick[0], k)  # the ticks covered: k, plus any skipped
        return k, codes

    def test_encoder_jump_then_estop_each_on_its_cycle_the_second_after_the_first_capture(self):
        # 2.5 s after the first capture froze: less than the 3.5 s window before the trigger, and time
        # for a reset on a loaded machine (hsactl's round trips took over a second under load).
        estop_at_s = EVENT_AT_S + 3.0
        self.scenario = Scenario([{"at_s": EVENT_AT_S, "encoder_jump_m": 0.01},
                                  {"at_s": estop_at_s, "estop": True}])
        wait_for(lambda s: s["state"] == "FAULT", timeout=30, what="the encoder-jump fault")
        # A reset well before the e-stop (3 s of simulated time later), so that it trips from DISABLED.
        wait_for(lambda s: ctl("reset")[0] == 0, what="the reset")
        wait_for(lambda s: s["state"] == "ESTOP", timeout=30, what="the e-stop")
        jump, estop = self.scenario.captures(2)

        k, _ = self.check_capture(jump, "encoder_jump", "FAULT")
        self.assertEqual(jump["state"][k - 1], codes_of(jump["codes"])["state"]["ENABLED"])
        # The jump is seen in the cycle whose read applied it, and judged in that same cycle.
        step = np.diff(jump["position_m"])
        self.assertEqual(list(np.nonzero(np.abs(step) > 0.009)[0] + 1), [k], "the rows where the encoder jumped")
        self.assertEqual(jump["seq"][k], seq_of(EVENT_AT_S))
        self.assertIn("encoder jumped 10.00 mm", jump["reason"])

        # The second capture's history starts where the first one's rows ended (the ring's other
        # buffer, from empty): every row since, and the file says how many by its trigger row.
        history = int(estop["seq"][int(estop["trigger_index"]) - 1] - jump["seq"][-1] - 1)
        k, codes = self.check_capture(estop, "estop", "ESTOP", history_rows=history)
        self.assertEqual(estop["seq"][0], jump["seq"][-1] + 1)
        self.assertEqual(estop["state"][k - 1], codes["state"]["DISABLED"])
        self.assertEqual(estop["seq"][k], seq_of(estop_at_s))
        self.assertEqual(estop["reason"], "e-stop pressed")

    def test_a_lost_pressure_sensor_trips_on_the_first_sample_it_is_missing_from(self):
        self.scenario = Scenario([{"at_s": EVENT_AT_S, "sensor": "pressure_a", "fault": "disconnected"}])
        wait_for(lambda s: s["state"] == "FAULT", timeout=30, what="the sensor fault")
        (m,) = self.scenario.captures(1)
        k, codes = self.check_capture(m, "sensor_not_ok", "FAULT")
        self.assertEqual(m["state"][k - 1], codes["state"]["ENABLED"])
        # The rig's next step samples the disconnected sensor: the first cycle after the event's.
        self.assertEqual(m["seq"][k], seq_of(EVENT_AT_S) + 1)
        pa = m["pressure_a_pa"]
        self.assertTrue(np.all(np.isfinite(pa[:k])), "pressure A unreadable before the trigger")
        self.assertTrue(math.isnan(pa[k]), f"pressure A in the trigger row: {pa[k]}")
        self.assertIn("pressure A", m["reason"])
        self.assertIn("disconnected", m["reason"])

    def test_a_driver_error_trips_in_the_cycle_whose_read_failed(self):
        self.scenario = Scenario([{"at_s": EVENT_AT_S, "driver_error": True}])
        wait_for(lambda s: s["state"] == "FAULT", timeout=30, what="the driver error")
        (m,) = self.scenario.captures(1)
        k, codes = self.check_capture(m, "driver_error", "FAULT")
        self.assertEqual(m["state"][k - 1], codes["state"]["ENABLED"])
        self.assertEqual(m["seq"][k], seq_of(EVENT_AT_S))
        # The failed read left the last good samples in place: the trigger row is the first whose
        # pressures did not change (the sensors' noise changes them every step before).
        pa = m["pressure_a_pa"]
        self.assertEqual(pa[k], pa[k - 1])
        self.assertTrue(np.all(np.diff(pa[:k]) != 0), "a cycle without a fresh pressure before the trigger")
        self.assertEqual(m["reason"], "driver error")

    def check_following_error_trip(self, m, k, codes):
        """The trigger is the cycle in which the following error had been over its limit for
        following_error_s of cycles in a row, as the supervisor judges it (axis_loop.cpp: the rod
        setpoint the PI followed last cycle minus this cycle's position), and not one cycle later or
        earlier; and it was within its limit everywhere before the event."""
        config = tomllib.loads(m["configuration"])["axes"][0]
        limit = config["safety"]["max_following_error_m"]
        cycles = math.ceil(config["safety"].get("following_error_s", FOLLOWING_ERROR_S) * float(m["sample_rate_hz"]) - 1e-9)
        error = m["rod_setpoint_m"][:-1] - m["position_m"][1:]  # error[j - 1]: judged in row j
        over = np.abs(error) > limit
        enabled = m["state"] == codes["state"]["ENABLED"]
        self.assertTrue(np.all(enabled[: k]), "the axis was not driving all along before the trigger")
        self.assertTrue(np.all(over[k - cycles : k]), f"not {cycles} cycles over {limit} m before row {k}")
        self.assertFalse(over[k - cycles - 1], f"over the limit already {cycles + 1} cycles at row {k}")
        event_row = int(seq_of(EVENT_AT_S) - m["seq"][0])
        self.assertGreater(event_row, 0)
        self.assertFalse(np.any(over[: event_row]), "over the limit before the event")
        self.assertIn(f"over limit {limit * 1e3:.2f} mm", m["reason"])
        # The sine was tracked: the setpoint moved in the rows before the event.
        self.assertGreater(np.ptp(m["rod_setpoint_m"][:event_row]), 0.01)

    def test_a_stuck_valve_trips_on_following_error_the_cycle_the_streak_reaches_its_length(self):
        self.scenario = Scenario([{"at_s": EVENT_AT_S, "valve_stuck": True}], sine=True)
        wait_for(lambda s: s["state"] == "FAULT", timeout=30, what="the following error of the stuck valve")
        (m,) = self.scenario.captures(1)
        k, codes = self.check_capture(m, "following_error", "FAULT")
        self.check_following_error_trip(m, k, codes)

    def test_a_lost_supply_trips_on_following_error_the_cycle_the_streak_reaches_its_length(self):
        self.scenario = Scenario([{"at_s": EVENT_AT_S, "supply_lost": True}], sine=True)
        wait_for(lambda s: s["state"] == "FAULT", timeout=30, what="the following error of the lost supply")
        (m,) = self.scenario.captures(1)
        k, codes = self.check_capture(m, "following_error", "FAULT")
        self.check_following_error_trip(m, k, codes)


if __name__ == "__main__":
    unittest.main(verbosity=2)
