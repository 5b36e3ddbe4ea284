"""End to end through the real Modbus path: hsad with the `modbus` plugin against hsa-simdev (the
simulated rig served over Modbus TCP on 127.0.0.1), driven with the real hsactl.

Run by ctest inside a private network namespace (LCM multicast never reaches the host network):
    python3 test_hsad_modbus.py HSAD HSACTL HSA_SIMDEV CONFIG
CONFIG is the shipped systemd/hsad-modbus-simdev.toml. Each test runs a temporary copy of it with
only the port replaced by a free one (hsad has no option to override it), so the example is what
is tested. Every wait is bounded and polls a condition with a generous timeout; nothing asserts
timing.

What is checked:
  - the position loop closes over the bus and reaches its setpoint;
  - killing hsa-simdev mid-run makes the inputs stale and latches a fault whose reason says so;
    restarting it on the same port, the plugin reconnects, `hsactl reset` clears the fault, and
    the loop reaches a new setpoint in the same daemon process, its counters intact;
  - with no device listening, hsad refuses to start and names the link and the reason;
  - a device that refuses every write mid-run (exception 3, from a proxy in front of hsa-simdev)
    latches a driver-error fault whose reason says "write failed" with the exception; a reset while
    it still refuses is refused once, naming that cause, and changes neither the state nor the
    fault's text; the device itself is safe meanwhile (its watchdog, fed by no accepted write,
    tripped); once the device accepts writes again a reset clears the fault;
  - a device that stops answering (hsa-simdev SIGSTOPped: its socket still takes connections)
    latches a fault that says "not answering", distinct from a link that is down; the link never
    reads up meanwhile and the timeouts are counted; once it runs again, a reset clears the fault;
  - a device that refuses the valve command mid-run (hsa-simdev's coil 9: exception 03) latches a
    FAULT whose reason is the driver's write failure, with the exception and the registers; the
    plugin still switches the valve's enable off at the device; `hsactl reset` while it still
    refuses is refused with that standing cause, said once, and the fault text stays; once the
    device takes the command again, a reset clears the fault and the loop runs again;
  - hsad stopped (SIGSTOP) while the axis is enabled: hsa-simdev's communication watchdog trips
    and latches the valve safe (read from its registers by a client of this test that only
    reads); once hsad runs again, the operator's disable (or reset) and enable clear the latch,
    and the loop reaches a new setpoint.
"""
import os
import re
import signal
import subprocess
import time
import sys
import tempfile
import unittest

import hsad_process
import simdev_device
from refusing_modbus_proxy import RefusingProxy
from simdev_device import free_port, read_watchdog, refuse_valve_command

HSAD, HSACTL, SIMDEV, CONFIG = sys.argv[1:5]
del sys.argv[1:5]

AXIS = "x"  # the axis of hsad-modbus-simdev.toml
ENABLED, DISABLED, FAULT, ESTOP = "ENABLED", "DISABLED", "FAULT", "ESTOP"
FAULT_SENSOR, FAULT_ENCODER, FAULT_DRIVER, FAULT_ESTOP, FAULT_INPUTS_NOT_READY = 1, 2, 8, 9, 12  # status_t.FAULT_*


def config_for(port, drop_estop=False, estop_address=None):
    """A temporary copy of the shipped configuration with the driver's port replaced; with
    drop_estop, without the axis's e-stop signal (an e-stop wired elsewhere, not over Modbus);
    with estop_address, the e-stop channel read from that discrete input instead."""
    with open(CONFIG) as f:
        text = f.read()
    text, n = re.subn(r"(?m)^port\s*=\s*\d+", f"port = {port}", text, count=1)
    assert n == 1, f"no `port = ...` line in {CONFIG}"
    if estop_address is not None:
        text, n = re.subn(r'(?m)(^name = "estop"\n(?:.*\n)*?^address = )\d+', rf"\g<1>{estop_address}", text, count=1)
        assert n == 1, f"no e-stop channel address in {CONFIG}"
    if drop_estop:
        text, n = re.subn(r"(?ms)^\[axes\.signals\.estop\]\n.*?(?=^\[)", "", text, count=1)
        assert n == 1, f"no [axes.signals.estop] table in {CONFIG}"
    f = tempfile.NamedTemporaryFile("w", suffix=".toml", prefix="hsad-modbus-", delete=False)
    f.write(text)
    f.close()
    return f.name


def Simdev(port, initial_position_m):
    return simdev_device.Simdev(SIMDEV, port, initial_position_m)


def Daemon(config):
    return hsad_process.Daemon(HSAD, config, duration_s=110)


_operator = hsad_process.Operator(HSACTL, axis=AXIS, timeout=40)
ctl, status, wait_for = _operator.ctl, _operator.status, _operator.wait_for


class HsadModbusTest(unittest.TestCase):
    def setUp(self):
        self.port = free_port()
        self.simdev = None
        self.daemon = None

    def tearDown(self):
        if self.daemon is not None:
            self.daemon.stop()
        if self.simdev is not None:
            self.simdev.kill()

    def start(self, drop_estop=False):
        # The rod starts at 100 mm, so the first move has somewhere to go.
        self.simdev = Simdev(self.port, 0.100)
        self.daemon = Daemon(config_for(self.port, drop_estop))
        wait_for(lambda s: s["state"] == DISABLED, what="the axis to come up DISABLED")

    def move(self, mm):
        code, out = ctl("move", str(mm), "--tolerance", "0.1", "--timeout", "20")
        self.assertEqual(code, 0, out)
        s = status()
        self.assertEqual(s["state"], ENABLED, s)
        self.assertLess(abs(s["position_m"] - mm * 1e-3), 0.1e-3, s)
        return s

    def lose_and_recover_the_device(self, states, codes, reason):
        self.assertEqual(ctl("enable")[0], 0)
        before = self.move(150)

        # The device dies mid-run: no new samples, the inputs age past max_age_s and read stale.
        self.simdev.kill()
        s = wait_for(lambda s: s["state"] in states, what=f"{' or '.join(states)} after the device died")
        self.assertEqual(len(s["faults"]), 1, s)
        self.assertIn(s["faults"][0]["code"], codes, s)
        self.assertRegex(s["faults"][0]["reason"], reason, s)
        # The reason names the bus and why it is silent, and hsactl drivers shows the link down.
        link_down = f"(driver 'io' link down: Modbus TCP 127.0.0.1:{self.port}: "
        s = wait_for(lambda s: link_down in s["faults"][0]["reason"], what="the fault to name the dead link")
        self.assertEqual(s["drivers"][0]["link"], "down", s)
        self.assertGreater(s["drivers"][0]["counters"]["link_errors"], 0, s)
        code, out = ctl("drivers")
        self.assertEqual(code, 0, out)
        self.assertIn("io (modbus): active, LINK DOWN; link_errors", out)
        self.assertIn(f"last error: Modbus TCP 127.0.0.1:{self.port}: ", out)
        # Latched: while the device is gone, reset is refused and names the cause.
        refused, out = ctl("reset")
        self.assertNotEqual(refused, 0, out)
        self.assertRegex(out, reason)

        # The device comes back on the same port, its rod where the old one was (a remote-I/O
        # module rebooting does not move the cylinder). The plugin reconnects with backoff; only
        # then do the inputs turn fresh and a reset go through.
        self.simdev = Simdev(self.port, s["position_m"])
        wait_for(lambda s: ctl("reset")[0] == 0, timeout=30, what="reset to succeed after the reconnect")
        s = wait_for(lambda s: s["state"] == DISABLED, what="DISABLED after the reset")
        self.assertEqual(s["faults"], [])

        # Nothing lost but the fault: the same daemon runs the loop to a new setpoint, its
        # counters carried on, and the RT cycle still clean.
        self.assertTrue(self.daemon.running())
        self.assertEqual(ctl("enable")[0], 0)
        after = self.move(120)
        self.assertGreater(after["commands_accepted"], before["commands_accepted"])
        for counter in hsad_process.RT_COUNTERS_ASSERTED:
            self.assertEqual(after["rt_" + counter], 0, f"rt_{counter} in the RT cycle: {after}")
        code, err = self.daemon.stop()
        self.daemon = None
        self.assertEqual(code, 0, err)

    def test_loop_closes_over_modbus_and_reaches_its_setpoint(self):
        self.start()
        self.assertEqual(ctl("enable")[0], 0)
        self.move(150)
        self.move(200)

    def test_lost_device_gives_estop_then_reconnects_and_resets(self):
        # The shipped configuration reads the e-stop loop over the same bus: a dead device leaves
        # it unreadable, which the supervisor takes as pressed. Every input of the bus ages at
        # once, so which the supervisor finds stale first is a race: the e-stop (ESTOP) or a
        # sensor (FAULT, whose first cause a later e-stop no longer replaces). Either names it.
        self.start()
        self.lose_and_recover_the_device((ESTOP, FAULT), [FAULT_ESTOP, FAULT_SENSOR, FAULT_ENCODER],
                                         r"e-stop input stale|(position|pressure [AB]) (sample stale|stale: no new sample)|encoder stale")

    def test_lost_device_gives_a_sensor_fault_then_reconnects_and_resets(self):
        # With the e-stop wired elsewhere, the same loss is a sensor fault: the position sample
        # turns stale after max_age_s. The supervisor's own checks (cycles without a new encoder
        # sample, time without a new timestamp on any input) have the same limit in time and may
        # see it first; each names the signal.
        self.start(drop_estop=True)
        self.lose_and_recover_the_device((FAULT,), [FAULT_SENSOR, FAULT_ENCODER],
                                         r"(position|pressure [AB]) (sample stale|stale: no new sample)|encoder stale")

    def test_a_device_that_refuses_writes_keeps_its_fault_through_a_refused_reset(self):
        device_port = free_port()
        proxy = RefusingProxy(self.port, device_port)
        try:
            self.simdev = Simdev(device_port, 0.100)
            self.daemon = Daemon(config_for(self.port))
            wait_for(lambda s: s["state"] == DISABLED, what="the axis to come up DISABLED")
            self.assertEqual(ctl("enable")[0], 0)
            self.move(150)

            proxy.refuse_writes.set()
            s = wait_for(lambda s: s["state"] == FAULT, what="FAULT after the device refused a write")
            self.assertEqual(len(s["faults"]), 1, s)
            fault = s["faults"][0]
            self.assertRegex(fault["reason"], r"^driver error .*write failed: Modbus exception 3 "
                             r"\(Illegal data value\) writing (coils|holding registers) \d+\.\.\d+", s)
            self.assertNotIn("read failed", fault["reason"], s)
            # Safety at the device: no write reaches it, so its own watchdog made the valve safe.
            deadline = time.monotonic() + 5
            while read_watchdog(device_port)[0] != 1 and time.monotonic() < deadline:
                time.sleep(0.01)
            self.assertEqual(read_watchdog(device_port)[0], 1, "the device's valve is not safe")

            # The cause persists: the reset is refused, said once, naming it; nothing changes.
            for _ in range(2):
                code, out = ctl("reset")
                self.assertNotEqual(code, 0, out)
                self.assertIn("reset refused", out)
                self.assertNotIn("reset refused: reset refused", out)
                self.assertIn("write failed: Modbus exception 3", out)
                s = status()
                self.assertEqual(s["state"], FAULT, s)
                self.assertEqual(s["faults"], [fault], s)
            self.assertGreater(proxy.refused, 0)

            # The device accepts writes again: a reset now clears the fault and the loop runs.
            proxy.refuse_writes.clear()
            wait_for(lambda s: ctl("reset")[0] == 0, timeout=30, what="reset once writes are accepted")
            s = wait_for(lambda s: s["state"] == DISABLED, what="DISABLED after the reset")
            self.assertEqual(s["faults"], [], s)
            self.assertEqual(ctl("disable")[0], 0)  # the master's enable-off clears the device's latch
            self.assertEqual(ctl("enable")[0], 0)
            self.move(120)
            code, err = self.daemon.stop()
            self.daemon = None
            self.assertEqual(code, 0, err)
        finally:
            if self.daemon is not None:
                self.daemon.stop()
                self.daemon = None
            proxy.close()

    def test_a_device_that_stops_answering_is_reported_not_answering(self):
        self.start()
        os.kill(self.simdev.proc.pid, signal.SIGSTOP)
        try:
            # Which input the supervisor finds stale first is a race (as with a dead device): the
            # e-stop (ESTOP) or a sensor (FAULT). Either names the silent device.
            s = wait_for(lambda s: s["state"] in (ESTOP, FAULT), what="a fault after the device stopped answering")
            not_answering = f"(driver 'io' not answering: Modbus TCP 127.0.0.1:{self.port}: Connection timed out"
            s = wait_for(lambda s: not_answering in s["faults"][0]["reason"],
                         what="the fault to say the device does not answer")
            self.assertRegex(s["faults"][0]["reason"], r"^(e-stop input|position|pressure [AB]|encoder) ", s)
            self.assertNotIn("link down", s["faults"][0]["reason"], s)
            # The kernel still takes the plugin's reconnects: the link must not read up meanwhile.
            for _ in range(5):
                d = status()["drivers"][0]
                self.assertEqual(d["link"], "not answering", d)
                time.sleep(0.1)
            self.assertGreater(d["counters"]["timeouts"], 0, d)
            code, out = ctl("drivers")
            self.assertEqual(code, 0, out)
            self.assertIn("io (modbus): active, NOT ANSWERING; link_errors", out)
        finally:
            os.kill(self.simdev.proc.pid, signal.SIGCONT)
        wait_for(lambda s: ctl("reset")[0] == 0, timeout=30, what="reset once the device answers again")
        s = wait_for(lambda s: s["state"] == DISABLED, what="DISABLED after the reset")
        self.assertEqual(s["drivers"][0]["link"], "up", s)

    def test_an_input_the_device_refuses_at_start_up_names_the_exception(self):
        # hsa-simdev has two discrete inputs: reading the 100th answers exception 2. The link is
        # up and the device answers, so the start-up fault says what it answered, not that the
        # input is disconnected.
        self.simdev = Simdev(self.port, 0.100)
        self.daemon = Daemon(config_for(self.port, estop_address=100))
        s = wait_for(lambda s: s["state"] == FAULT, what="FAULT after the start-up timeout")
        self.assertEqual(s["faults"][0]["code"], FAULT_INPUTS_NOT_READY, s)
        self.assertEqual(s["faults"][0]["reason"],
                         "no first sample from e-stop within 2.0 s of start-up (driver 'io': Modbus TCP "
                         f"127.0.0.1:{self.port}: Modbus exception 2 (Illegal data address) reading discrete "
                         "inputs 100..100)", s)
        self.assertEqual(s["drivers"][0]["link"], "up", s)

    def test_a_device_that_refuses_the_command_faults_and_reset_names_the_standing_cause(self):
        self.start()
        self.assertEqual(ctl("enable")[0], 0)
        before = self.move(150)

        # Mid-run the device starts refusing the valve command (exception 03), as a device does a
        # value it will not take. The link stays up and every input stays fresh: the only cause
        # is the refused write, and the fault must say so, not blame an input.
        refuse_valve_command(self.port, True)
        refusal = (f"write failed: Modbus exception 3 (Illegal data value) writing holding registers 0..1 of "
                   f"Modbus TCP 127.0.0.1:{self.port}")
        first = wait_for(lambda s: s["state"] != ENABLED, what="the axis to leave ENABLED after the refusal")
        self.assertEqual(first["state"], FAULT, first)
        self.assertEqual(first["faults"], [{"code": FAULT_DRIVER, "reason": f"driver error ('io': {refusal})"}], first)
        self.assertEqual(first["drivers"][0]["link"], "up", first)

        # Safe at the device: the plugin's make_safe still writes the enable coil, which the device
        # takes, while its command writes are refused. The watchdog has not tripped, so the enable
        # is off because hsad switched it off, not because hsad went silent.
        client = simdev_device.DeviceClient(self.port)
        try:
            deadline = time.monotonic() + 5
            while client.valve()[1] != 0 and time.monotonic() < deadline:
                time.sleep(0.01)
            command, enable, _ = client.valve()
            self.assertEqual(enable, 0, "the valve is still enabled at the device while the axis is faulted")
            self.assertEqual(read_watchdog(self.port)[0], 0, "the device's watchdog made it safe, not hsad")
            self.assertGreater(client.input_registers(simdev_device.IR_REFUSED_COMMAND_WRITES, 1)[0], 0)
        finally:
            client.close()
        code, text = ctl("status")
        self.assertEqual(code, 0, text)
        self.assertIn(refusal, text)

        # While the device still refuses, each reset recovers the driver, whose activation fails on
        # the same refusal: refused, naming it once, and the fault and its text are left as they were.
        for attempt in range(2):
            code, out = ctl("reset")
            self.assertNotEqual(code, 0, out)
            self.assertNotIn("reset refused: reset refused", out)
            self.assertEqual(out.count("reset refused:"), 1, out)
            refused_line = next(line for line in out.splitlines() if "reset refused:" in line)
            self.assertIn(refusal, refused_line, out)
            self.assertEqual(refused_line.count("Modbus exception 3"), 1, out)
            if attempt == 0:
                print(f"\n    fault: {first['faults'][0]['reason']!r}\n    hsactl reset: {out!r}", file=sys.stderr)
            s = status()
            self.assertEqual(s["state"], FAULT, s)
            self.assertEqual(s["faults"], first["faults"], s)
            code, after = ctl("status")
            self.assertEqual(code, 0, after)
            self.assertIn(refusal, after)

        # The device takes the command again: a reset goes through (retried while the recovered
        # driver's inputs are still coming back, as after a reconnect) and the loop runs again.
        refuse_valve_command(self.port, False)
        wait_for(lambda s: ctl("reset")[0] == 0, timeout=30, what="reset once the device takes the command")
        s = wait_for(lambda s: s["state"] == DISABLED, what="DISABLED after the reset")
        self.assertEqual(s["faults"], [])
        self.assertEqual(ctl("enable")[0], 0)
        after = self.move(120)
        self.assertGreater(after["commands_accepted"], before["commands_accepted"])
        code, err = self.daemon.stop()
        self.daemon = None
        self.assertEqual(code, 0, err)

    def test_stopped_daemon_trips_the_device_watchdog_and_the_operator_clears_it(self):
        self.start()
        self.assertEqual(read_watchdog(self.port), (0, 0))
        self.assertEqual(ctl("enable")[0], 0)
        before = self.move(150)
        self.assertEqual(read_watchdog(self.port), (0, 0), "tripped while hsad was running")

        # hsad stopped: nothing on the PC can act. The device makes the valve safe by itself.
        os.kill(self.daemon.proc.pid, signal.SIGSTOP)
        try:
            deadline = time.monotonic() + 10
            while read_watchdog(self.port) != (1, 1) and time.monotonic() < deadline:
                time.sleep(0.01)
            self.assertEqual(read_watchdog(self.port), (1, 1), "the device's watchdog did not trip")
        finally:
            os.kill(self.daemon.proc.pid, signal.SIGCONT)
        # hsad runs again. Still ENABLED (it was so throughout, since only a reset leaves a
        # fault), it writes the enable on, which does not clear the latch.
        time.sleep(0.3)
        latched = read_watchdog(self.port)[0]
        s = status()
        print(f"after SIGCONT: hsad {s['state']}, device latch {latched}", file=sys.stderr)
        if s["state"] == ENABLED:
            self.assertEqual(latched, 1, "hsad's enable-on writes cleared the latch")

        # The operator's disable (or reset, if hsad latched a fault meanwhile) then enable: the
        # plugin writes the enable off, then on, which clears the latch.
        if s["state"] == ENABLED:
            self.assertEqual(ctl("disable")[0], 0)
        else:
            wait_for(lambda s: ctl("reset")[0] == 0, timeout=30, what="reset after SIGCONT")
        wait_for(lambda s: s["state"] == DISABLED, what="DISABLED before re-enabling")
        wait_for(lambda s: read_watchdog(self.port)[0] == 0, what="the latch to clear")
        self.assertEqual(ctl("enable")[0], 0)
        after = self.move(120)
        self.assertGreater(after["commands_accepted"], before["commands_accepted"])
        self.assertEqual(read_watchdog(self.port), (0, 1))

    def test_no_device_at_start_is_refused_with_the_link_and_reason(self):
        config = config_for(self.port)
        try:
            r = subprocess.run([HSAD, "--config", config, "--duration", "5", "--key-dir", hsad_process.KEY_DIR],
                               capture_output=True, text=True, timeout=60)
        finally:
            os.unlink(config)
        self.assertNotEqual(r.returncode, 0, r.stderr)
        self.assertIn(f"127.0.0.1:{self.port}", r.stderr)
        self.assertIn("refused", r.stderr.lower())

    def test_shipped_configuration_is_valid(self):
        r = subprocess.run([HSAD, "--check-config", CONFIG, "--key-dir", hsad_process.KEY_DIR], capture_output=True,
                           text=True, timeout=30)
        self.assertEqual(r.returncode, 0, r.stdout + r.stderr)


if __name__ == "__main__":
    links = subprocess.run(["ip", "-o", "link"], capture_output=True, text=True).stdout.splitlines()
    if len(links) != 1:
        sys.exit("test_hsad_modbus.py: refusing to run outside a private network namespace (multicast must not reach the host's network)")
    unittest.main(verbosity=2)
