"""mujoco-py's MaterialModder: a geom's material's specularity, shininess,
reflectance, texture repeats and colour.

MuJoCo reads materials from the model at every frame, so an edit shows in the
next frame with no upload.  Geoms are named by their names.
"""

from ._simmodderbase import BaseModder, numbers, real, unit


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
