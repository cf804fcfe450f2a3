"""mujoco-py's TextureModder: rewrite the pixels of a geom's texture.

The pixels live in the model (`model.tex_data`); after an edit the texture is
uploaded to every render context of the sim (`mjr_uploadTexture`), so the next
frame shows it.  A render context made later reads the textures from the model
when it is made, so an edit with no render context yet needs no OpenGL.  Geoms
are named by their names; 'skybox' names the skybox texture.

Colours are RGB triples of 0..255, cast to bytes by truncation as mujoco-py's
array assignment did, so a seeded random state draws the same pixels as
mujoco-py.  Texture edits act on the texture: geoms sharing it all change.
`whiten_materials()` sets material colours to white, so that textures show
their own colours rather than a blend with the material's.
"""

import numpy as np

from .._enums import mjtTexture, mjtTextureRole
from ._simmatmodder import GeomModder
from ._simmodderbase import colour, unit

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
