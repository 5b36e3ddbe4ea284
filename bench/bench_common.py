"""Helpers shared by the bench/ scripts (latency-compare, setpoint-latency, throughput, run-all).

Python's standard library only. Every script that starts hsad re-executes itself once inside a
private network namespace (loopback only, multicast routed to it), so the daemon's LCM multicast
never leaves the machine and every process it starts (hsad, hsactl, the LCM clients) shares that
namespace. That needs root (or CAP_SYS_ADMIN), as do SCHED_FIFO, mlockall and cyclictest.
"""

import os
import re
import subprocess
import sys
import time
import tomllib

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
NETNS_ENV = "HSA_BENCH_IN_NETNS"


def default_build_dir():
    return os.environ.get("HSA_BUILD_DIR", os.path.join(ROOT, "build"))


def require_root(what):
    if os.geteuid() != 0:
        sys.exit(f"{what}: must run as root (SCHED_FIFO at priority 80, mlockall, a private network "
                 "namespace with unshare -n, and cyclictest's /dev/cpu_dma_latency all need it)")


def enter_netns():
    """Re-executes the calling script inside a private network namespace, once."""
    if os.environ.get(NETNS_ENV) == "1":
        return
    env = dict(os.environ, **{NETNS_ENV: "1"})
    setup = ('ip link set lo up && ip link set lo multicast on && '
             'ip route add 224.0.0.0/4 dev lo && exec "$0" "$@"')
    argv = ["unshare", "-n", "sh", "-c", setup, sys.executable, os.path.abspath(sys.argv[0])] + sys.argv[1:]
    os.execvpe("unshare", argv, env)


def binary(build, name):
    path = os.path.join(build, "bin", name)
    if not os.access(path, os.X_OK):
        sys.exit(f"{path} is missing: build it (ninja -C {build} {name}) or run bench/run-all, which builds")
    return path


def operator_key(hsactl, folder):
    """Makes an operator key with `hsactl keygen` in `folder` (a new private folder) and points
    HSA_KEY at it for every client this script starts; returns the folder for hsad's --key-dir.
    The benchmarks run with authentication on, as hsad is deployed."""
    os.makedirs(folder, mode=0o700)
    path = subprocess.run([hsactl, "keygen", "bench", "--dir", folder], capture_output=True, text=True,
                          check=True, timeout=30).stdout.strip()
    os.environ["HSA_KEY"] = path
    return folder


def rewrite_realtime(template, out_path, cpu=None, priority=None, period_us=None):
    """Copies a configuration, replacing the [realtime] keys given (the line `key = value`)."""
    text = open(template).read()
    for key, value in (("cpu", cpu), ("priority", priority), ("base_period_us", period_us)):
        if value is None:
            continue
        text, n = re.subn(rf"^{key}\s*=\s*[-0-9]+", f"{key} = {value}", text, count=1, flags=re.M)
        if n != 1:
            sys.exit(f"{template}: no '{key} = ...' line to rewrite")
    with open(out_path, "w") as f:
        f.write(text)
    return out_path


def axis_names(config_path):
    """The axis names of an hsad configuration, in order."""
    with open(config_path, "rb") as f:
        return [a["name"] for a in tomllib.load(f).get("axes", [])]


def telemetry_rate(config_path):
    """(telemetry rate in Hz, base ticks per published sample) of a configuration: the bridge uses
    the first axis's rate for every axis."""
    with open(config_path, "rb") as f:
        c = tomllib.load(f)
    base_hz = 1e6 / c.get("realtime", {}).get("base_period_us", 100)
    rate = c["axes"][0].get("telemetry_rate_hz", 1000)
    return rate, round(base_hz / rate)


def percentile_from_bins(bins, q):
    """bins: [(lower, upper, count)] sorted by lower. The lower edge of the bin holding the
    nearest-rank q-quantile (cyclictest and hsad both report truncated whole µs, so for 1 µs bins
    this is the sample itself, truncated)."""
    total = sum(c for _, _, c in bins)
    if total == 0:
        return 0
    rank = max(1, -(-int(round(q * total * 1e6)) // 1_000_000))  # ceil(q·total), robust to 0.999's rounding
    seen = 0
    for lower, _, count in bins:
        seen += count
        if seen >= rank:
            return lower
    return bins[-1][0]


def count_at_least(bins, threshold):
    return sum(c for lower, _, c in bins if lower >= threshold)


def merge_bins(a, b):
    acc = {}
    for lower, upper, count in list(a) + list(b):
        key = (lower, upper)
        acc[key] = acc.get(key, 0) + count
    return sorted((lo, up, c) for (lo, up), c in acc.items())


class CpuTimes:
    """/proc/stat's aggregate CPU line: lets a run say how much time the hypervisor stole."""

    def __init__(self):
        fields = open("/proc/stat").readline().split()[1:]
        v = [int(x) for x in fields]
        self.total = sum(v[:8])  # user nice system idle iowait irq softirq steal
        self.steal = v[7] if len(v) > 7 else 0
        self.idle = v[3] + v[4]

    @staticmethod
    def steal_percent(before, after):
        dt = after.total - before.total
        return 100.0 * (after.steal - before.steal) / dt if dt > 0 else 0.0

    @staticmethod
    def busy_percent(before, after):
        dt = after.total - before.total
        return 100.0 * (dt - (after.idle - before.idle)) / dt if dt > 0 else 0.0


def process_cpu_seconds(pid):
    """utime + stime of a process, s (from /proc/PID/stat), and of each of its threads by name."""
    tick = os.sysconf("SC_CLK_TCK")

    def times(path):
        data = open(path).read()
        comm = data[data.index("(") + 1:data.rindex(")")]
        rest = data[data.rindex(")") + 2:].split()
        return comm, (int(rest[11]) + int(rest[12])) / tick  # fields 14 and 15: utime, stime

    _, total = times(f"/proc/{pid}/stat")
    threads = {}
    for tid in os.listdir(f"/proc/{pid}/task"):
        try:
            comm, t = times(f"/proc/{pid}/task/{tid}/stat")
        except OSError:
            continue
        threads[f"{comm}/{tid}"] = t
    return total, threads


def machine_facts():
    """What the results depend on, for the report."""
    uname = os.uname()
    facts = {
        "kernel": f"{uname.release} {uname.version}",
        "preempt_rt": os.path.exists("/sys/kernel/realtime"),
        "cpus": os.cpu_count(),
        "cpu_model": "",
        "sched_rt_runtime_us": open("/proc/sys/kernel/sched_rt_runtime_us").read().strip(),
        "loadavg": open("/proc/loadavg").read().split()[:3],
    }
    for line in open("/proc/cpuinfo"):
        if line.startswith("model name"):
            facts["cpu_model"] = line.split(":", 1)[1].strip()
            break
    try:
        facts["hypervisor"] = "hypervisor" in open("/proc/cpuinfo").read().split("flags", 2)[1].split("\n", 1)[0]
    except IndexError:
        facts["hypervisor"] = False
    return facts


def hold_cpu_dma_latency_zero():
    """Holds /dev/cpu_dma_latency at 0 µs for the life of the process, as cyclictest does for its
    own run, so that hsad's legs get the same power-management setting as cyclictest's."""
    try:
        fd = os.open("/dev/cpu_dma_latency", os.O_WRONLY)
        os.write(fd, (0).to_bytes(4, sys.byteorder))
        return fd
    except OSError:
        return None


def wait_or_kill(proc, timeout):
    try:
        return proc.wait(timeout=timeout)
    except subprocess.TimeoutExpired:
        proc.kill()
        proc.wait()
        return None


def sleep_until(t):
    dt = t - time.monotonic()
    if dt > 0:
        time.sleep(dt)


def off_rt_cpu(cmd, rt_cpu):
    """`cmd` run by taskset on every CPU but rt_cpu: a client the benchmark starts (hsactl) kept
    off the RT CPU, as a deployment keeps other programs off it. Traced (bench/late-wakeups), an
    unpinned `hsactl sine` beside 64 axes was woken onto the RT CPU by IPI hundreds of times in
    5 s, each time holding hsad's RT thread up by 25-40 µs: a cost of the harness, which
    cyclictest's legs, having no client, never paid. `cmd` itself when rt_cpu is None or the only
    CPU."""
    others = sorted(set(range(os.cpu_count() or 1)) - {rt_cpu}) if rt_cpu is not None else []
    return ["taskset", "-c", ",".join(map(str, others))] + list(cmd) if others else list(cmd)


def axis_states(hsactl, rt_cpu=None):
    """{axis: state} of every axis `hsactl axes` hears within a second (its lines "NAME: STATE");
    hsactl kept off rt_cpu (off_rt_cpu)."""
    out = subprocess.run(off_rt_cpu([hsactl, "axes"], rt_cpu), stdout=subprocess.PIPE, stderr=subprocess.DEVNULL,
                         text=True, timeout=60).stdout
    states = {}
    for line in out.splitlines():
        name, sep, state = line.partition(": ")
        if sep:
            states[name.strip()] = state.strip()
    return states


def enable_axes(hsactl, axes, attempts=3, rt_cpu=None):
    """Enables every axis (hsactl enable, 16 at a time) and returns those not ENABLED after
    `attempts` rounds, or None when `hsactl axes` heard no axis (then it cannot tell). On a loaded machine hsactl may time out waiting for the answer of a command
    hsad did take, so each round asks `hsactl axes` which axes are ENABLED, and tries the others.
    Every hsactl runs off rt_cpu (off_rt_cpu)."""
    from concurrent.futures import ThreadPoolExecutor

    def one(axis):
        subprocess.run(off_rt_cpu([hsactl, "--axis", axis, "enable"], rt_cpu), stdout=subprocess.DEVNULL,
                       stderr=subprocess.DEVNULL, timeout=60)
    not_enabled = list(axes)
    for _ in range(attempts):
        with ThreadPoolExecutor(max_workers=16) as pool:
            list(pool.map(one, not_enabled))
        states = axis_states(hsactl, rt_cpu)
        if not states:
            # hsactl heard no status at all within its second (a client starved by N axes' telemetry
            # on a loaded machine): unknown, not refused. The axes' faults are counted apart.
            return None
        not_enabled = [a for a in axes if states.get(a) != "ENABLED"]
        if not not_enabled:
            break
    return not_enabled


def rig_thread(rt_cpu, rig_priority=0):
    """The sim plugin's device thread for bench/axes_config.generate(rig_thread=...): the first CPU
    other than the RT thread's (the RT CPU itself on a 1-CPU machine), at SCHED_FIFO rig_priority,
    or SCHED_OTHER with 0 (the default: bench/README.md, "the rigs on the device thread", says why)."""
    other = next((c for c in sorted(os.sched_getaffinity(0)) if c != rt_cpu), rt_cpu)
    return {"priority": rig_priority, "cpu": other}
