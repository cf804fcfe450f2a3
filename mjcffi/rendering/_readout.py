"""Reading MuJoCo's offscreen framebuffer out as images, top row first.

OpenGL reads pixels bottom row first; a `Readout` reads them into buffers it
keeps for its size, then writes them flipped into the caller's array in one
pass.  Three kinds of image, as the official Renderer returns them:

- colour: (height, width, 3) uint8;
- depth: (height, width) float32 distances in metres, from the buffer's
  values (MuJoCo's reversed Z, mjDEPTH_ZEROFAR) by the inverse of the
  projection, in the official's arithmetic (float32 coefficients, float64
  division, float32 result), so that both give the same bits;
- segmentation: (height, width, 2) int32 (object id, object type) from the
  scene's geoms, whose ids MuJoCo's mjRND_IDCOLOR drew as colours (segid + 1,
  0 for the background, which maps to (-1, -1)).
"""

import numpy as np

from ..functions._overrides import mjr_readPixels
from .._support.library import ffi

# segid, objid and objtype of an mjvGeom, read straight from the scene's buffer
_GEOM = np.dtype({"names": ["segid", "objid", "objtype"],
                  "formats": [np.intc, np.intc, np.intc],
                  "offsets": [ffi.offsetof("mjvGeom", "segid"),
                              ffi.offsetof("mjvGeom", "objid"),
                              ffi.offsetof("mjvGeom", "objtype")],
                  "itemsize": ffi.sizeof("mjvGeom")})


def shape_of(mode, height, width):
    """The image shape of a mode: 'rgb', 'depth' or 'segmentation'."""
    if mode == "depth":
        return (height, width)
    return (height, width, 2 if mode == "segmentation" else 3)


DTYPES = {"rgb": np.dtype(np.uint8), "depth": np.dtype(np.float32),
          "segmentation": np.dtype(np.int32)}


class Readout:
    """Buffers for one image size, and the conversions from OpenGL's rows to images."""

    def __init__(self, height, width):
        self.height, self.width = height, width
        self.rgb = np.empty((height, width, 3), np.uint8)
        self._depth = None           # float32 raw depth, float64 work: made on first use
        self._wide = None
        self._padded = None          # rgb padded to 4 bytes a pixel, and its uint32 view
        self._ids = None
        self._table = None           # (maxgeom + 1, 2) int32: segid + 1 -> (objid, objtype)

    # ------------------------------------------------------------ colour

    def read_rgb(self, rect, con, out):
        """The colour image into `out`, a C-contiguous uint8 (h, w, 3) array."""
        mjr_readPixels(self.rgb, None, rect, con)
        np.copyto(out, self.rgb[::-1])

    # ------------------------------------------------------------ depth

    def read_depth(self, rect, con, out, model, orthographic):
        """Distances in metres into `out`, a C-contiguous float32 (h, w) array."""
        if self._depth is None:
            self._depth = np.empty((self.height, self.width), np.float32)
            self._wide = np.empty((self.height, self.width), np.float64)
        mjr_readPixels(None, self._depth, rect, con)
        extent = model.stat.extent
        znear = np.float32(model.vis.map.znear * extent)
        zfar = np.float32(model.vis.map.zfar * extent)
        wide = self._wide
        if orthographic:
            # glOrtho: depth is linear in distance
            np.multiply(self._depth, zfar - znear, out=wide, dtype=np.float64)
            np.subtract(zfar, wide, out=wide, dtype=np.float64)
        else:
            # glFrustum, in reversed Z: the window value is the NDC value, so
            # distance = d / (value + c) with MuJoCo's remapped coefficients
            c = -(zfar + znear) / (zfar - znear)
            d = -(np.float32(2) * zfar * znear) / (zfar - znear)
            c = np.float32(-0.5) * c - np.float32(0.5)
            d = np.float32(-0.5) * d
            np.add(self._depth, c, out=wide, dtype=np.float64)
            np.divide(d, wide, out=wide, dtype=np.float64)
        np.copyto(out, wide[::-1], casting="same_kind")

    # ------------------------------------------------------------ segmentation

    def read_segmentation(self, rect, con, out, scene):
        """(object id, object type) per pixel into `out`, a C-contiguous int32 (h, w, 2)."""
        if self._ids is None:
            self._padded = np.zeros((self.height, self.width, 4), np.uint8)
            # bytes r, g, b, 0 read as a little-endian uint32: r + 256 g + 65536 b
            self._ids = self._padded.view("<u4")[..., 0]
        mjr_readPixels(self.rgb, None, rect, con)
        self._padded[..., :3] = self.rgb
        table = self._segment_table(scene)
        # an id past the scene's geoms raises IndexError, as the official's indexing does
        np.take(table, self._ids[::-1], axis=0, out=out, mode="raise")

    def _segment_table(self, scene):
        """(ngeom + 1, 2) int32: row segid + 1 holds that geom's (objid, objtype);
        row 0, the background, and geoms without an id hold (-1, -1)."""
        c_scene = scene._ptr
        ngeom, maxgeom = c_scene.ngeom, c_scene.maxgeom
        if self._table is None or len(self._table) < maxgeom + 1:
            self._table = np.empty((maxgeom + 1, 2), np.int32)
        table = self._table[:ngeom + 1]
        table.fill(-1)
        if ngeom:
            geoms = np.frombuffer(ffi.buffer(c_scene.geoms, ngeom * _GEOM.itemsize), _GEOM)
            shown = geoms[geoms["segid"] != -1]
            table[shown["segid"] + 1, 0] = shown["objid"]
            table[shown["segid"] + 1, 1] = shown["objtype"]
        return table
