"""mujoco-py's LightModder and CameraModder: edit a named light or camera in
the model.

A light's colours (ambient, diffuse, specular), `active` and `castshadow`,
and a camera's `fovy`, are read from the model at every frame, so the next
frame shows them.  Positions and orientations (`light_pos`, `light_dir`,
`cam_pos`, `cam_quat`) are local to the body; MuJoCo turns them into the
world frame (`data.light_xpos`, `data.cam_xpos`, ...) in mj_forward, so call
`sim.forward()` (or step) before rendering, as with mujoco-py.
"""

import numpy as np

from ._simmodderbase import BaseModder, flag, numbers, real


def _direction(value, size, name):
    array = numbers(value, size, name)
    if not np.any(array):
        raise ValueError(f"{name} must not be all zeros")
    return array


class LightModder(BaseModder):
    """Set a named light's position, direction, colours, and whether it is on and
    casts shadows.  Unknown names are a ValueError naming them."""

    def get_lightid(self, name):
        """The id of the light `name`."""
        return self._name2id("light", name)

    def _set(self, field, name, value):
        getattr(self.model, field)[self.get_lightid(name)] = value

    def set_pos(self, name, value):
        """Position in its body's frame (3 numbers)."""
        self._set("light_pos", name, numbers(value, 3, "light pos"))

    def set_dir(self, name, value):
        """Direction in its body's frame (3 numbers, not all zero)."""
        self._set("light_dir", name, _direction(value, 3, "light dir"))

    def set_active(self, name, value):
        """Whether the light is on (True, False, 1 or 0)."""
        self._set("light_active", name, flag(value, "active"))

    def set_castshadow(self, name, value):
        """Whether the light casts shadows (True, False, 1 or 0)."""
        self._set("light_castshadow", name, flag(value, "castshadow"))

    def set_specular(self, name, value):
        """Specular colour (3 numbers)."""
        self._set("light_specular", name, numbers(value, 3, "specular"))

    def set_ambient(self, name, value):
        """Ambient colour (3 numbers)."""
        self._set("light_ambient", name, numbers(value, 3, "ambient"))

    def set_diffuse(self, name, value):
        """Diffuse colour (3 numbers)."""
        self._set("light_diffuse", name, numbers(value, 3, "diffuse"))


class CameraModder(BaseModder):
    """Get and set a named camera's position, orientation and vertical field of view.
    Unknown names are a ValueError naming them."""

    def get_camid(self, name):
        """The id of the camera `name`."""
        return self._name2id("camera", name)

    def get_pos(self, name):
        """Position in its body's frame: a live view of the model's row."""
        return self.model.cam_pos[self.get_camid(name)]

    def set_pos(self, name, value):
        self.model.cam_pos[self.get_camid(name)] = numbers(value, 3, "camera pos")

    def get_quat(self, name):
        """Orientation in its body's frame (w, x, y, z): a live view of the model's row."""
        return self.model.cam_quat[self.get_camid(name)]

    def set_quat(self, name, value):
        """Orientation (w, x, y, z), stored as given: MuJoCo expects a unit quaternion."""
        self.model.cam_quat[self.get_camid(name)] = _direction(value, 4, "camera quat")

    def set_fovy(self, name, value):
        """Vertical field of view in degrees, strictly between 0 and 180."""
        value = real(value, "fovy")
        if not 0.0 < value < 180.0:
            raise ValueError(f"fovy must be between 0 and 180 degrees, not {value}")
        self.model.cam_fovy[self.get_camid(name)] = value
