"""End-to-end tests of the real hsad process on the simulated rig, driven with the real hsactl.

Run by ctest inside a private network namespace (LCM multicast never reaches the host network):
    python3 test_hsad.py HSAD HSACTL CONFIG TWO_AXES_CONFIG PROPORTIONAL_CONFIG
Each test starts its own hsad with a configuration derived from an example one (plus scripted
sim-plugin events for the faults, see drivers/sim/sim_driver.cpp), and stops it with SIGTERM.
Every wait is bounded; nothing asserts timing: conditions are polled with generous timeouts.

Every fault class is injected through the sim plugin: FAULT (or ESTOP) with the
class's code and reason text, the valve read back in its safe state from telemetry (and, with the
proportional valve, from the spool LVDT), and recovery by `hsactl reset` where the daemon can
recover the cause.
"""
import json
import re
import socket
import subprocess
import sys
import tempfile
import time
import tomllib
import unittest

import hsad_process

HSAD, HSACTL, CONFIG, TWO_AXES_CONFIG, PROPORTIONAL_CONFIG = sys.argv[1:6]
del sys.argv[1:6]

# Wire values of status_t.
INIT, ENABLED, DISABLED, FAULT, ESTOP = "INIT", "ENABLED", "DISABLED", "FAULT", "ESTOP"
(FAULT_SENSOR, FAULT_ENCODER, FAULT_PRESSURE, FAULT_SOFT_LIMIT, FAULT_FOLLOWING_ERROR,
 FAULT_CURRENT_SATURATION, FAULT_OVERRUNS, FAULT_DRIVER, FAULT_ESTOP, FAULT_BLIND_TIME,
 FAULT_CONTROL_OUTPUT, FAULT_INPUTS_NOT_READY) = range(1, 13)

# The proportional valve's spring rest zone (sim/, docs/simulator.md): where a de-energized spool parks.
FAIL_SAFE_SPOOL_M = (-2.5e-3, -1.875e-3)


def event(at_s, **fields):
    """One [[drivers.settings.events]] table of the sim plugin."""
    body = "".join(f"{k} = {json.dumps(v)}\n" for k, v in fields.items())
    return f"[[drivers.settings.events]]\nat_s = {at_s}\n{body}"


def config_with(events="", base=None, **replace):
    """An example configuration, with sim-plugin events appended to its driver's settings."""
    base = base or CONFIG
    with open(base) as f:
        text = f.read()
    for key, value in replace.items():
        text, n = re.subn(rf"(?m)^{key}\s*=.*$", f"{key} = {value}", text, count=1)
        assert n == 1, f"key {key} not in {base}"
    # The events belong to the [drivers.settings] table: insert them right after it.
    if events:
        head, sep, tail = text.partition("[[axes]]")
        text = head + events + "\n" + sep + tail
    f = tempfile.NamedTemporaryFile("w", suffix=".toml", delete=False)
    f.write(text)
    f.close()
    return f.name


def Daemon(config):
    return hsad_process.Daemon(HSAD, config, duration_s=60)


# hsactl with its default axis, "lift"; status() and wait_for() take another with axis=.
_operator = hsad_process.Operator(HSACTL)
ctl, status, wait_for = _operator.ctl, _operator.status, _operator.wait_for


NOISE_OVERRUN_STREAK = hsad_process.NOISE_OVERRUN_STREAK  # see there
OVERRUN_TEST_STREAK = 200  # the limit test_streak_of_rt_overruns provokes


class HsadTest(unittest.TestCase):
    def start(self, **kw):  # events=..., base=..., key=value replacements
        kw.setdefault("overrun_streak", NOISE_OVERRUN_STREAK)
        self.daemon = Daemon(config_with(**kw))
        wait_for(lambda s: s["state"] == DISABLED, what="the axis to come up DISABLED")

    def tearDown(self):
        if hasattr(self, "daemon"):
            self.daemon.stop()

    def test_enable_and_move_settle_within_a_tenth_of_a_millimetre(self):
        self.start()
        self.assertEqual(ctl("enable")[0], 0)
        code, out = ctl("move", "150", "--tolerance", "0.1", "--timeout", "20")
        self.assertEqual(code, 0, out)
        code, out = ctl("move", "200", "--tolerance", "0.1", "--timeout", "20")
        self.assertEqual(code, 0, out)
        s = status()
        self.assertLess(abs(s["position_m"] - 0.200), 0.1e-3)
        self.assertIs(s["valve_enabled"], True, s)  # so that the safe-state checks can fail

    def test_bad_setpoints_are_rejected_and_counted_without_effect(self):
        self.start()
        self.assertEqual(ctl("enable")[0], 0)
        self.assertEqual(ctl("move", "150", "--timeout", "20")[0], 0)
        before = status()
        # 500 mm is outside the axis's soft limits, nan is not a number: both must be refused.
        self.assertNotEqual(ctl("move", "500", "--stream", "--timeout", "1")[0], 0)
        self.assertNotEqual(ctl("move", "nan", "--stream", "--timeout", "1")[0], 0)
        s = wait_for(lambda s: s["rejected_out_of_range"] > before["rejected_out_of_range"]
                     and s["rejected_non_finite"] > before["rejected_non_finite"], what="reject counters")
        self.assertEqual(s["state"], ENABLED, s)
        self.assertLess(abs(s["position_m"] - 0.150), 0.2e-3, "a rejected setpoint moved the rod")

    def test_a_refused_move_is_answered_at_once_with_the_axis_reason_and_changes_nothing(self):
        self.start()
        # Not enabled: the axis's own reason, at once (not a timeout).
        started = time.monotonic()
        code, out = ctl("move", "150", "--timeout", "20")
        self.assertEqual(code, 1, out)
        self.assertIn("move refused: axis not ENABLED: enable it first", out)
        self.assertLess(time.monotonic() - started, 5.0, "a refusal must not wait for the move's timeout")
        # Opening the valve of a disabled axis is refused before anything is sent: the mode stays.
        code, out = ctl("open", "0.1")
        self.assertEqual(code, 1, out)
        self.assertIn("open refused: axis 'lift' is DISABLED, not ENABLED", out)
        self.assertEqual(status()["mode"], "position")
        self.assertEqual(ctl("enable")[0], 0)
        self.assertEqual(ctl("move", "150", "--timeout", "20")[0], 0)
        before = status()
        code, out = ctl("move", "300", "--timeout", "20")
        self.assertEqual(code, 1, out)
        self.assertRegex(out, r"move refused: target outside the axis's soft limits \[[0-9.]+, 290\.00\] mm")
        code, out = ctl("move", "nan", "--timeout", "20")
        self.assertEqual(code, 1, out)
        self.assertIn("not a finite number", out)
        s = status()
        self.assertEqual(s["state"], ENABLED, s)
        self.assertLess(abs(s["position_m"] - before["position_m"]), 0.2e-3, "a refused move moved the rod")

    def test_gains_within_the_bounds_apply_and_gains_over_max_kp_are_refused_with_the_reason(self):
        # The proportional valve axis, holding: a gain change must not disturb it, and a change
        # over its max_kp (default: twice kp = 85, so 170) is refused and says why.
        self.start(base=PROPORTIONAL_CONFIG)
        self.assertEqual(ctl("enable")[0], 0)
        self.assertEqual(ctl("move", "150", "--stream", "--timeout", "20")[0], 0)
        # Where the rod holds once the setpoints stop, and how far it wanders from there on its own:
        # on this shared VM, skipped periods alone move a holding proportional-valve rod by tenths
        # of a millimetre (measured: 0.15 to 1.3 mm peaks with no command at all). The gain changes
        # are judged against that, in the same run; the exact bumplessness is pinned by
        # tests/daemon/test_axis_loop.cpp on the lockstep rig.
        held_m = wait_for(lambda s: s["holding"], what="holding at the move's end")["position_m"]
        wander_before = max(abs(status()["position_m"] - held_m) for _ in range(8))
        # kp 80, ki 400: a change the gain gate passes (Table A3: gain margin 12.5 dB, phase margin
        # 62.1 deg). This test set kp 120 before the gate existed; that pair has 9.0 dB of gain
        # margin on the 6 kg / 290 mm plant, under the default minimum of 11 dB, and is refused now.
        code, out = ctl("gains", "80", "400")
        self.assertEqual(code, 0, out)
        s = status()
        self.assertEqual((s["kp"], s["ki"], s["gain_changes_applied"]), (80.0, 400.0, 1), s)
        code, out = ctl("gains", "500", "460")
        self.assertEqual(code, 1, out)
        self.assertIn("gains refused", out)
        self.assertIn("kp 500 is outside (0, max_kp 170]", out)
        s = status()
        self.assertEqual((s["kp"], s["gain_changes_applied"], s["gain_changes_refused"]), (80.0, 1, 1), s)
        self.assertIn("max_kp 170", s["gains_refusal"])
        # NaN never reaches the axis: the message checks reject it, and hsactl says so.
        code, out = ctl("gains", "nan", "460")
        self.assertEqual(code, 1, out)
        self.assertIn("gains refused: a value is not a finite number", out)
        s = status()
        self.assertEqual(s["state"], ENABLED, s)
        self.assertEqual(s["kp"], 80.0, s)
        wander_after = max(abs(status()["position_m"] - held_m) for _ in range(8))
        print(f"\n    holding: wander {wander_before * 1e3:.3f} mm before the gain changes, "
              f"{wander_after * 1e3:.3f} mm after", end=" ", file=sys.stderr)
        self.assertLess(wander_after, max(0.2e-3, 2.0 * wander_before), "a gain change moved the rod")

    def test_gains_the_gain_gate_refuses_name_the_worst_plant_and_leave_the_running_gains(self):
        # max_kp 500 lets kp 400 past the bounds to the gate: on Table A3 it closes an unstable loop
        # (the 6 kg / 290 mm plant has the smallest gain margin, -1.19 dB); kp 120 is stable with
        # too little gain margin. Neither reaches the RT thread: the running gains stay 85 and 460.
        self.start(max_kp="500.0")
        self.assertEqual(ctl("enable")[0], 0)
        code, out = ctl("gains", "400", "460")
        self.assertEqual(code, 1, out)
        self.assertIn("gains refused: axis 'lift': unstable on plant 6 kg / 290 mm (GM -1.19 dB)", out)
        s = status()
        self.assertEqual((s["kp"], s["ki"], s["gain_changes_applied"], s["gain_changes_refused"]),
                         (85.0, 460.0, 0, 1), s)
        self.assertIn("unstable on plant 6 kg / 290 mm", s["gains_refusal"])
        code, out = ctl("gains", "120", "460")
        self.assertEqual(code, 1, out)
        self.assertIn("gain margin 9.04 dB on plant 6 kg / 290 mm below the minimum 11 dB", out)
        self.assertEqual((status()["kp"], status()["gain_changes_refused"]), (85.0, 2))
        # A pair that passes (gain margin 12.5 dB, phase margin 62.1 deg) is applied.
        code, out = ctl("gains", "80", "400")
        self.assertEqual(code, 0, out)
        s = wait_for(lambda s: s["gain_changes_applied"] == 1, what="the passing gains to be applied")
        self.assertEqual((s["kp"], s["ki"], s["state"]), (80.0, 400.0, ENABLED), s)

    def test_setpoint_silence_holds_position_without_a_fault(self):
        self.start()
        self.assertEqual(ctl("enable")[0], 0)
        self.assertEqual(ctl("move", "170", "--stream", "--timeout", "20")[0], 0)
        s = wait_for(lambda s: s["holding"], what="holding after the setpoint stream stopped")
        self.assertEqual(s["state"], ENABLED)
        self.assertEqual(s["faults"], [])
        self.assertLess(abs(s["position_m"] - 0.170), 0.2e-3)

    def expect_fault(self, code, reason, state=FAULT):
        """Waits for `state` with fault `code`; checks its reason text contains `reason`."""
        s = wait_for(lambda s: s["state"] == state, what=state)
        codes = [f["code"] for f in s["faults"]]
        self.assertIn(code, codes, s)
        text = next(f["reason"] for f in s["faults"] if f["code"] == code)
        self.assertIn(reason, text, s)
        print(f"\n    status: {state}, fault {code}: {text!r}", end=" ", file=sys.stderr)
        return s

    def expect_valve_safe(self, safe_command=0.0, rod_stops=True):
        """The valve read back from telemetry: opening 0, the output at the null command and the
        valve-enable output off.

        With rod_stops, the rod's measured velocity must also fall to (almost) nothing: a
        servo-valve at its null holds an unloaded rod."""
        s = wait_for(lambda s: s["telemetry_state"] in (FAULT, ESTOP), what="telemetry of the fault")
        self.assertEqual(s["valve_opening"], 0.0, s)
        self.assertEqual(s["current_ref_a"], safe_command, s)
        self.assertIs(s["valve_enabled"], False, s)
        if rod_stops:
            wait_for(lambda s: abs(s["velocity_m_s"]) < 2e-3, what="the rod to stop with the valve at null")
        return s

    def reset_and_enable_again(self, move_to_mm=None):
        wait_for(lambda s: ctl("reset")[0] == 0, what="reset to succeed")
        s = wait_for(lambda s: s["state"] == DISABLED, what="DISABLED after reset")
        self.assertEqual(s["faults"], [])
        code, out = ctl("enable")
        self.assertEqual(code, 0, out)
        if move_to_mm is not None:
            code, out = ctl("move", str(move_to_mm), "--timeout", "20")
            self.assertEqual(code, 0, out)
        s = status()
        self.assertEqual(s["state"], ENABLED, s)
        self.assertEqual(s["faults"], [])
        return s

    def fault_then_reset(self, events, state, code, clear_after_s):
        self.start(events=events)
        self.assertEqual(ctl("enable")[0], 0)
        s = wait_for(lambda s: s["state"] == state, what=state)
        self.assertIn(code, [f["code"] for f in s["faults"]], s)
        self.assertTrue(all(f["reason"] for f in s["faults"]), "a fault without a reason text")
        self.expect_valve_safe()
        # The cause is scripted to clear; reset must then succeed (and not before).
        time.sleep(max(0.0, clear_after_s))
        wait_for(lambda s: ctl("reset")[0] == 0, what="reset to succeed")
        s = wait_for(lambda s: s["state"] == DISABLED, what="DISABLED after reset")
        self.assertEqual(s["faults"], [])
        return s

    def test_estop_input(self):
        self.fault_then_reset('[[drivers.settings.events]]\nat_s = 5.0\nestop = true\n'
                              '[[drivers.settings.events]]\nat_s = 7.0\nestop = false\n',
                              ESTOP, FAULT_ESTOP, 1.0)

    def test_disconnected_pressure_sensor(self):
        self.fault_then_reset('[[drivers.settings.events]]\nat_s = 5.0\nsensor = "pressure_a"\nfault = "disconnected"\n'
                              '[[drivers.settings.events]]\nat_s = 7.0\nsensor = "pressure_a"\nfault = "none"\n',
                              FAULT, FAULT_SENSOR, 1.0)

    def test_an_input_late_at_start_is_waited_for_and_not_a_fault(self):
        # Pressure A delivers nothing for its first second, as a bus device that answers late.
        self.daemon = Daemon(config_with(
            events=event(0.0, sensor="pressure_a", fault="disconnected") + event(1.0, sensor="pressure_a", fault="none"),
            overrun_streak=NOISE_OVERRUN_STREAK))
        first = wait_for(lambda s: True, what="a first status")
        self.assertEqual(first["state"], INIT, first)
        self.assertEqual(first["faults"], [], first)
        refused, out = ctl("enable")
        self.assertNotEqual(refused, 0, out)
        s = wait_for(lambda s: s["state"] != INIT, what="the axis to leave INIT")
        self.assertEqual(s["state"], DISABLED, s)
        self.assertEqual(s["faults"], [], s)
        self.assertEqual(ctl("enable")[0], 0)

    def test_an_input_silent_past_the_startup_timeout_faults_naming_it(self):
        self.daemon = Daemon(config_with(
            events=event(0.0, sensor="pressure_a", fault="disconnected") + event(3.0, sensor="pressure_a", fault="none"),
            overrun_streak=NOISE_OVERRUN_STREAK, startup_timeout_s=0.5))
        s = wait_for(lambda s: s["state"] == FAULT, what="FAULT after the start-up timeout")
        self.assertEqual([f["code"] for f in s["faults"]], [FAULT_INPUTS_NOT_READY], s)
        self.assertEqual(s["faults"][0]["reason"],
                         "no first sample from pressure A within 0.5 s of start-up", s)
        self.expect_valve_safe()
        wait_for(lambda s: ctl("reset")[0] == 0, what="reset to succeed once pressure A delivers")
        s = wait_for(lambda s: s["state"] == DISABLED, what="DISABLED after the reset")
        self.assertEqual(s["faults"], [])

    def test_lost_supply_gives_a_following_error(self):
        self.start(events='[[drivers.settings.events]]\nat_s = 5.0\nsupply_lost = true\n')
        self.assertEqual(ctl("enable")[0], 0)
        # Move up; the supply goes at 5 s (during the move or while holding) and the load sinks.
        mover = subprocess.Popen([HSACTL, "move", "250", "--timeout", "15"], stdout=subprocess.DEVNULL,
                                 stderr=subprocess.DEVNULL)
        s = wait_for(lambda s: s["state"] == FAULT, what="FAULT")
        mover.wait(timeout=20)
        self.assertIn(FAULT_FOLLOWING_ERROR, [f["code"] for f in s["faults"]], s)
        self.expect_valve_safe()

    def test_overload_gives_an_over_pressure_fault(self):
        # 100 kg needs ≈ 20 bar in chamber A; the limit is set to 15 bar.
        self.start(events='[[drivers.settings.events]]\nat_s = 5.0\nload_kg = 100\n', max_pressure_pa="15e5")
        self.assertEqual(ctl("enable")[0], 0)
        s = wait_for(lambda s: s["state"] == FAULT, what="FAULT")
        self.assertIn(FAULT_PRESSURE, [f["code"] for f in s["faults"]], s)
        self.expect_valve_safe(rod_stops=False)  # 100 kg on a closed valve may still creep

    def test_open_loop_past_the_soft_limit_faults_and_the_axis_recovers_inward(self):
        self.start()
        self.assertEqual(ctl("enable")[0], 0)
        # 0.3 opens the valve upward: the rod runs from 150 mm past soft_max_m = 290 mm.
        code, out = ctl("open", "0.3", "--duration", "20", timeout=40)
        self.assertNotEqual(code, 0, out)
        s = self.expect_fault(FAULT_SOFT_LIMIT, "beyond soft limit 290.00 mm")
        self.assertGreater(s["position_m"], 0.290, s)
        self.expect_valve_safe()
        # The rod stopped outside the limits. Back to position mode, reset, enable: the axis holds
        # at the limit and can be moved back in.
        code, out = ctl("mode", "position")
        self.assertEqual(code, 0, out)
        s = self.reset_and_enable_again(move_to_mm=150)
        self.assertLess(abs(s["position_m"] - 0.150), 0.2e-3, s)

    def test_open_loop_opening_moves_the_rod_and_position_mode_takes_over_bumplessly(self):
        self.start()
        self.assertEqual(ctl("enable")[0], 0)
        self.assertEqual(ctl("move", "150", "--timeout", "20")[0], 0)
        code, out = ctl("mode", "open-loop")
        self.assertEqual(code, 0, out)
        self.assertEqual(status()["mode"], "open-loop")
        start = status()["position_m"]
        code, out = ctl("open", "0.1", "--duration", "1")
        self.assertEqual(code, 0, out)
        up = wait_for(lambda s: abs(s["velocity_m_s"]) < 2e-3, what="the rod to stop at opening 0")
        self.assertGreater(up["position_m"] - start, 2e-3, up)
        code, out = ctl("open", "-0.1", "--duration", "1")
        self.assertEqual(code, 0, out)
        down = wait_for(lambda s: abs(s["velocity_m_s"]) < 2e-3, what="the rod to stop at opening 0")
        self.assertLess(down["position_m"] - up["position_m"], -2e-3, down)
        self.assertEqual(down["state"], ENABLED, down)
        # Back to position mode: the loop starts from where the rod is and holds it there.
        code, out = ctl("mode", "position")
        self.assertEqual(code, 0, out)
        s = wait_for(lambda s: s["holding"] and s["mode"] == "position", what="holding in position mode")
        time.sleep(1.0)
        s = status()
        self.assertEqual(s["state"], ENABLED, s)
        self.assertEqual(s["faults"], [])
        self.assertLess(abs(s["position_m"] - down["position_m"]), 0.5e-3, "position mode did not start bumplessly")
        code, out = ctl("move", "160", "--timeout", "20")
        self.assertEqual(code, 0, out)

    def test_current_saturated_for_too_long(self):
        # The valve is seized at its null from the start (so surely before the enable); a 100 mm
        # move then saturates the PI. The following-error limit is raised out of the way so that
        # saturation is what trips.
        self.start(events=event(0.0, valve_stuck=True), max_following_error_m="0.5")
        self.assertEqual(ctl("enable")[0], 0)
        code, out = ctl("move", "250", "--timeout", "20")
        self.assertNotEqual(code, 0, out)
        self.expect_fault(FAULT_CURRENT_SATURATION, "valve command saturated for 5000 cycles (limit 5000)")
        self.expect_valve_safe()
        # The saturation streak ends with the fault: reset is accepted, and the axis holds again.
        self.reset_and_enable_again()

    def test_encoder_jump(self):
        self.start(events=event(5.0, encoder_jump_m=0.01))
        self.assertEqual(ctl("enable")[0], 0)
        # Allowed: 0.15 m/s × the time between the two samples + the 5 mm margin. The samples are
        # stamped when their cycles read them, so the gap is 100 µs (5.015 mm) when both cycles
        # were on time, longer when the second was late and shorter when the first was (a run
        # gave 5.01 mm): the speed term is there, and it is small.
        s = self.expect_fault(FAULT_ENCODER, "encoder jumped 10.00 mm between two samples (limit ")
        text = next(f["reason"] for f in s["faults"] if f["code"] == FAULT_ENCODER)
        limit_mm = float(re.search(r"limit ([0-9.]+) mm", text).group(1))
        self.assertGreater(limit_mm, 5.0, text)
        self.assertLess(limit_mm, 10.0, text)
        self.expect_valve_safe()
        # The encoder reads 10 mm more from now on; the rod can be enabled and moved again.
        self.reset_and_enable_again(move_to_mm=170)

    def test_encoder_stale(self):
        self.start(events=event(5.0, encoder_stale=True) + event(7.0, encoder_stale=False))
        self.assertEqual(ctl("enable")[0], 0)
        self.expect_fault(FAULT_ENCODER, "encoder stale: no new sample for 10 cycles (limit 10)")
        self.expect_valve_safe(rod_stops=False)  # a frozen encoder shows no velocity anyway
        self.reset_and_enable_again(move_to_mm=170)  # accepted once fresh samples return at 7 s

    def test_streak_of_rt_overruns(self):
        # From 5 s, 400 driver reads each take 500 µs: 400 consecutive overruns of the 100 µs
        # period, twice this test's streak limit.
        self.start(events=event(5.0, stall_us=500, stall_cycles=2 * OVERRUN_TEST_STREAK),
                   overrun_streak=OVERRUN_TEST_STREAK)
        self.assertEqual(ctl("enable")[0], 0)
        self.expect_fault(FAULT_OVERRUNS, f"consecutive RT overruns (limit {OVERRUN_TEST_STREAK})")
        self.expect_valve_safe()
        self.reset_and_enable_again(move_to_mm=170)

    def test_one_long_stall_gives_blind_time(self):
        # From 5 s, one driver read busy-waits 150 ms: a single overrun (no streak), but more than
        # 150 ms without control, over the example's bound of 100 ms (which this shared VM needs:
        # the lockstep test in tests/daemon/test_axis_loop.cpp pins 50 ms against 5 ms). Over it
        # by construction, not by luck: the gap runs from the stalled cycle's wake-up, before the
        # read began, to the next cycle's, after it ended. The reason carries the measured gap.
        self.start(events=event(5.0, stall_us=150000, stall_cycles=1))
        self.assertEqual(ctl("enable")[0], 0)
        s = self.expect_fault(FAULT_BLIND_TIME, "without a cycle (limit 100.0 ms)")
        text = next(f["reason"] for f in s["faults"] if f["code"] == FAULT_BLIND_TIME)
        gap_ms = float(re.search(r"blind time: ([0-9.]+) ms", text).group(1))
        self.assertGreaterEqual(gap_ms, 150.0, text)  # the stall is a lower bound of the gap
        self.expect_valve_safe()
        # The cycles run on time again: reset is accepted at once.
        self.reset_and_enable_again(move_to_mm=170)

    def test_driver_error_is_recovered_by_reset(self):
        # The sim plugin's read() and write() fail from 12 s on for 3 s, as a bus that stopped
        # answering for a while. The RT thread then skips the driver; `hsactl reset` recovers it on
        # hsad's operator thread (on_error, on_configure with the same settings, on_activate) and
        # only then resets. A reset before the bus is back is refused (the driver fails again on
        # its first read), so the operator tries until one succeeds.
        self.start(events=event(12.0, driver_error=True, driver_error_s=3.0))
        self.assertEqual(ctl("enable")[0], 0)
        code, out = ctl("move", "170", "--tolerance", "0.1", "--timeout", "20")
        self.assertEqual(code, 0, out)
        self.expect_fault(FAULT_DRIVER, "driver error")
        # What the loop writes is read back; the rig itself is no longer read or written (the
        # driver is in its error state), so its velocity says nothing.
        self.expect_valve_safe(rod_stops=False)
        # Enable is refused while the fault is latched.
        code, out = ctl("enable")
        self.assertNotEqual(code, 0, out)
        # Resets until the bus is back: the one that succeeds clears the fault.
        wait_for(lambda s: ctl("reset")[0] == 0, what="a reset to succeed once the bus is back")
        s = status()
        self.assertEqual(s["state"], DISABLED, s)
        self.assertEqual(s["faults"], [])
        # A lost bus is not a lost rig: the recovered driver reads the rod where it was.
        s = wait_for(lambda s: s["telemetry_state"] == DISABLED, what="telemetry after the reset")
        self.assertLess(abs(s["position_m"] - 0.170), 1e-3, s)
        code, out = ctl("enable")
        self.assertEqual(code, 0, out)
        code, out = ctl("move", "190", "--tolerance", "0.1", "--timeout", "20")
        self.assertEqual(code, 0, out)
        s = status()
        self.assertEqual(s["state"], ENABLED, s)
        self.assertEqual(s["faults"], [])
        self.assertLess(abs(s["position_m"] - 0.190), 0.1e-3, s)
        code, err = self.daemon.stop()
        del self.daemon
        self.assertEqual(code, 0, err)
        self.assertIn("driver 'rig' recovered", err)

    def test_driver_that_stays_down_keeps_the_fault_and_reset_says_why(self):
        # The sim plugin's bus fails on its first read and never comes back: every recovery
        # configures, then fails again on its first read. Nothing was ever read, so the e-stop
        # input is not ok either, but the fault keeps its first cause: the driver error.
        self.daemon = Daemon(config_with(events=event(0.0, driver_error=True), overrun_streak=NOISE_OVERRUN_STREAK))
        first = self.expect_fault(FAULT_DRIVER, "driver error ('rig': read failed)")
        # Each reset recovers the driver, sees it fail again at once and is refused with that
        # reason, said once; the fault and its text stay and the next reset tries again.
        for attempt in range(2):
            code, out = ctl("reset")
            self.assertNotEqual(code, 0, out)
            self.assertIn("reset refused: driver 'rig' failed again right after its recovery ('rig': read failed)", out)
            self.assertNotIn("reset refused: reset refused", out)
            s = status()
            self.assertEqual(s["state"], FAULT)
            self.assertEqual(s["faults"], first["faults"])
        code, err = self.daemon.stop()
        del self.daemon
        self.assertEqual(code, 0, err)
        self.assertEqual(err.count("driver 'rig' recovered"), 2, err)

    def test_a_position_no_longer_read_is_shown_stale_with_a_growing_age(self):
        # The sim plugin's bus fails at 5 s and stays down: hsad no longer reads it, and the rod's
        # last position stays in status and telemetry. Before, the position is live; after, status
        # (text and JSON) and telemetry mark it stale, with an age that grows as time passes.
        self.start(events=event(5.0, driver_error=True))
        s = status()
        self.assertFalse(s["status_position_stale"], s)
        self.assertFalse(s["inputs"]["position"]["stale"], s)
        self.expect_fault(FAULT_DRIVER, "driver error")
        wait_for(lambda s: s["status_position_stale"], what="the rod's position marked stale")
        code, out = ctl("status")
        self.assertEqual(code, 0, out)
        self.assertRegex(out, r"rod [0-9.]+ mm \(STALE, [0-9.]+ m?s old\)")
        self.assertRegex(out, r"inputs \(telemetry\): position STALE, ")

        def timed_status():
            began = time.monotonic()
            s = status()
            return s, began, time.monotonic()

        first, start1, end1 = timed_status()
        time.sleep(1.0)
        second, start2, end2 = timed_status()
        for s in (first, second):
            self.assertTrue(s["status_position_stale"], s)
            self.assertTrue(s["inputs"]["position"]["stale"], s)
            self.assertTrue(s["inputs"]["pressure_a"]["stale"], s)
        self.assertEqual(second["status_position_m"], first["status_position_m"])  # frozen
        # Each status was sent while its own hsactl ran, so they lie between start2 - end1 and
        # end2 - start1 apart; the age also counts from a telemetry sample (1 ms apart at 1 kHz).
        grown = second["status_position_age_s"] - first["status_position_age_s"]
        print(f"\n    position age {first['status_position_age_s']:.3f} s -> {second['status_position_age_s']:.3f} s "
              f"(+{grown:.3f} s; hsactl runs {start2 - end1:.3f} to {end2 - start1:.3f} s apart)", end=" ",
              file=sys.stderr)
        self.assertGreaterEqual(grown, start2 - end1 - 0.002, (first, second))
        self.assertLessEqual(grown, end2 - start1 + 0.002, (first, second))
        code, out = ctl("watch", "--duration", "0.5")
        self.assertEqual(code, 0, out)
        self.assertIn("position STALE, ", out)

    def test_proportional_valve_spool_reads_back_its_fail_safe_rest(self):
        # With the proportional valve the safe state is visible on the rig: enable off takes the
        # solenoid current to 0 and the spring parks the spool in its fail-safe zone, which the
        # spool LVDT reports; enabled, the valve loop holds the spool near hydraulic zero.
        self.start(base=PROPORTIONAL_CONFIG, events=event(5.0, encoder_jump_m=0.01))
        self.assertEqual(ctl("enable")[0], 0)
        s = wait_for(lambda s: s["state"] == ENABLED and abs(s["spool_position_m"]) < 0.5e-3,
                     what="the spool near its null while enabled")
        # The jump between the two samples is the 10 mm step plus what the rod moved in between,
        # which a late cycle stretches: a holding rod needs 2.5 ms even at the axis's 0.2 m/s speed
        # bound to add 0.5 mm.
        s = self.expect_fault(FAULT_ENCODER, "encoder jumped 10.")
        jump_mm = float(re.search(r"encoder jumped ([0-9.]+) mm", s["faults"][0]["reason"]).group(1))
        self.assertGreaterEqual(jump_mm, 10.0, s)
        self.assertLess(jump_mm, 10.5, s)
        with open(PROPORTIONAL_CONFIG, "rb") as f:
            safe_command = tomllib.load(f)["axes"][0]["safety"]["safe_valve_command"]
        s = self.expect_valve_safe(safe_command=safe_command, rod_stops=False)
        low, high = FAIL_SAFE_SPOOL_M
        s = wait_for(lambda s: low - 0.1e-3 <= s["spool_position_m"] <= high,
                     what="the spool in its fail-safe rest zone")
        print(f"spool {s['spool_position_m'] * 1e3:.3f} mm", end=" ", file=sys.stderr)
        self.reset_and_enable_again()
        wait_for(lambda s: abs(s["spool_position_m"]) < 0.5e-3, what="the spool back near its null")

    def test_steady_state_counters_stay_at_zero_over_ten_seconds(self):
        self.start()
        self.assertEqual(ctl("enable")[0], 0)
        code, out = ctl("sine", "10", "0.5", "--duration", "10", timeout=40)
        self.assertEqual(code, 0, out)
        s = status()
        for counter in hsad_process.RT_COUNTERS_ASSERTED:
            self.assertEqual(s["rt_" + counter], 0, f"rt_{counter} in the RT cycle: {s}")

    def test_sigterm_exits_cleanly_in_the_safe_state(self):
        self.start()
        self.assertEqual(ctl("enable")[0], 0)
        self.assertEqual(ctl("move", "160", "--timeout", "20")[0], 0)
        code, err = self.daemon.stop()
        del self.daemon
        self.assertEqual(code, 0, err)
        self.assertIn("SIGTERM: stopping", err)


class TwoAxesTest(unittest.TestCase):
    def test_two_axes_run_independently_in_one_daemon(self):
        with open(TWO_AXES_CONFIG) as f:
            text = re.sub(r"(?m)^overrun_streak\s*=.*$", f"overrun_streak = {NOISE_OVERRUN_STREAK}", f.read())
        tmp = tempfile.NamedTemporaryFile("w", suffix=".toml", delete=False)
        tmp.write(text)
        tmp.close()
        daemon = Daemon(tmp.name)
        try:
            for axis in ("left", "right"):
                wait_for(lambda s: s["state"] == DISABLED, axis=axis, what=f"{axis} DISABLED")
            # hsactl axes lists both; a wrong --axis is told which axes do answer.
            code, out = ctl("axes")
            self.assertEqual((code, out.split("\n")[:2]), (0, ["left: DISABLED", "right: DISABLED"]), out)
            code, out = ctl("--axis", "lift", "status")
            self.assertEqual(code, 2, out)
            self.assertIn("no axis 'lift'; the axes that answer: left, right (give --axis NAME)", out)
            code, out = ctl("--axis", "left", "gains")
            self.assertEqual(code, 0, out)
            self.assertRegex(out, r"^left: kp [0-9.]+ 1/m, ki [0-9.]+ 1/\(m s\); 0 changes applied, 0 refused")
            self.assertEqual(ctl("--axis", "left", "enable")[0], 0)
            # Only the enabled axis moves; the other stays disabled.
            self.assertEqual(ctl("--axis", "left", "move", "120", "--timeout", "20")[0], 0)
            self.assertEqual(status("right")["state"], DISABLED)
            self.assertEqual(ctl("--axis", "right", "enable")[0], 0)
            self.assertEqual(ctl("--axis", "right", "move", "180", "--timeout", "20")[0], 0)
            left, right = status("left"), status("right")
            self.assertLess(abs(left["position_m"] - 0.120), 0.2e-3, left)
            self.assertLess(abs(right["position_m"] - 0.180), 0.1e-3, right)
        finally:
            code, err = daemon.stop()
        self.assertEqual(code, 0, err)

    def test_each_axis_publishes_telemetry_at_its_own_rate(self):
        # The example gives "right" telemetry_rate_hz = 500 and "left" the default 1000 Hz. Both
        # streams are counted on the wire for two seconds (datagrams on each TELEMETRY channel).
        with open(TWO_AXES_CONFIG, "rb") as f:
            axes = {a["name"]: a.get("telemetry_rate_hz", 1000) for a in tomllib.load(f)["axes"]}
        self.assertNotEqual(axes["left"], axes["right"], "the example no longer has two rates")
        with open(TWO_AXES_CONFIG) as f:
            text = re.sub(r"(?m)^overrun_streak\s*=.*$", f"overrun_streak = {NOISE_OVERRUN_STREAK}", f.read())
        tmp = tempfile.NamedTemporaryFile("w", suffix=".toml", delete=False)
        tmp.write(text)
        tmp.close()
        daemon = Daemon(tmp.name)
        try:
            for axis in axes:
                wait_for(lambda s: s["state"] == DISABLED, axis=axis, what=f"{axis} DISABLED")
            counts = {axis: 0 for axis in axes}
            with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as sock:
                sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
                sock.bind(("", 7667))
                sock.setsockopt(socket.IPPROTO_IP, socket.IP_ADD_MEMBERSHIP,
                                socket.inet_aton("239.255.76.67") + socket.inet_aton("0.0.0.0"))
                sock.settimeout(1)
                start = time.monotonic()
                while time.monotonic() - start < 2.0:
                    datagram = sock.recv(65536)
                    for axis in axes:
                        counts[axis] += f"HSA/{axis}/TELEMETRY".encode() + b"\0" in datagram[:64]
        finally:
            code, err = daemon.stop()
        self.assertEqual(code, 0, err)
        print(f"telemetry in 2 s: {counts} for rates {axes}", file=sys.stderr)
        for axis, rate in axes.items():
            # Within 10 % of the configured rate over two seconds (a shared machine may drop a few).
            self.assertGreater(counts[axis], 0.9 * 2 * rate, f"{axis}: {counts}")
            self.assertLess(counts[axis], 1.1 * 2 * rate, f"{axis}: {counts}")


if __name__ == "__main__":
    links = subprocess.run(["ip", "-o", "link"], capture_output=True, text=True).stdout.splitlines()
    if len(links) != 1:
        sys.exit("test_hsad.py: refusing to run outside a private network namespace (multicast must not reach the host's network)")
    unittest.main(verbosity=2)
