"""hsad's start-up under a flood of forged LCM fragment headers.

Run by ctest inside a private network namespace (hsad opens its LCM bridge):
    python3 test_hsad_startup_flood.py HSAD HSACTL CONFIG
CONFIG is systemd/hsad-sim.toml; each start runs on a temporary copy of it.

LCM 1.3.1 reserves, for the first fragment of a fragmented message, a buffer of the size its header
claims (up to 256 MiB), and hsad locks its memory once its loops run. hsad's receive filter keeps
every fragment out of LCM's sockets; this test checks that it is there from the moment a socket can
receive, not only once the bridge is built: forged headers, each claiming 256 MiB on a channel
hsad's LCM has a handler for (its own, and LCM's self-test channel while it tests itself), are sent
without pause to the LCM group and port while hsad starts, several times. After each start, hsad's
resident and locked memory must be within a few MiB of a start without the flood, and hsad must
still answer.
"""
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time
import unittest

import hsad_process

HSAD, HSACTL, CONFIG = sys.argv[1:4]
del sys.argv[1:4]

AXIS = "lift"  # the axis of hsad-sim.toml
LCM_GROUP, LCM_PORT = "239.255.76.67", 7667  # its lcm_url
STARTS = int(os.environ.get("HSA_FLOOD_STARTS", "8"))
# Far below the 256 MiB one forged header would cost, far above a start's own variation.
BOUND_KIB = 16 * 1024

# Run as a separate process until killed: first fragments of fragmented messages ("LC03": magic,
# sequence number, claimed total size, fragment offset, fragment number, fragment count, then the
# channel and the start of the payload), each claiming 256 MiB, a new sequence number each time so
# LCM starts a new buffer for each, on the channels hsad's two LCM instances handle and on LCM's
# self-test channel, multicast on this namespace's loopback as any LAN host could send them.
FLOODER = """
import socket, struct, sys, time
group, port, channels = sys.argv[1], int(sys.argv[2]), [c.encode() for c in sys.argv[3:]]
s = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
s.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_TTL, 0)
seq = 0
print("flooding", flush=True)
while True:
    for _ in range(50):
        for channel in channels:
            seq += 1
            s.sendto(struct.pack(">IIIIHH", 0x4C433033, seq, 256 << 20, 0, 0, 4) + channel + b"\\0" + bytes(64),
                     (group, port))
    time.sleep(0.0005)
"""


def memory_kib(pid):
    """hsad's resident and locked memory (VmRSS, VmLck) in KiB."""
    with open(f"/proc/{pid}/status") as f:
        status = f.read()
    return tuple(int(re.search(rf"^{key}:\s+(\d+) kB", status, re.M).group(1)) for key in ("VmRSS", "VmLck"))


class StartupFloodTest(unittest.TestCase):
    def setUp(self):
        self.lock_dir = tempfile.mkdtemp()
        self.config = hsad_process.quiet_config_copy(CONFIG)
        self.operator = hsad_process.Operator(HSACTL, AXIS)

    def tearDown(self):
        os.unlink(self.config)
        shutil.rmtree(self.lock_dir)

    def start_and_measure(self, flood):
        """Starts hsad (with the flood on from before its start until its loops run, when `flood`)
        and returns its (VmRSS, VmLck) once the flood has stopped. hsad's own line "... running at"
        says when: hsactl is not used during the flood, since its LCM would read the flood too."""
        flooder = None
        if flood:
            flooder = subprocess.Popen(["/usr/bin/python3", "-c", FLOODER, LCM_GROUP, str(LCM_PORT),
                                        f"HSA/{AXIS}/SETPOINT", f"HSA/{AXIS}/COMMAND", "LCM_SELF_TEST"],
                                       stdout=subprocess.PIPE, text=True)
            self.assertEqual(flooder.stdout.readline().strip(), "flooding")
        log = tempfile.TemporaryFile("w+")
        d = subprocess.Popen([HSAD, "--config", self.config, "--duration", "60", "--lock-dir", self.lock_dir,
                              "--key-dir", hsad_process.KEY_DIR],
                             stdout=subprocess.DEVNULL, stderr=log, text=True)
        try:
            deadline = time.monotonic() + 30
            while "running at" not in self.log_text(log):
                self.assertIsNone(d.poll(), f"hsad ended during start-up: {self.log_text(log)}")
                self.assertLess(time.monotonic(), deadline, "hsad did not start within 30 s")
                time.sleep(0.05)
            if flooder:
                flooder.kill()
                flooder.wait(timeout=10)
                flooder.stdout.close()
                flooder = None
            time.sleep(0.5)  # not a timing assertion: lets what the LCM threads still hold show
            memory = memory_kib(d.pid)
            # Still answering after the flood: the status of a live LCM thread.
            self.operator.wait_for(lambda s: s["state"] == "DISABLED", what="the axis to answer DISABLED")
            return memory
        finally:
            if flooder:
                flooder.kill()
                flooder.wait(timeout=10)
                flooder.stdout.close()
            d.terminate()
            d.wait(timeout=20)
            err = self.log_text(log)
            log.close()
            self.assertEqual(d.returncode, 0, err)

    @staticmethod
    def log_text(log):
        log.seek(0)
        return log.read()

    def test_forged_fragments_during_start_up_cost_no_memory(self):
        quiet_rss, quiet_lck = self.start_and_measure(flood=False)
        flooded = [self.start_and_measure(flood=True) for _ in range(STARTS)]
        print(f"without the flood: VmRSS {quiet_rss} KiB, VmLck {quiet_lck} KiB; with it, per start (KiB): " +
              ", ".join(f"{rss}/{lck}" for rss, lck in flooded), file=sys.stderr)
        grown = [i for i, (rss, lck) in enumerate(flooded)
                 if rss > quiet_rss + BOUND_KIB or lck > quiet_lck + BOUND_KIB]
        self.assertEqual(grown, [], f"forged fragments sent during start-up grew hsad in {len(grown)} of "
                                    f"{STARTS} starts")


if __name__ == "__main__":
    unittest.main(verbosity=2)
