#!/usr/bin/python3
"""bench/configs/hsad-latency.toml is systemd/hsad-sim.toml but for its header and [realtime].

The latency benchmarks measure the daemon a user runs: the example's axis, law, fault bounds and
recorder. A benchmark configuration that drifted from the example measured something else (it had
kept a 5 ms blind-time bound the example had relaxed for a shared VM, so its axis faulted under
load and did less work in the rest of the leg). Then `hsad --check-config` must accept it.

    test_bench_config.py SOURCE_DIR HSAD HSACTL
"""
import os
import re
import subprocess
import sys
import tempfile


def without_header_and_realtime(text):
    lines = text.splitlines()
    start = next(i for i, line in enumerate(lines) if line.startswith("# LCM URL"))
    out, in_realtime = [], False
    for line in lines[start:]:
        if re.match(r"^\[[^\]]+\]", line):
            in_realtime = line.strip() == "[realtime]"
        if not in_realtime:
            out.append(line)
    return out


def main():
    source, hsad, hsactl = sys.argv[1:4]
    example = open(os.path.join(source, "systemd", "hsad-sim.toml")).read()
    bench = open(os.path.join(source, "bench", "configs", "hsad-latency.toml")).read()
    a, b = without_header_and_realtime(example), without_header_and_realtime(bench)
    if a != b:
        diff = [f"  example: {x!r}\n  bench:   {y!r}" for x, y in zip(a, b) if x != y][:5]
        sys.exit("bench/configs/hsad-latency.toml differs from systemd/hsad-sim.toml outside its header and "
                 f"[realtime] ({len(a)} vs {len(b)} lines); first differences:\n" + "\n".join(diff))
    realtime = bench[bench.index("[realtime]"):]
    for key, value in (("cpu", "1"), ("require_realtime", "true"), ("isolate_cpu", "true")):
        if not re.search(rf"^{key} = {value}\b", realtime, re.M):
            sys.exit(f"bench/configs/hsad-latency.toml: [realtime] {key} is not {value}")
    with tempfile.TemporaryDirectory() as keys:
        os.chmod(keys, 0o700)
        subprocess.run([hsactl, "keygen", "bench", "--dir", keys], check=True, capture_output=True, timeout=30)
        r = subprocess.run([hsad, "--check-config", os.path.join(source, "bench", "configs", "hsad-latency.toml"),
                            "--key-dir", keys], capture_output=True, text=True, timeout=60)
        if r.returncode != 0:
            sys.exit(f"hsad --check-config refused the bench configuration:\n{r.stderr}")
    print(f"bench configuration = example outside header and [realtime] ({len(a)} lines), and hsad accepts it")


if __name__ == "__main__":
    main()
