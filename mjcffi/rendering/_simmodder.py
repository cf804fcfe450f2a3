"""mujoco-py's modders, for domain randomization between frames.

`TextureModder` rewrites a geom's texture pixels (_simtexmodder),
`MaterialModder` a geom's material (_simmatmodder), `LightModder` and
`CameraModder` a named light or camera (_simlightcammodder); what they share
(the sim, the random state, name lookups, value checks) is in _simmodderbase.
Each takes `(sim, random_state=None)`: None for a fresh random state, a seed,
or a numpy RandomState, so that a seeded run is reproducible.
"""

from ._simlightcammodder import CameraModder, LightModder
from ._simmatmodder import MaterialModder
from ._simmodderbase import BaseModder
from ._simtexmodder import Texture, TextureModder

__all__ = ["TextureModder", "MaterialModder", "LightModder", "CameraModder", "Texture",
           "BaseModder"]
