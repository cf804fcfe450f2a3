"""What mujoco-py's render calls take, checked before MuJoCo or OpenGL sees it.

mujoco-py passed sizes and camera ids straight to C.  Here an image size is a
positive int no larger than the offscreen buffer, a camera is one the model
has, and each refusal is a TypeError or ValueError that names the argument.
"""

import operator

import numpy as np

from ..rendering._base import GLContextBase
from ..rendering._sizes import pixels

# the largest offscreen buffer side accepted: the GL contexts' own limit (OpenGL's
# renderbuffer limit on Mesa and common GPUs)
MAX_BUFFER = GLContextBase.max_size


def buffer_side(value, name):
    """A side for update_offscreen_size: a positive int of at most MAX_BUFFER."""
    return pixels(value, name, MAX_BUFFER)


def image_size(width, height, buffer_width, buffer_height):
    """(width, height), positive and within an offscreen buffer of that size."""
    width, height = pixels(width, "width"), pixels(height, "height")
    if width > buffer_width or height > buffer_height:
        need = f"{max(width, buffer_width)}, {max(height, buffer_height)}"
        wide, high = need.split(", ")
        raise ValueError(
            f"an image of {width}x{height} pixels does not fit the offscreen buffer of "
            f"{buffer_width}x{buffer_height} (model.vis.global_.offwidth/offheight): "
            f"call update_offscreen_size({need}) on the render context, or give the model "
            f'<visual><global offwidth="{wide}" offheight="{high}"/></visual>')
    return width, height


def default_size(width, height, model):
    """None for a side means the model's offscreen buffer side."""
    if width is None:
        width = model.vis.global_.offwidth
    if height is None:
        height = model.vis.global_.offheight
    return width, height


def camera_names(model):
    return [model.camera(i).name for i in range(model.ncam)]


def camera_id(model, value):
    """None (keep the render context's camera), -1 (its free camera) or a camera id."""
    if value is None:
        return None
    if isinstance(value, (bool, np.bool_)) or not hasattr(value, "__index__"):
        raise TypeError(f"camera_id must be an int or None, not {type(value).__name__}")
    value = operator.index(value)
    if not -1 <= value < model.ncam:
        raise ValueError(f"camera_id must be -1 (the free camera) or a camera id from 0 to "
                         f"{model.ncam - 1}, not {value}" if model.ncam else
                         f"camera_id must be -1 (the free camera): the model has no camera, "
                         f"not {value}")
    return value


def camera_name(model, name):
    """The id of the camera named `name`; None for None (the free camera)."""
    if name is None:
        return None
    if not isinstance(name, str):
        raise TypeError(f"camera_name must be a str or None, not {type(name).__name__}")
    names = camera_names(model)
    if not name or name not in names:
        known = ", ".join(repr(n) for n in names if n) or "none named"
        raise ValueError(f"unknown camera name {name!r}: the model's cameras are {known}")
    return names.index(name)
