"""Texture and material randomization, as mujoco-py's `modder` offered it.

`TextureModder(sim)` rewrites the pixels of a geom's texture in the model
(`model.tex_data`) and uploads them to every render context of the sim
(`mjr_uploadTexture`), so the next frame shows them; `MaterialModder(sim)`
sets a geom's material's specular, shininess and reflectance, which MuJoCo
reads from the model at every frame, so no upload is needed.  Geoms are named
by their names; 'skybox' names the skybox texture.  A render context made
later reads the textures from the model when it is made.

Colours are RGB triples of 0..255.  Texture edits act on the texture: geoms
sharing it all change.  `whiten_materials()` sets material colours to white,
so that textures show their own colours.
"""

import numpy as np

from .._enums import mjtObj, mjtTexture, mjtTextureRole
from .. import functions as _f

_TYPES = {int(mjtTexture.mjTEXTURE_2D): "2d", int(mjtTexture.mjTEXTURE_CUBE): "cube",
          int(mjtTexture.mjTEXTURE_SKYBOX): "skybox"}
_RGB_ROLE = int(mjtTextureRole.mjTEXROLE_RGB)


def _random_state(value):
    """mujoco-py's random_state: None (numpy's global state), a seed, or a RandomState."""
    if value is None:
        return np.random
    if isinstance(value, (int, np.integer)) and not isinstance(value, bool):
        return np.random.RandomState(int(value))
    if not callable(getattr(value, "uniform", None)):
        raise TypeError(f"random_state must be None, a seed or a numpy RandomState, not "
                        f"{type(value).__name__}")
    return value


def _colour(value, name):
    """An RGB triple of 0..255 as a uint8 array, or ValueError naming `name`."""
    array = np.asarray(value, dtype=np.float64)
    if array.shape != (3,) or not np.all(np.isfinite(array)) \
            or np.any((array < 0) | (array > 255)):
        raise ValueError(f"{name} must be three numbers from 0 to 255 (R, G, B), not {value!r}")
    return np.round(array).astype(np.uint8)


def _unit(value, name):
    value = float(value)
    if not 0.0 <= value <= 1.0:
        raise ValueError(f"{name} must be from 0 to 1, not {value}")
    return value


class _Modder:
    """What both modders share: the sim, its model, a random state, name lookups."""

    def __init__(self, sim, random_state=None):
        from ..sim import MjSim
        if not isinstance(sim, MjSim):
            raise TypeError(f"sim must be an MjSim, not {type(sim).__name__}")
        self.sim = sim
        self.random_state = _random_state(random_state)

    @property
    def model(self):
        return self.sim.model

    def _geom(self, name):
        if not isinstance(name, str):
            raise TypeError(f"a geom name must be a str, not {type(name).__name__}")
        geom = _f.mj_name2id(self.model, int(mjtObj.mjOBJ_GEOM), name) if name else -1
        if geom < 0:
            raise ValueError(f"the model has no geom named {name!r}")
        return geom

    def get_mat_id(self, name):
        """The material id of the geom `name`; ValueError if it has none."""
        material = int(self.model.geom_matid[self._geom(name)])
        if material < 0:
            raise ValueError(f"geom {name!r} has no material")
        return material


class Texture:
    """One texture of a model: `id`, `type` ('2d', 'cube', 'skybox'), `width`, `height`,
    `nchannel`, `tex_adr`, and `bitmap`, its pixels as a live (height, width, nchannel)
    uint8 view of `model.tex_data`."""

    __slots__ = ("id", "type", "width", "height", "nchannel", "tex_adr", "_model")

    def __init__(self, model, tex_id):
        self.id, self._model = tex_id, model
        self.type = _TYPES.get(int(model.tex_type[tex_id]), str(model.tex_type[tex_id]))
        self.width, self.height = int(model.tex_width[tex_id]), int(model.tex_height[tex_id])
        self.nchannel = int(model.tex_nchannel[tex_id])
        self.tex_adr = int(model.tex_adr[tex_id])

    @property
    def bitmap(self):
        size = self.width * self.height * self.nchannel
        data = self._model.tex_data[self.tex_adr:self.tex_adr + size]
        return data.reshape(self.height, self.width, self.nchannel)

    def __repr__(self):
        return f"<Texture {self.id} ({self.type}) {self.width}x{self.height}x{self.nchannel}>"


class TextureModder(_Modder):
    """Set or randomize the textures of geoms (by geom name, or 'skybox').

    `set_rgb`, `set_checker` (one-pixel checks), `set_gradient`, `set_noise`; `rand_*`
    pick the colours at random; `randomize()` does `rand_all` for every textured geom.
    Each uploads the texture to the sim's render contexts and returns its bitmap.
    """

    def __init__(self, sim, random_state=None):
        super().__init__(sim, random_state)
        self.textures = [Texture(self.model, i) for i in range(self.model.ntex)]

    def get_texture(self, name):
        """The Texture of the geom `name`'s material, or the skybox for 'skybox'."""
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

    def _bitmap(self, name):
        texture = self.get_texture(name)
        if texture.nchannel < 3:
            raise ValueError(f"the texture of {name!r} has {texture.nchannel} channel: only "
                             f"RGB and RGBA textures take colours")
        return texture, texture.bitmap

    def _paint(self, name, colours):
        """Write (height, width, 3) `colours` into the texture's RGB channels; upload."""
        texture, bitmap = self._bitmap(name)
        bitmap[..., :3] = colours
        self._upload(texture)
        return bitmap

    def set_rgb(self, name, rgb):
        """The whole texture one colour."""
        return self._paint(name, _colour(rgb, "rgb"))

    def set_checker(self, name, rgb1, rgb2):
        """A checkerboard of single pixels, rgb1 at the texture's first pixel."""
        rgb1, rgb2 = _colour(rgb1, "rgb1"), _colour(rgb2, "rgb2")
        texture, _ = self._bitmap(name)
        rows, columns = np.indices((texture.height, texture.width))
        first = ((rows + columns) % 2 == 0)[..., None]
        return self._paint(name, np.where(first, rgb1, rgb2))

    def set_gradient(self, name, rgb1, rgb2, vertical=True):
        """A linear blend from rgb1 to rgb2, along the rows (vertical) or the columns."""
        rgb1, rgb2 = _colour(rgb1, "rgb1"), _colour(rgb2, "rgb2")
        texture, _ = self._bitmap(name)
        steps = texture.height if vertical else texture.width
        t = np.linspace(0.0, 1.0, steps)[:, None, None] if vertical else \
            np.linspace(0.0, 1.0, steps)[None, :, None]
        blend = (1.0 - t) * rgb1 + t * rgb2
        return self._paint(name, np.broadcast_to(np.round(blend).astype(np.uint8),
                                                 (texture.height, texture.width, 3)))

    def set_noise(self, name, rgb1, rgb2, fraction=0.9):
        """rgb1, with a random `fraction` of the pixels rgb2."""
        rgb1, rgb2 = _colour(rgb1, "rgb1"), _colour(rgb2, "rgb2")
        fraction = _unit(fraction, "fraction")
        texture, _ = self._bitmap(name)
        mask = self.random_state.uniform(size=(texture.height, texture.width)) < fraction
        return self._paint(name, np.where(mask[..., None], rgb2, rgb1))

    def get_rand_rgb(self, n=1):
        """A random colour, or a tuple of `n` of them."""
        colours = tuple((self.random_state.uniform(size=3) * 255).astype(np.uint8)
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
        fraction = 0.1 + 0.8 * self.random_state.uniform()
        return self.set_noise(name, *self.get_rand_rgb(2), fraction=fraction)

    def rand_all(self, name):
        """One of rand_checker, rand_gradient, rand_rgb and rand_noise, at random."""
        choices = (self.rand_checker, self.rand_gradient, self.rand_rgb, self.rand_noise)
        return choices[self.random_state.randint(len(choices))](name)

    def randomize(self):
        """rand_all for every named geom with a texture, and for the skybox if any."""
        for name in self._textured_geoms():
            self.rand_all(name)
        if any(t.type == "skybox" for t in self.textures):
            self.rand_all("skybox")

    def _textured_geoms(self):
        model, names = self.model, []
        for geom in range(model.ngeom):
            material = int(model.geom_matid[geom])
            name = model.geom(geom).name
            if name and material >= 0 and int(model.mat_texid[material][_RGB_ROLE]) >= 0 \
                    and model.tex_nchannel[model.mat_texid[material][_RGB_ROLE]] >= 3:
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
            for name in geom_names:
                self.model.mat_rgba[self.get_mat_id(name)] = 1.0
        else:
            self.model.mat_rgba[:] = 1.0


class MaterialModder(_Modder):
    """Set or randomize a geom's material: specularity, shininess, reflectance (0..1),
    texture repeats (`set_texrepeat`) and colour (`set_rgba`; MuJoCo shows a material's
    colour on geoms that leave their own rgba at the default).  MuJoCo reads them at
    every frame: no upload is needed."""

    def set_specularity(self, name, value):
        self.model.mat_specular[self.get_mat_id(name)] = _unit(value, "specularity")

    def set_shininess(self, name, value):
        self.model.mat_shininess[self.get_mat_id(name)] = _unit(value, "shininess")

    def set_reflectance(self, name, value):
        self.model.mat_reflectance[self.get_mat_id(name)] = _unit(value, "reflectance")

    def set_rgba(self, name, rgba):
        """The material's colour, four numbers from 0 to 1."""
        array = np.asarray(rgba, dtype=np.float64)
        if array.shape != (4,) or not np.all((array >= 0) & (array <= 1)):
            raise ValueError(f"rgba must be four numbers from 0 to 1, not {rgba!r}")
        self.model.mat_rgba[self.get_mat_id(name)] = array

    def set_texrepeat(self, name, repeat_x, repeat_y):
        """Repeat the material's 2-d texture repeat_x by repeat_y times over the geom
        (not per unit length: texuniform is turned off, as mujoco-py did)."""
        repeats = np.array([float(repeat_x), float(repeat_y)])
        if not np.all(np.isfinite(repeats)) or np.any(repeats <= 0):
            raise ValueError(f"texture repeats must be positive numbers, not "
                             f"({repeat_x!r}, {repeat_y!r})")
        material = self.get_mat_id(name)
        self.model.mat_texuniform[material] = 0
        self.model.mat_texrepeat[material] = repeats

    def rand_texrepeat(self, name, max_repeat=5):
        """Random whole repeats from 1 to max_repeat along each axis."""
        high = int(max_repeat)
        if high < 1:
            raise ValueError(f"max_repeat must be at least 1, not {max_repeat!r}")
        self.set_texrepeat(name, self.random_state.randint(high) + 1,
                           self.random_state.randint(high) + 1)

    def rand_specularity(self, name):
        self.set_specularity(name, 0.1 + 0.2 * self.random_state.uniform())

    def rand_shininess(self, name):
        self.set_shininess(name, 0.1 + 0.5 * self.random_state.uniform())

    def rand_reflectance(self, name):
        self.set_reflectance(name, 0.1 + 0.5 * self.random_state.uniform())

    def rand_all(self, name):
        """Random specularity, shininess and reflectance."""
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

