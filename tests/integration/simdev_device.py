"""hsa-simdev as the integration tests use it: the simulated device on a free loopback port, and
an independent Modbus TCP client that reads what the device holds.

The client is this test's own, a few lines over a socket, not the modbus plugin under test, and it
only reads: reads do not feed the device's communication watchdog, so it can watch a dead master's
outputs without keeping them alive. The one write here, refuse_valve_command, is a test hook's
coil, which the device takes from any connection and which is no output of the master's. Addresses are tools/hsa_simdev/register_map.hpp's. Every call
is bounded by a 2 s socket timeout.
"""
import random
import select
import socket
import struct
import subprocess
import time

# tools/hsa_simdev/register_map.hpp
HR_VALVE_COMMAND, HR_MASTER_HEARTBEAT = 0, 2
COIL_VALVE_ENABLE = 0
COIL_REFUSE_VALVE_COMMAND = 9
IR_WATCHDOG_TRIPPED = 40
IR_REFUSED_COMMAND_WRITES = 45
# Between two polls of a watch: fine enough to time a 5 ms output timeout, and leaves the CPU to
# the threads being watched.
POLL_S = 0.001


def free_port():
    """A free loopback port below the ephemeral range: the device must come back on the same
    port, and a port in the ephemeral range could meanwhile become some connect()'s source port."""
    with open("/proc/sys/net/ipv4/ip_local_port_range") as f:
        ephemeral_low = int(f.read().split()[0])
    for _ in range(200):
        port = random.randrange(10000, max(11000, ephemeral_low))
        with socket.socket() as s:
            try:
                s.bind(("127.0.0.1", port))
                return port
            except OSError:
                continue
    raise RuntimeError("no free loopback port in 200 attempts")


class Simdev:
    """hsa-simdev on `port`, bounded to two minutes whatever happens to the test."""

    def __init__(self, simdev, port, initial_position_m, *args, prefix=()):
        self.proc = subprocess.Popen([*prefix, simdev, "--port", str(port), "--duration", "120",
                                      "--initial-position-m", f"{initial_position_m:.6f}", *args],
                                     stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        # It prints one line once it listens, or exits; bounded in case it does neither.
        ready, _, _ = select.select([self.proc.stdout], [], [], 20)
        line = self.proc.stdout.readline() if ready else ""
        if f"listening on 127.0.0.1:{port}" not in line:
            self.proc.kill()
            _, err = self.proc.communicate(timeout=10)
            raise AssertionError(f"hsa-simdev did not come up on port {port}: {line!r} {err!r}")

    def kill(self):
        """SIGKILL: the device vanishes mid-transaction, no goodbye on the socket."""
        if self.proc.poll() is None:
            self.proc.kill()
        self.proc.communicate(timeout=10)


class DeviceClient:
    """A read-only Modbus TCP client of one device, on one connection."""

    def __init__(self, port):
        self.sock = socket.create_connection(("127.0.0.1", port), timeout=2)
        self.transaction = 0

    def close(self):
        self.sock.close()

    def _request(self, function, address, count, reply_bytes):
        self.transaction = (self.transaction + 1) & 0xFFFF
        self.sock.sendall(struct.pack(">HHHBBHH", self.transaction, 0, 6, 1, function, address, count))
        want = 9 + reply_bytes
        reply = b""
        while len(reply) < want:
            chunk = self.sock.recv(want - len(reply))
            if not chunk:
                raise AssertionError(f"the device closed the connection: {reply!r}")
            reply += chunk
        transaction, _, _, _, fn, n = struct.unpack(">HHHBBB", reply[:9])
        assert (transaction, fn, n) == (self.transaction, function, reply_bytes), f"unexpected reply {reply!r}"
        return reply[9:]

    def input_registers(self, address, count):
        return struct.unpack(f">{count}H", self._request(4, address, count, 2 * count))

    def holding_registers(self, address, count):
        return struct.unpack(f">{count}H", self._request(3, address, count, 2 * count))

    def coil(self, address):
        return self._request(1, address, 1, 1)[0] & 1

    def valve(self):
        """(valve command, enable, master heartbeat) as the device holds them."""
        hi, lo, heartbeat = self.holding_registers(HR_VALVE_COMMAND, 3)
        command = struct.unpack(">f", struct.pack(">HH", hi, lo))[0]
        return command, self.coil(COIL_VALVE_ENABLE), heartbeat


def refuse_valve_command(port, refuse):
    """hsa-simdev's coil 9, written on a connection of its own (function 05): while set, the
    device refuses the master's writes to the valve command with exception 03."""
    value = 0xFF00 if refuse else 0x0000
    request = struct.pack(">HHHBBHH", 1, 0, 6, 1, 5, COIL_REFUSE_VALVE_COMMAND, value)
    with socket.create_connection(("127.0.0.1", port), timeout=2) as sock:
        sock.sendall(request)
        reply = b""
        while len(reply) < len(request):
            chunk = sock.recv(len(request) - len(reply))
            if not chunk:
                break
            reply += chunk
    # A write single coil is answered with its own echo; anything else (an exception) is a failure.
    assert reply == request, f"the device did not take coil {COIL_REFUSE_VALVE_COMMAND} = {int(refuse)}: {reply!r}"


def read_watchdog(port):
    """hsa-simdev's input registers 40-41: (watchdog tripped, trips since start)."""
    client = DeviceClient(port)
    try:
        return client.input_registers(IR_WATCHDOG_TRIPPED, 2)
    finally:
        client.close()


def wait_until_safe(client, safe_command, timeout_s=5.0):
    """Polls the device every POLL_S until its valve command is `safe_command` and its enable off;
    returns the time.monotonic() of the first read that showed it, or None."""
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        command, enable, _ = client.valve()
        if command == safe_command and enable == 0:
            return time.monotonic()
        time.sleep(POLL_S)
    return None
