"""Ray, imported on first use: mjcffi.distributed imports without it, and says how to get it."""

import importlib

EXTRA_HINT = "pip install 'mjcffi[distributed]'"


def require():
    """The `ray` module, or ImportError naming the extra that installs it."""
    try:
        return importlib.import_module("ray")
    except ImportError as exc:
        raise ImportError(f"mjcffi.distributed needs Ray, which is not installed: "
                          f"{EXTRA_HINT} (or pip install 'ray>=2.9')") from exc


def connect():
    """`ray`, connected: ray.init() with Ray's defaults (RAY_ADDRESS, else a local
    cluster) unless this process is connected already."""
    ray = require()
    if not ray.is_initialized():
        ray.init()
    return ray
