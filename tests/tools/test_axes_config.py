#!/usr/bin/python3
"""bench/axes-per-core's configurations (bench/axes_config.py) are ones hsad accepts.

For both variants, with the rigs in the RT thread's reads and on the sim plugin's device thread
(--rig-thread), `hsad --check-config` accepts 64 axes, and refuses a 65th driver instance naming
it: a benchmark whose configuration hsad refused would report nothing about axes.

    test_axes_config.py SOURCE_DIR HSAD HSACTL
"""
import os
import subprocess
import sys
import tempfile

source, hsad, hsactl = sys.argv[1:4]
sys.dont_write_bytecode = True
sys.path.insert(0, os.path.join(source, "bench"))
import axes_config  # noqa: E402


def check(text, keys):
    with tempfile.NamedTemporaryFile("w", suffix=".toml", delete=False) as f:
        f.write(text)
    try:
        r = subprocess.run([hsad, "--check-config", f.name, "--key-dir", keys], capture_output=True, text=True,
                           timeout=120)
    finally:
        os.unlink(f.name)
    return r.returncode, r.stdout + r.stderr


def main():
    failures = []
    with tempfile.TemporaryDirectory() as keys, tempfile.TemporaryDirectory() as captures:
        os.chmod(keys, 0o700)
        subprocess.run([hsactl, "keygen", "bench", "--dir", keys], check=True, capture_output=True, timeout=30)
        for variant in axes_config.VARIANTS:
            for rigs in (None, {"priority": 0, "cpu": 0}):
                where = f"{variant}, rigs {'on the device thread' if rigs else 'in the reads'}"
                text = axes_config.generate(variant, 64, 1, 80, 1000, captures, rig_thread=rigs)
                if rigs and text.count('timing = "device"') != 64:
                    failures.append(f"{where}: not every rig is device-timed")
                code, out = check(text, keys)
                if code != 0:
                    failures.append(f"{where}: hsad refused 64 axes:\n{out[-1500:]}")
                code, out = check(axes_config.generate(variant, 65, 1, 80, 1000, captures, rig_thread=rigs), keys)
                if code == 0 or "drivers[64]" not in out:
                    failures.append(f"{where}: 65 driver instances not refused at drivers[64]:\n{out[-800:]}")
    if failures:
        sys.exit("\n".join(failures))
    print("64 axes accepted and 65 refused, both variants, rigs in the reads and on the device thread")


if __name__ == "__main__":
    main()
