"""The machine state a benchmark table states: processor, cores and affinity, each core's busy
share during the run (/proc/stat), load average, versions, commit and time; and the table's
atomic write (:func:`write_markdown`)."""

from __future__ import annotations

import datetime
import os
import platform
import subprocess

import numpy as np

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), ".."))


def cpu_times() -> dict[int, tuple[int, int]]:
    """(busy, total) jiffies of each core (/proc/stat); empty where not available."""
    out = {}
    try:
        with open("/proc/stat") as f:
            for line in f:
                if line.startswith("cpu") and line[3].isdigit():
                    parts = line.split()
                    v = [int(x) for x in parts[1:]]
                    idle = v[3] + (v[4] if len(v) > 4 else 0)
                    out[int(parts[0][3:])] = (sum(v[:8]) - idle, sum(v[:8]))
    except OSError:
        pass
    return out


def commit() -> str:
    """Short commit of the working tree, marked where it has uncommitted changes."""
    try:
        rev = subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=ROOT,
                             capture_output=True, text=True, timeout=10,
                             check=False).stdout.strip()
        dirty = subprocess.run(["git", "status", "--porcelain", "--untracked-files=no"],
                               cwd=ROOT, capture_output=True, text=True, timeout=10,
                               check=False).stdout
        return rev + (" (with uncommitted changes)" if dirty.strip() else "")
    except (OSError, subprocess.SubprocessError):
        return "unknown"


def cpu_model() -> str:
    """The processor's model name (/proc/cpuinfo, else platform.processor())."""
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or ""


def machine_lines(cpu0, cpu1, load0, load1) -> list[str]:
    """Markdown bullets of the machine state between two (cpu_times(), os.getloadavg())."""
    model = cpu_model()
    aff = sorted(os.sched_getaffinity(0))
    busy = []
    for c in sorted(cpu1):
        if c in cpu0 and cpu1[c][1] > cpu0[c][1]:
            share = (cpu1[c][0] - cpu0[c][0]) / (cpu1[c][1] - cpu0[c][1])
            if aff == [c]:
                who = "this benchmark"
            elif c in aff:           # not pinned: this benchmark may run on every core it has
                who = "this benchmark and any other processes"
            else:
                who = "other processes: " + ("busy" if share > 0.5 else "idle")
            busy.append(f"core {c} {100 * share:.0f} % ({who})")
    return [f"- CPU: {model}; {os.cpu_count()} logical processors; this run pinned to "
            f"{'core ' + str(aff[0]) if len(aff) == 1 else 'cores ' + str(aff)}"
            + (" (`taskset -c 0`)" if aff == [0] else " (NOT pinned to one core)"),
            "- busy share of each core during the run: " + ", ".join(busy) if busy else
            "- busy share of each core: not available",
            f"- load average (1, 5, 15 min) before: {load0[0]:.2f}, {load0[1]:.2f}, "
            f"{load0[2]:.2f}; after: {load1[0]:.2f}, {load1[1]:.2f}, {load1[2]:.2f}",
            f"- Python {platform.python_version()}, numpy {np.__version__}, "
            f"{platform.platform()}",
            f"- commit {commit()}",
            f"- {datetime.datetime.now(datetime.timezone.utc):%Y-%m-%d %H:%M} UTC"]


def write_markdown(path: str, lines: list[str]) -> None:
    """Write the table's ``lines`` to ``path`` atomically (sim_core.result.atomic_write_bytes)
    and say so."""
    import sys
    sys.path.insert(0, ROOT)
    from sim_core.result import atomic_write_bytes
    atomic_write_bytes(path, ("\n".join(lines) + "\n").encode())
    print("wrote", path)
