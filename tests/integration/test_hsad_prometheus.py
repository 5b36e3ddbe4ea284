"""hsad's health read back the way a lab reads it: the real hsad writes its metrics textfile
([metrics] in its configuration), Debian's real prometheus-node-exporter serves it from its
textfile collector, and Debian's real prometheus server scrapes the exporter every second; the test
asks the server through its HTTP query API (/api/v1/query), as a dashboard or an alert rule would.

The simulated rig presses its e-stop (a scripted [[events]] of the sim plugin) after PRESS_AT_S of
its clock. Before it, Prometheus must show the axis DISABLED with no e-stop fault counted; after,
ESTOP with exactly one e-stop fault counted, and every other reason still 0. The textfile itself
passes `promtool check metrics`, and the file hsad leaves as it stops says it is not running.

Run with /usr/bin/python3 inside a private network namespace (hsad sends LCM multicast; the
exporter and the server listen on 127.0.0.1 of that namespace only):
    python3 test_hsad_prometheus.py HSAD CONFIG
Every process the test starts is killed at its end, whatever happened.
"""
import json
import os
import subprocess
import sys
import tempfile
import time
import unittest
import urllib.parse
import urllib.request

import hsad_process

HSAD, CONFIG = sys.argv[1:3]
del sys.argv[1:3]

PROMETHEUS = "/usr/bin/prometheus"
NODE_EXPORTER = "/usr/bin/prometheus-node-exporter"
PROMTOOL = "/usr/bin/promtool"
EXPORTER_ADDRESS = "127.0.0.1:19100"  # the namespace is the test's own: no other listener
SERVER_ADDRESS = "127.0.0.1:19090"
PRESS_AT_S = 20.0  # the sim's clock; time enough for the server to start and scrape the healthy axis
POLL_S = 0.5
POLL_LIMIT = 120  # queries per wait, and...
WAIT_LIMIT_S = 60.0  # ...seconds per wait, whichever ends first


def config_text(textfile, folder):
    """hsad-sim.toml, quiet about VM overruns, the e-stop pressed at PRESS_AT_S, metrics into `textfile`."""
    text = hsad_process.quiet_config_text(CONFIG)
    head, sep, tail = text.partition("[[axes]]")
    event = f"[[drivers.settings.events]]\nat_s = {PRESS_AT_S}\nestop = true\n\n"
    return (head + event + sep + tail + f'\n[recorder]\nfolder = "{folder}"\n' +
            f'\n[metrics]\ntextfile = "{textfile}"\ninterval_s = 0.5\n')


def query(expression):
    """The server's instant vector for `expression`, as {labels: value}; {} while it has none."""
    url = f"http://{SERVER_ADDRESS}/api/v1/query?" + urllib.parse.urlencode({"query": expression})
    with urllib.request.urlopen(url, timeout=5) as response:
        body = json.load(response)
    assert body["status"] == "success", body
    return {tuple(sorted(r["metric"].items())): float(r["value"][1]) for r in body["data"]["result"]}


class Prometheus(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.procs = []
        cls.dir = tempfile.TemporaryDirectory()
        cls.textdir = os.path.join(cls.dir.name, "textfile")
        os.mkdir(cls.textdir)
        cls.textfile = os.path.join(cls.textdir, "hsad.prom")
        captures = os.path.join(cls.dir.name, "captures")
        os.mkdir(captures)
        cls.config = os.path.join(cls.dir.name, "hsad.toml")
        with open(cls.config, "w") as f:
            f.write(config_text(cls.textfile, captures))
        server_config = os.path.join(cls.dir.name, "prometheus.yml")
        with open(server_config, "w") as f:
            f.write("global:\n  scrape_interval: 1s\n  evaluation_interval: 1s\n"
                    "scrape_configs:\n  - job_name: hsad\n    static_configs:\n"
                    f"      - targets: ['{EXPORTER_ADDRESS}']\n")
        try:
            cls.hsad = cls.start([HSAD, "--config", cls.config, "--key-dir", hsad_process.KEY_DIR,
                                  "--duration", "120"])
            # Only the textfile collector: the others would read the host's /proc and /sys for nothing.
            cls.start([NODE_EXPORTER, f"--web.listen-address={EXPORTER_ADDRESS}", "--collector.disable-defaults",
                       "--collector.textfile", f"--collector.textfile.directory={cls.textdir}"])
            cls.start([PROMETHEUS, f"--config.file={server_config}",
                       f"--storage.tsdb.path={os.path.join(cls.dir.name, 'tsdb')}",
                       f"--web.listen-address={SERVER_ADDRESS}"])
        except BaseException:
            cls.stop_all()
            raise

    @classmethod
    def start(cls, argv):
        """`argv` with its stderr into a log file of its own (a pipe nobody reads would fill and stall it)."""
        log = open(os.path.join(cls.dir.name, os.path.basename(argv[0]) + ".log"), "w+")
        proc = subprocess.Popen(argv, stdout=subprocess.DEVNULL, stderr=log, text=True)
        proc.log = log
        cls.procs.append(proc)
        return proc

    @staticmethod
    def log_of(proc):
        proc.log.seek(0)
        return proc.log.read()

    @classmethod
    def stop_all(cls):
        for proc in cls.procs:
            if proc.poll() is None:
                proc.kill()
            proc.wait(timeout=30)
            proc.log.close()
        cls.dir.cleanup()

    @classmethod
    def tearDownClass(cls):
        cls.stop_all()

    def wait_for(self, expression, want, what):
        """Queries `expression` until it has one sample equal to `want`; bounded in count and time."""
        deadline = time.monotonic() + WAIT_LIMIT_S
        seen = None
        for _ in range(POLL_LIMIT):
            for proc in self.procs:
                if proc.poll() is not None:
                    self.fail(f"{proc.args[0]} ended: {self.log_of(proc)}")
            try:
                seen = query(expression)
            except OSError as e:  # the server is not listening yet
                seen = e
            if isinstance(seen, dict) and len(seen) == 1 and list(seen.values())[0] == want:
                return
            if time.monotonic() > deadline:
                break
            time.sleep(POLL_S)
        self.fail(f"{what}: {expression} never became {want}; last answer {seen}")

    def test_1_the_healthy_axis_then_the_estop_fault_through_prometheus(self):
        self.wait_for('hsa_axis_state{axis="lift",state="DISABLED"}', 1.0, "the healthy axis")
        self.wait_for('hsa_faults_total{axis="lift",reason="estop"}', 0.0, "no fault before the e-stop")
        self.wait_for('hsa_running', 1.0, "hsad running")
        self.wait_for('node_textfile_scrape_error', 0.0, "the exporter reads the file")
        self.wait_for('hsa_axis_state{axis="lift",state="ESTOP"}', 1.0, "the e-stop state")
        self.wait_for('hsa_faults_total{axis="lift",reason="estop"}', 1.0, "one e-stop fault counted")
        self.wait_for('hsa_axis_fault_latched{axis="lift",reason="estop"}', 1.0, "the latched reason")
        self.wait_for('sum(hsa_faults_total{axis="lift",reason!="estop"})', 0.0, "no other fault")
        self.wait_for('hsa_driver_link{driver="rig",link="none"}', 1.0, "the sim driver has no link")
        # The histogram is usable as such: a percentile over a window, computed by the server.
        self.wait_for('count(histogram_quantile(0.99, rate(hsa_rt_lateness_seconds_bucket[5s])) >= 0)', 1.0,
                      "a lateness percentile")

    def test_2_the_textfile_passes_promtool_and_is_left_saying_hsad_stopped(self):
        deadline = time.monotonic() + WAIT_LIMIT_S
        while not os.path.exists(self.textfile) and time.monotonic() < deadline:
            time.sleep(POLL_S)
        with open(self.textfile) as f:
            check = subprocess.run([PROMTOOL, "check", "metrics"], stdin=f, capture_output=True, text=True,
                                   timeout=30)
        self.assertEqual(check.returncode, 0, check.stdout + check.stderr)
        self.assertEqual(check.stdout + check.stderr, "", "promtool's lint complains")
        self.assertEqual([n for n in os.listdir(self.textdir) if n != "hsad.prom"], [], "a temporary file left")
        self.hsad.terminate()
        self.hsad.wait(timeout=30)
        stderr = self.log_of(self.hsad)
        self.assertEqual(self.hsad.returncode, 0, stderr)
        self.assertIn("hsad: metrics: " + self.textfile, stderr)
        with open(self.textfile) as f:
            text = f.read()
        self.assertIn("\nhsa_running 0\n", text)


if __name__ == "__main__":
    unittest.main(verbosity=2)
