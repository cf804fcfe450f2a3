"""What a measurement ran on: date, versions and CPU, for the reports."""

import datetime
import os
import platform
from importlib import metadata


def _version(name):
    try:
        return metadata.version(name)
    except metadata.PackageNotFoundError:
        return "not installed"


def cpu_name():
    try:
        with open("/proc/cpuinfo") as info:
            for line in info:
                if line.startswith("model name"):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or platform.machine()


def environment(packages=("mjcffi", "mujoco-core", "cffi", "numpy")):
    """Markdown lines naming the date, the versions of `packages` and the CPU."""
    versions = ", ".join(f"{name} {_version(name)}" for name in packages)
    return [f"- date: {datetime.date.today().isoformat()}",
            f"- Python {platform.python_version()} ({platform.python_implementation()}), "
            f"{versions}",
            f"- CPU: {cpu_name()} ({os.cpu_count()} cores); {platform.system()} "
            f"{platform.machine()}"]
