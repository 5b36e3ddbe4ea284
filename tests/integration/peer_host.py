"""Another host on the LAN, for the tests that treat the network as hostile: a second network
namespace joined to the test's own by a veth pair, with nothing else shared.

    with PeerHost() as peer:
        peer.run(["/usr/bin/python3", "-c", "..."])   # runs in the peer's namespace

This namespace's end is HOST_ADDR, the peer's PEER_ADDR (a /24 of their own). The peer's namespace
lives as long as a `sleep` that holds it; nsenter runs commands in it. Needs root (the tests run in
a private namespace made by unshare -n, as root). Every wait is bounded.
"""
import os
import subprocess
import time

HOST_ADDR = "10.77.0.1"
PEER_ADDR = "10.77.0.2"


def _ip(*args, ns_pid=None):
    prefix = ["nsenter", "-t", str(ns_pid), "-n"] if ns_pid else []
    subprocess.run([*prefix, "ip", *args], check=True, capture_output=True, timeout=10)


class PeerHost:
    def __enter__(self):
        self.holder = subprocess.Popen(["unshare", "-n", "sleep", "600"])
        own = os.readlink("/proc/self/ns/net")
        deadline = time.monotonic() + 10
        while os.readlink(f"/proc/{self.holder.pid}/ns/net") == own:
            if time.monotonic() > deadline:
                self.holder.kill()
                raise AssertionError("the peer's network namespace did not appear within 10 s")
            time.sleep(0.01)
        pid = self.holder.pid
        _ip("link", "add", "hsa-host", "type", "veth", "peer", "name", "hsa-peer", "netns", str(pid))
        _ip("addr", "add", f"{HOST_ADDR}/24", "dev", "hsa-host")
        _ip("link", "set", "hsa-host", "up")
        _ip("link", "set", "lo", "up", ns_pid=pid)
        _ip("addr", "add", f"{PEER_ADDR}/24", "dev", "hsa-peer", ns_pid=pid)
        _ip("link", "set", "hsa-peer", "up", ns_pid=pid)
        return self

    def run(self, argv, timeout=30):
        """Runs argv in the peer's namespace; returns the CompletedProcess (output captured)."""
        return subprocess.run(["nsenter", "-t", str(self.holder.pid), "-n", *argv], capture_output=True,
                              text=True, timeout=timeout)

    def __exit__(self, *exc):
        self.holder.kill()  # the namespace, and the veth pair with it, go with its last process
        self.holder.wait(timeout=10)
