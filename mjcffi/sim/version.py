"""mujoco-py's `mujoco_py.version`: the version of mujoco-py that this face follows.

Code written for mujoco-py compares `mujoco_py.__version__` with mujoco-py's
releases, so the face answers 2.1.2.14, the release whose API and tests it
follows.  MuJoCo's own version is `mjcffi.__version__` (4.0.0), mjcffi's
`mjcffi.__mjcffi_version__`.
"""

__all__ = ["__version__", "get_version"]

version_info = (2, 1, 2, 14)
__version__ = ".".join(str(part) for part in version_info)


def get_version():
    """mujoco-py's version that this face follows, as a string."""
    return __version__
