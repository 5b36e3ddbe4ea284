#!/usr/bin/python3
"""tools/valve-corner-bound on a valve identified from the simulator's record, as a user runs it.

The bound is a linear program; what pins it down is what any such bound must obey:
- a law with one more sample of delay can run the other's currents one sample later, so the bound
  never rises with the delay;
- keeping current off the limits only removes choices, so it never falls with the headroom;
- the currents the tool says reach the bound, run through the identified model and its LVDT
  filter integrated here independently of the tool's code (Runge-Kutta steps, not its exact
  discretisation), reach the bound, and before the corner they are the ramp's own (the law cannot
  know the corner is coming);
- a law that keeps the old ramp's current until the corner enters it, then the new ramp's (no
  shaping at all), is one of the programme's choices, so its peak is never below the bound.
A cap on the currents' swing after the corner only removes choices (the capped bound is never
below the free one and never rises with the cap), the capped currents keep to their cap and reach
their bound here, and a cap at the free optimum's own swing leaves the bound where it was.
A law at the bound on every corner of the experiment's 4 periods peaks at the bound without noise
and higher through the LVDT's. And a file that is not an identification is refused with a message
naming it. The model's delay is τ + δ − T, the identification's own (the tool's header says it).

    test_valve_corner_bound.py HSA_ANALYZE TOOL
"""
import json
import math
import os
import re
import subprocess
import sys
import tempfile

import numpy as np


def run_bound(tool, valve_json, delays, headrooms, commands_csv, extra=()):
    out = subprocess.run([tool, valve_json, "--delay", *map(str, delays), "--headroom", *map(str, headrooms),
                          "--commands", commands_csv, *extra],
                         capture_output=True, text=True, timeout=300)
    if out.returncode != 0:
        sys.exit(f"valve-corner-bound failed ({out.returncode}): {out.stderr}")
    rows = {}
    for line in out.stdout.splitlines():
        m = re.match(r"^\s+([0-9.]+)\s+([0-9.]+)\s+([0-9.]+)$", line)
        if m:
            rows[(float(m.group(1)), float(m.group(2)))] = float(m.group(3))
    if len(rows) != len(delays) * len(headrooms):
        sys.exit(f"expected {len(delays) * len(headrooms)} rows, got:\n{out.stdout}")
    return rows


def read_commands(path):
    """The tool's --commands CSV: sample -> current."""
    with open(path) as f:
        return {int(a): float(c) for a, c in (line.split(",") for line in f.read().splitlines()[1:])}


def steady_command(v, slope, apex, delay_k, j, s, period=1e-4):
    """The current at sample j that holds the spool on the line of slope s through the apex, K
    samples late (the line at the middle of the sample the command is held for)."""
    w0 = 2 * math.pi * v["f0"]
    d = int(round(v["delay"] / period))
    # the spool s·τs ahead of the line, so that the LVDT's lagging reading is on it
    x = apex + s * (j + d - delay_k + 0.5) * period + s * v["tau_s"]
    return (x - v["x_min"] + 2 * v["zeta"] * s / w0) / v["g"] + v["tau_a"] * s / v["g"] + v["w"] / 2


def corner_peak(v, imax, slope, apex, delay_k, commands=None, period=1e-4):
    """The peak |y(i) − r(i − K)|, y the LVDT's reading (eq 7's first-order filter on x), over the
    tool's window, i in [−60 + K, 140 + K), under `commands` (sample → current) where given and
    otherwise each ramp's steady current switched when the corner reaches the valve (the unshaped
    law).

    Integrated with Runge-Kutta steps (not the tool's exact discretisation), so that the two agree
    only if both describe the same valve.
    """
    w0 = 2 * math.pi * v["f0"]
    d = int(round(v["delay"] / period))

    def reference(i):
        return apex - slope * abs(i) * period

    start = -400
    x = reference(start - delay_k) + slope * v["tau_s"]
    c = (x - v["x_min"] + 2 * v["zeta"] * slope / w0) / v["g"]
    vel = slope
    reading = x - slope * v["tau_s"]
    peak, sub = 0.0, 10
    for i in range(start, 140 + delay_k):
        if i >= -60 + delay_k:
            peak = max(peak, abs(reading - reference(i - delay_k)))
        j = i - d
        if commands is not None and j in commands:
            command = commands[j]
        else:
            command = min(max(steady_command(v, slope, apex, delay_k, j, slope if j < 0 else -slope), 0.0), imax)
        p = command - v["w"] / 2
        for _ in range(sub):  # classical Runge-Kutta on (c, x, ẋ, y), the command held
            def f(y):
                return np.array([(p - y[0]) / v["tau_a"], y[2],
                                 w0 * w0 * (v["x_min"] + v["g"] * y[0] - y[1]) - 2 * v["zeta"] * w0 * y[2],
                                 (y[1] - y[3]) / v["tau_s"]])
            h = period / sub
            y = np.array([c, x, vel, reading])
            k1 = f(y)
            k2 = f(y + 0.5 * h * k1)
            k3 = f(y + 0.5 * h * k2)
            k4 = f(y + h * k3)
            c, x, vel, reading = y + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
    return peak


def main():
    analyze, tool = sys.argv[1:3]
    with tempfile.TemporaryDirectory() as tmp:
        record = os.path.join(tmp, "valve.csv")
        subprocess.run([analyze, "experiment", "valve-excite", "--csv", record], check=True,
                       capture_output=True, timeout=120)
        fit = subprocess.run([analyze, "identify-valve", record, "--json"], check=True, capture_output=True,
                             text=True, timeout=300).stdout
        valve_json = os.path.join(tmp, "valve.json")
        with open(valve_json, "w") as f:
            f.write(fit)

        delays, headrooms = [1.6e-3, 1.0e-3, 2.0e-3], [0.0, 0.3]
        commands_csv = os.path.join(tmp, "commands.csv")
        rows = run_bound(tool, valve_json, delays, headrooms, commands_csv)
        for h in headrooms:
            seq = [rows[(d * 1e3, h)] for d in sorted(delays)]
            if any(b > a + 1e-3 for a, b in zip(seq, seq[1:])):
                sys.exit(f"the bound rose with the delay at headroom {h} A: {seq}")
        for d in delays:
            if rows[(d * 1e3, 0.3)] < rows[(d * 1e3, 0.0)] - 1e-3:
                sys.exit(f"the bound fell with more headroom at {d * 1e3} ms: {rows}")

        d = json.loads(fit)
        val = lambda k: d[k]["value"] if isinstance(d[k], dict) else d[k]
        v = {"g": val("gain_m_per_a"), "x_min": val("rest_position_m"), "f0": val("natural_frequency_hz"),
             "zeta": val("damping_ratio"), "tau_a": val("magnetic_lag_s"), "w": val("width_a"),
             # the regulator's shift in rows (τ/T − 1) and then the valve model's δ, as the tool
             "delay": d["regulator"]["delay_s"] - 1e-4 + val("delay_s"),
             "tau_s": 1 / (2 * math.pi * d["sensor_bandwidth_hz"])}
        imax = d["regulator"]["current_max_a"]["value"]
        # The tool composes the command-to-reading delay as the identified model does: the regulator's
        # shift in rows, then δ (τ + δ − T), not τ + δ, which counts the command's period twice.
        head = subprocess.run([tool, valve_json, "--delay", "1.6e-3"], capture_output=True, text=True, timeout=300)
        m = re.search(r"delay ([0-9.]+) ms", head.stdout)
        if head.returncode != 0 or not m or abs(float(m.group(1)) * 1e-3 - v["delay"]) > 1e-9:
            sys.exit(f"the tool's delay is not tau + delta - T = {v['delay'] * 1e3:.3g} ms: {head.stdout[:200]!r}")
        slope, apex = 4 * 0.875e-3 * 10, 0.875e-3
        commands = read_commands(commands_csv)
        k = int(round(delays[0] / 1e-4))
        for j, c in commands.items():
            if j < 0 and abs(c - steady_command(v, slope, apex, k, j, slope)) > 1e-6:
                sys.exit(f"before the corner (sample {j}) the bound's current {c} A is not the ramp's")
            if j >= 0 and not -1e-9 <= c <= imax + 1e-9:
                sys.exit(f"the bound's current {c} A at sample {j} is outside [0, {imax}] A")
        reached = corner_peak(v, imax, slope, apex, k, commands) * 1e6
        bound = rows[(delays[0] * 1e3, 0.0)]
        if abs(reached - bound) > 0.002 * bound:  # 0.2 %: RK steps against the exact discretisation
            sys.exit(f"the bound's currents reach {reached:.3f} um on the model integrated here, the tool says {bound:.3f} um")
        print(f"{delays[0] * 1e3:.1f} ms: its currents reach {reached:.3f} um here against the bound {bound:.3f} um")
        for delay in delays:
            naive = corner_peak(v, imax, slope, apex, int(round(delay / 1e-4))) * 1e6
            bound = rows[(delay * 1e3, 0.0)]
            if not bound <= naive + 0.05:
                sys.exit(f"at {delay * 1e3} ms the unshaped switch reaches {naive:.2f} um, below the bound {bound:.2f} um")
            print(f"{delay * 1e3:.1f} ms: bound {bound:.2f} um, unshaped switch {naive:.2f} um")

        # A cap on the currents' swing from the corner on (sum |ΔI| from sample -1) only removes
        # choices: the bound never falls below the uncapped one, and never rises as the cap grows;
        # the capped currents keep within their cap and reach their bound on the model integrated
        # here; and a cap at the uncapped optimum's own swing leaves the bound where it was.
        def variation(cmds):
            seq = [cmds[j] for j in sorted(cmds) if j >= -1]
            return sum(abs(b - a) for a, b in zip(seq, seq[1:]))

        free = variation(commands)
        capped, prev = {}, None
        for cap in (1.0, 2.0, 4.0):
            capped_csv = os.path.join(tmp, f"capped{cap}.csv")
            b = run_bound(tool, valve_json, [delays[0]], [0.0], capped_csv, ("--max-variation", str(cap)))
            capped[cap] = b[(delays[0] * 1e3, 0.0)]
            cmds = read_commands(capped_csv)
            if variation(cmds) > cap + 1e-6:
                sys.exit(f"capped at {cap} A, the bound's currents swing by {variation(cmds):.4f} A")
            here = corner_peak(v, imax, slope, apex, k, cmds) * 1e6
            if abs(here - capped[cap]) > 0.002 * capped[cap]:
                sys.exit(f"capped at {cap} A, the currents reach {here:.3f} um here, the tool says {capped[cap]:.3f} um")
            if capped[cap] < rows[(delays[0] * 1e3, 0.0)] - 1e-3 or (prev is not None and capped[cap] > prev + 1e-3):
                sys.exit(f"the capped bounds are not ordered: {capped}, uncapped {rows[(delays[0] * 1e3, 0.0)]}")
            prev = capped[cap]
        at_own = run_bound(tool, valve_json, [delays[0]], [0.0], os.path.join(tmp, "own.csv"),
                           ("--max-variation", str(free * (1 + 1e-6))))[(delays[0] * 1e3, 0.0)]
        if abs(at_own - rows[(delays[0] * 1e3, 0.0)]) > 0.002 * at_own:
            sys.exit(f"capped at the optimum's own swing ({free:.3f} A) the bound moved: {at_own} against "
                     f"{rows[(delays[0] * 1e3, 0.0)]}")
        print(f"{delays[0] * 1e3:.1f} ms, currents' swing capped at 1 / 2 / 4 A: " +
              " / ".join(f"{capped[c]:.2f}" for c in (1.0, 2.0, 4.0)) + f" um; the optimum swings by {free:.2f} A")
        out = subprocess.run([tool, valve_json, "--max-variation", "-1"], capture_output=True, text=True, timeout=60)
        if out.returncode == 0 or "--max-variation" not in out.stderr:
            sys.exit(f"a negative --max-variation was not refused clearly: {out.returncode} {out.stderr!r}")

        # A law at the bound on every corner and exact on the ramps: with no noise its peak over the
        # 4 periods is the bound itself; read through noise it can only be seen higher.
        def with_noise(rms):
            out = subprocess.run([tool, valve_json, "--delay", "1.6e-3", "--noise-rms", str(rms), "--draws", "8"],
                                 capture_output=True, text=True, timeout=300)
            m = re.search(r"^\s+1\.60\s+0\.00\s+([0-9.]+)\s+([0-9.]+) \(([0-9.]+)-([0-9.]+)\)$", out.stdout, re.M)
            if out.returncode != 0 or not m:
                sys.exit(f"valve-corner-bound --noise-rms failed ({out.returncode}): {out.stdout} {out.stderr}")
            return [float(x) for x in m.groups()]
        quiet, noisy = with_noise(1e-12), with_noise(1e-6)
        if abs(quiet[1] - quiet[0]) > 0.01 or abs(quiet[3] - quiet[0]) > 0.01:
            sys.exit(f"without noise the law at the bound should peak at the bound: {quiet}")
        if not noisy[2] > quiet[0]:
            sys.exit(f"read through 1 um rms of noise the peak stayed at or below the bound: {noisy}")
        print(f"a law at the bound, read through 1 um rms: {noisy[1]:.2f} um ({noisy[2]:.2f}-{noisy[3]:.2f}), bound {quiet[0]:.2f}")

        out = subprocess.run([tool, valve_json, "--sensor-bandwidth", "-1"], capture_output=True, text=True, timeout=60)
        if out.returncode == 0 or "sensor bandwidth" not in out.stderr:
            sys.exit(f"a negative sensor bandwidth was not refused clearly: {out.returncode} {out.stderr!r}")

        bad = os.path.join(tmp, "bad.json")
        with open(bad, "w") as f:
            f.write("{\"gain_m_per_a\": 1}")
        out = subprocess.run([tool, bad], capture_output=True, text=True, timeout=60)
        if out.returncode == 0 or "not an identify-valve --json object" not in out.stderr or bad not in out.stderr:
            sys.exit(f"a file that is not an identification was not refused clearly: {out.returncode} {out.stderr!r}")
    print("ok")


if __name__ == "__main__":
    main()
