"""The first line of a measurement script's output: the date, the load, the machine, so that a
figure quoted in the docs says when and where it was measured (imported by error_bar_cost.py
and several_delays_cost.py)."""
import os
import platform
import time


def machine_stamp(detail):
    """'# DATE UTC, load L1 L5, CPU, K cores, DETAIL' with the load measured now."""
    load = os.getloadavg()
    cpu = platform.machine()
    try:
        with open("/proc/cpuinfo") as f:
            cpu = next(line.split(":", 1)[1].strip() for line in f if line.startswith("model name"))
    except (OSError, StopIteration):
        pass
    return (f"# {time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}, load {load[0]:.2f} {load[1]:.2f}, "
            f"{cpu}, {os.cpu_count()} cores, {detail}")
