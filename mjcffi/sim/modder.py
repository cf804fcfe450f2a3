"""mujoco-py's `mujoco_py.modder`: domain randomization between frames.

`TextureModder` rewrites a geom's texture pixels, `MaterialModder` a geom's
material, `LightModder` and `CameraModder` a named light or camera; what they
share (the sim, the random state, name lookups, value checks) is `BaseModder`.
Each takes `(sim, random_state=None)`: None for a fresh random state, a seed, or
a numpy RandomState, so that a seeded run is reproducible.  Every check raises
before the model is touched, so a refused edit leaves the model as it was.

- Materials, lights' colours, `active` and `castshadow`, and a camera's `fovy`
  are read from the model at every frame: the next frame shows an edit.
- Positions and orientations of lights and cameras (`light_pos`, `light_dir`,
  `cam_pos`, `cam_quat`) are local to the body; MuJoCo turns them into the world
  frame in mj_forward, so call `sim.forward()` (or step) before rendering, as
  with mujoco-py.
- Texture pixels live in the model (`model.tex_data`); after an edit the texture
  is uploaded to every render context of the sim (`mjr_uploadTexture`).  A render
  context made later reads the textures when it is made, so an edit with no
  render context yet needs no OpenGL.  'skybox' names the skybox texture.
  Colours are RGB triples of 0..255, cast to bytes by truncation as mujoco-py's
  array assignment did, so a seeded random state draws the same pixels as
  mujoco-py.  Texture edits act on the texture: geoms sharing it all change.
  `whiten_materials()` sets material colours to white, so that textures show
  their own colours rather than a blend with the material's.
"""

import numpy as np

from .. import functions as _f
from .._generated.enums import mjtObj, mjtTexture, mjtTextureRole
from ._base import SimBase

__all__ = ["TextureModder", "MaterialModder", "LightModder", "CameraModder", "Texture",
           "BaseModder"]


# ------------------------------------------------------------------ shared
def make_random_state(value):
    """mujoco-py's random_state: None (a fresh, unseeded RandomState), a seed (an int),
    or a RandomState (anything with `uniform` and `randint`), used as given."""
    if value is None:
        return np.random.RandomState()
    if isinstance(value, (int, np.integer)) and not isinstance(value, (bool, np.bool_)):
        return np.random.RandomState(int(value))
    if not all(callable(getattr(value, m, None)) for m in ("uniform", "randint")):
        raise TypeError(f"random_state must be None, a seed or a numpy RandomState, not "
                        f"{type(value).__name__}")
    return value


def numbers(value, size, name):
    """`value` as a float64 array of shape (size,), all finite; TypeError when it is not
    numbers, ValueError when it is the wrong shape or not finite."""
    try:
        array = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError):
        raise TypeError(f"{name} must be {size} numbers, not {value!r}") from None
    if array.shape != (size,):
        raise ValueError(f"{name} must be {size} numbers (shape ({size},)), not an array "
                         f"of shape {array.shape}")
    if not np.all(np.isfinite(array)):
        raise ValueError(f"{name} must be finite, not {array.tolist()}")
    return array


def colour(value, name):
    """An RGB triple of 0..255, as float64 (the caller casts to uint8, truncating as
    mujoco-py's assignment did); ValueError naming `name` otherwise."""
    try:
        array = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError):
        array = None
    if array is None or array.shape != (3,) or not np.all(np.isfinite(array)) \
            or np.any((array < 0) | (array > 255)):
        raise ValueError(f"{name} must be three numbers from 0 to 255 (R, G, B), not {value!r}")
    return array


def real(value, name):
    """`value` as a finite float; TypeError when it is not a real number."""
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, float, np.integer,
                                                                   np.floating)):
        raise TypeError(f"{name} must be a number, not {type(value).__name__}")
    value = float(value)
    if not np.isfinite(value):
        raise ValueError(f"{name} must be finite, not {value}")
    return value


def unit(value, name):
    """A number from 0 to 1."""
    value = real(value, name)
    if not 0.0 <= value <= 1.0:
        raise ValueError(f"{name} must be from 0 to 1, not {value}")
    return value


def flag(value, name):
    """A switch: True, False, 1 or 0."""
    if isinstance(value, (bool, np.bool_, int, np.integer)) and int(value) in (0, 1):
        return bool(value)
    raise ValueError(f"{name} must be True, False, 1 or 0, not {value!r}")


class BaseModder:
    """The sim a modder edits (`sim`, `model`), its `random_state`, and name lookups."""

    def __init__(self, sim, random_state=None):
        if not isinstance(sim, SimBase):
            raise TypeError(f"sim must be an MjSim, not {type(sim).__name__}")
        self.sim = sim
        self.random_state = make_random_state(random_state)

    @property
    def model(self):
        return self.sim.model

    def _name2id(self, kind, name):
        """The id of the model's `kind` ('geom', 'light', 'camera') named `name`;
        ValueError naming it when there is none."""
        if not isinstance(name, str):
            raise TypeError(f"a {kind} name must be a str, not {type(name).__name__}")
        objtype = int(getattr(mjtObj, f"mjOBJ_{kind.upper()}"))
        found = _f.mj_name2id(self.model, objtype, name) if name else -1
        if found < 0:
            raise ValueError(f"the model has no {kind} named {name!r}")
        return found


# ------------------------------------------------------------------ materials

class GeomModder(BaseModder):
    """A modder that finds what it edits through a geom's material."""

    def _geom(self, name):
        return self._name2id("geom", name)

    def get_mat_id(self, name):
        """The material id of the geom `name`; ValueError if it has none."""
        material = int(self.model.geom_matid[self._geom(name)])
        if material < 0:
            raise ValueError(f"geom {name!r} has no material")
        return material


class MaterialModder(GeomModder):
    """Set or randomize a geom's material: specularity, shininess, reflectance (0..1),
    texture repeats (`set_texrepeat`) and colour (`set_rgba`; MuJoCo shows a material's
    colour on geoms that leave their own rgba at the default)."""

    def set_specularity(self, name, value):
        self.model.mat_specular[self.get_mat_id(name)] = unit(value, "specularity")

    def set_shininess(self, name, value):
        self.model.mat_shininess[self.get_mat_id(name)] = unit(value, "shininess")

    def set_reflectance(self, name, value):
        self.model.mat_reflectance[self.get_mat_id(name)] = unit(value, "reflectance")

    def set_rgba(self, name, rgba):
        """The material's colour, four numbers from 0 to 1."""
        array = numbers(rgba, 4, "rgba")
        if not all(0.0 <= x <= 1.0 for x in array):
            raise ValueError(f"rgba must be four numbers from 0 to 1, not {rgba!r}")
        self.model.mat_rgba[self.get_mat_id(name)] = array

    def set_texrepeat(self, name, repeat_x, repeat_y):
        """Repeat the material's 2-d texture repeat_x by repeat_y times over the geom
        (not per unit length: texuniform is turned off, as mujoco-py did)."""
        repeats = [real(repeat_x, "repeat_x"), real(repeat_y, "repeat_y")]
        if min(repeats) <= 0:
            raise ValueError(f"texture repeats must be positive numbers, not "
                             f"({repeat_x!r}, {repeat_y!r})")
        material = self.get_mat_id(name)
        self.model.mat_texuniform[material] = 0
        self.model.mat_texrepeat[material] = repeats

    def rand_texrepeat(self, name, max_repeat=5):
        """Random whole repeats from 1 to max_repeat along each axis."""
        high = int(real(max_repeat, "max_repeat"))
        if high < 1:
            raise ValueError(f"max_repeat must be at least 1, not {max_repeat!r}")
        self.set_texrepeat(name, self.random_state.randint(0, high) + 1,
                           self.random_state.randint(0, high) + 1)

    def rand_specularity(self, name):
        self.set_specularity(name, 0.1 + 0.2 * self.random_state.uniform())

    def rand_shininess(self, name):
        self.set_shininess(name, 0.1 + 0.5 * self.random_state.uniform())

    def rand_reflectance(self, name):
        self.set_reflectance(name, 0.1 + 0.5 * self.random_state.uniform())

    def rand_all(self, name):
        """Random specularity, shininess and reflectance, drawn in that order."""
        self.rand_specularity(name)
        self.rand_shininess(name)
        self.rand_reflectance(name)

    def randomize(self):
        """rand_all for every named geom with a material."""
        model = self.model
        for geom in range(model.ngeom):
            name = model.geom(geom).name
            if name and int(model.geom_matid[geom]) >= 0:
                self.rand_all(name)


# ------------------------------------------------------------------ textures

_TYPES = {int(mjtTexture.mjTEXTURE_2D): "2d", int(mjtTexture.mjTEXTURE_CUBE): "cube",
          int(mjtTexture.mjTEXTURE_SKYBOX): "skybox"}
_RGB_ROLE = int(mjtTextureRole.mjTEXROLE_RGB)


class Texture:
    """One texture of a model: `id`, `type` ('2d', 'cube', 'skybox'), `width`, `height`,
    `nchannel`, `tex_adr`, and `bitmap`, its pixels as a live (height, width, nchannel)
    uint8 view of `model.tex_data` (`tex_rgb`)."""

    __slots__ = ("id", "type", "width", "height", "nchannel", "tex_adr", "_model")

    def __init__(self, model, tex_id):
        self.id, self._model = tex_id, model
        self.type = _TYPES.get(int(model.tex_type[tex_id]), str(model.tex_type[tex_id]))
        self.width, self.height = int(model.tex_width[tex_id]), int(model.tex_height[tex_id])
        self.nchannel = int(model.tex_nchannel[tex_id])
        self.tex_adr = int(model.tex_adr[tex_id])

    @property
    def tex_rgb(self):
        """All the model's texture bytes (mujoco-py's name for model.tex_data)."""
        return self._model.tex_data

    @property
    def bitmap(self):
        size = self.width * self.height * self.nchannel
        data = self._model.tex_data[self.tex_adr:self.tex_adr + size]
        return data.reshape(self.height, self.width, self.nchannel)

    def __repr__(self):
        return f"<Texture {self.id} ({self.type}) {self.width}x{self.height}x{self.nchannel}>"


def _checker_masks(height, width):
    """mujoco-py's two checker masks, (height, width, 1) of 0 and 1: the first is 1
    where row + column is odd, the second where it is even."""
    rows, columns = np.indices((height, width))
    odd = ((rows + columns) % 2).astype(np.uint8)[..., None]
    return odd, 1 - odd


class TextureModder(GeomModder):
    """Set or randomize the textures of geoms (by geom name, or 'skybox').

    `set_rgb`, `set_checker` (one-pixel checks), `set_gradient`, `set_noise`; `rand_*`
    pick the colours at random, drawing from `random_state` as mujoco-py did;
    `randomize()` does `rand_all` for every named textured geom and the skybox.  Each
    uploads the texture to the sim's render contexts and returns its bitmap.
    """

    def __init__(self, sim, random_state=None):
        super().__init__(sim, random_state)
        self.textures = [Texture(self.model, i) for i in range(self.model.ntex)]

    def get_texture(self, name):
        """The Texture of the geom `name`'s material, or the (last) skybox for 'skybox'."""
        if name == "skybox":
            skyboxes = [t for t in self.textures if t.type == "skybox"]
            if not skyboxes:
                raise ValueError("the model has no skybox texture")
            return skyboxes[-1]
        material = self.get_mat_id(name)
        tex_id = int(self.model.mat_texid[material][_RGB_ROLE])
        if tex_id < 0:
            raise ValueError(f"the material of geom {name!r} has no (rgb) texture")
        return self.textures[tex_id]

    def get_checker_matrices(self, name):
        """The two 0/1 masks, (height, width, 1), that set_checker weighs rgb1 and rgb2
        by, for the texture of `name`."""
        texture = self.get_texture(name)
        return _checker_masks(texture.height, texture.width)

    def _colour_texture(self, name):
        texture = self.get_texture(name)
        if texture.nchannel < 3:
            raise ValueError(f"the texture of {name!r} has {texture.nchannel} channel: only "
                             f"RGB and RGBA textures take colours")
        return texture

    def _paint(self, texture, colours):
        """Write `colours` (broadcast to height x width x 3, truncated to bytes) into the
        texture's RGB channels, leaving alpha; upload it; its bitmap."""
        bitmap = texture.bitmap
        bitmap[..., :3] = np.broadcast_to(colours, bitmap.shape[:2] + (3,)).astype(np.uint8)
        self._upload(texture)
        return bitmap

    def set_rgb(self, name, rgb):
        """The whole texture one colour."""
        return self._paint(self._colour_texture(name), colour(rgb, "rgb"))

    def set_checker(self, name, rgb1, rgb2):
        """A checkerboard of single pixels: rgb2 at the first pixel, as in mujoco-py."""
        rgb1, rgb2 = colour(rgb1, "rgb1"), colour(rgb2, "rgb2")
        texture = self._colour_texture(name)
        odd, even = _checker_masks(texture.height, texture.width)
        return self._paint(texture, rgb1 * odd + rgb2 * even)

    def set_gradient(self, name, rgb1, rgb2, vertical=True):
        """A linear blend from rgb1 to rgb2, down the rows (vertical) or along the
        columns (MuJoCo's own builtin gradient is a sigmoid; this is linear)."""
        rgb1, rgb2 = colour(rgb1, "rgb1"), colour(rgb2, "rgb2")
        texture = self._colour_texture(name)
        if vertical:
            p = np.linspace(0.0, 1.0, texture.height)[:, None, None]
        else:
            p = np.linspace(0.0, 1.0, texture.width)[None, :, None]
        return self._paint(texture, rgb2 * p + rgb1 * (1.0 - p))

    def set_noise(self, name, rgb1, rgb2, fraction=0.9):
        """rgb1, with a random `fraction` of the pixels rgb2."""
        rgb1, rgb2 = colour(rgb1, "rgb1"), colour(rgb2, "rgb2")
        fraction = unit(fraction, "fraction")
        texture = self._colour_texture(name)
        mask = self.random_state.uniform(size=(texture.height, texture.width)) < fraction
        return self._paint(texture, np.where(mask[..., None], rgb2, rgb1))

    def get_rand_rgb(self, n=1):
        """A random colour (uint8), or a tuple of `n` of them."""
        colours = tuple(np.array(self.random_state.uniform(size=3) * 255, dtype=np.uint8)
                        for _ in range(n))
        return colours[0] if n == 1 else colours

    def rand_checker(self, name):
        return self.set_checker(name, *self.get_rand_rgb(2))

    def rand_gradient(self, name):
        rgb1, rgb2 = self.get_rand_rgb(2)
        return self.set_gradient(name, rgb1, rgb2, vertical=bool(self.random_state.uniform() > 0.5))

    def rand_rgb(self, name):
        return self.set_rgb(name, self.get_rand_rgb())

    def rand_noise(self, name):
        fraction = 0.1 + self.random_state.uniform() * 0.8
        return self.set_noise(name, *self.get_rand_rgb(2), fraction=fraction)

    def rand_all(self, name):
        """One of rand_checker, rand_gradient, rand_rgb and rand_noise, at random."""
        choices = (self.rand_checker, self.rand_gradient, self.rand_rgb, self.rand_noise)
        return choices[self.random_state.randint(len(choices))](name)

    def randomize(self):
        """rand_all for every named geom whose material has an RGB(A) texture, in geom
        order, then for the skybox if there is one.  (mujoco-py's went through every
        geom name, and failed on a geom with no name or no textured material.)"""
        for name in self._textured_geoms():
            self.rand_all(name)
        if any(t.type == "skybox" and t.nchannel >= 3 for t in self.textures):
            self.rand_all("skybox")

    def _textured_geoms(self):
        model, names = self.model, []
        for geom in range(model.ngeom):
            material = int(model.geom_matid[geom])
            name = model.geom(geom).name
            tex_id = int(model.mat_texid[material][_RGB_ROLE]) if material >= 0 else -1
            if name and tex_id >= 0 and model.tex_nchannel[tex_id] >= 3:
                names.append(name)
        return names

    def upload_texture(self, name):
        """Send the texture of `name` to every render context of the sim."""
        self._upload(self.get_texture(name))

    def _upload(self, texture):
        for context in list(self.sim.render_contexts):
            context.upload_texture(texture.id)

    def whiten_materials(self, geom_names=None):
        """Material colours white (for the given geoms' materials, or all), so textures
        show their own colours."""
        if geom_names:
            materials = [self.get_mat_id(name) for name in geom_names]   # all checked first
            for material in materials:
                self.model.mat_rgba[material] = 1.0
        else:
            self.model.mat_rgba[:] = 1.0


# --------------------------------------------------------- lights and cameras

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
