"""`UserOverlays`: the figures, texts and images a caller lays over the passive viewer.

`Handle.set_figures`, `set_texts` and `set_images` check their arguments on the
caller's thread and hand the viewer copies (the official handle copies them too:
later edits of the caller's figure or image do not show until the next set_*).
Each set_* replaces that kind's whole list; clear_* empties it.  The render thread
draws the lists after the scene, the panels and the viewer's own text, every frame
until they are cleared:

- figures with mjr_figure, each in its viewport (window pixels, from the bottom left);
- texts with mjr_overlay, placed by their gridpos in the 3D view;
- images with mjr_drawPixels, each filling its viewport.

Each list is a tuple replaced whole, so the render thread, which reads each list
once a frame, never sees one half set and needs no lock.  Should drawing one kind
raise anyway, it is reported once and that kind is cleared.
"""

import copy
import operator

import numpy as np

from .._functions import mjr_figure, mjr_overlay, mjr_rectangle
from ..functions._overrides import mjr_drawPixels
from .._generated.enums import mjtFontScale, mjtGridPos
from .._support import marshal as _marshal
from .._support import mjr as _mjr
from ..structs import MjrRect, MjvFigure
from ._window import report

# the official handle's defaults for a None font or gridpos (its font default is a
# font *scale*, 150, which MuJoCo draws as mjFONT_NORMAL: any font but 1 and 2 is)
DEFAULT_FONT = mjtFontScale.mjFONTSCALE_150
DEFAULT_GRIDPOS = mjtGridPos.mjGRID_TOPLEFT
_INT_MIN, _INT_MAX = -2**31, 2**31 - 1


def _entries(value, what, name):
    """A single tuple as a list of one; any other iterable as a list (the official)."""
    if isinstance(value, tuple):
        return [value]
    if isinstance(value, (str, bytes)):
        raise TypeError(f"{name}() takes a tuple {what} or a list of them, "
                        f"not {type(value).__name__}")
    try:
        return list(value)
    except TypeError:
        raise TypeError(f"{name}() takes a tuple {what} or a list of them, "
                        f"not {type(value).__name__}") from None


def _pair(entry, index, what, name):
    try:
        first, second = entry
    except (TypeError, ValueError):
        raise TypeError(f"{name}(): entry {index} must be a pair {what}, "
                        f"got {entry!r:.80}") from None
    return first, second


def _rect(viewport, where):
    """A copy of an MjrRect, checked as mjcffi's mjr_* functions check one."""
    if not isinstance(viewport, MjrRect):
        raise TypeError(f"{where}: the viewport must be an mjcffi.MjrRect, "
                        f"not {type(viewport).__name__}")
    rect = MjrRect(viewport.left, viewport.bottom, viewport.width, viewport.height)
    _mjr.rect_fits(rect, where)
    return rect


def _c_int(value, what, where):
    try:
        number = operator.index(value)
    except TypeError:
        raise TypeError(f"{where}: {what} must be an int, not {type(value).__name__}") from None
    if not _INT_MIN <= number <= _INT_MAX:
        raise ValueError(f"{where}: {what}={number} does not fit in a C int")
    return number


def check_figures(viewports_figures):
    """[(MjrRect, MjvFigure copy)] from a (viewport, figure) pair or a list of them."""
    name, what = "set_figures", "(viewport: MjrRect, figure: MjvFigure)"
    checked = []
    for index, entry in enumerate(_entries(viewports_figures, what, name)):
        viewport, figure = _pair(entry, index, what, name)
        where = f"{name}(): entry {index}"
        rect = _rect(viewport, where)
        if not isinstance(figure, MjvFigure):
            raise TypeError(f"{where}: the figure must be an mjcffi.MjvFigure, "
                            f"not {type(figure).__name__}")
        figure = copy.copy(figure)
        # what mjr_figure itself refuses, refused now rather than at every frame
        _mjr.figure_fields(figure._ptr, f"{where}: figure")
        checked.append((rect, figure))
    return tuple(checked)


def _text(value, what, where):
    """None as '' (the official); str or bytes as ASCII bytes mjr_overlay can draw."""
    if value is None:
        return b""
    raw = _marshal.text(value, f"{where}: {what}")
    _mjr.overlay_text(raw, f"{where}: {what}")
    return raw


def check_texts(texts):
    """[(font, gridpos, text1, text2)] from one such tuple or a list of them."""
    name = "set_texts"
    checked = []
    for index, entry in enumerate(_entries(texts, "(font, gridpos, text1, text2)", name)):
        where = f"{name}(): entry {index}"
        try:
            font, gridpos, text1, text2 = entry
        except TypeError:
            raise TypeError(f"{where} must be a tuple (font, gridpos, text1, text2), "
                            f"not {type(entry).__name__}") from None
        except ValueError:
            raise ValueError(f"{where} must have 4 values (font, gridpos, text1, text2), "
                             f"got {entry!r:.80}") from None
        font = DEFAULT_FONT if font is None else _c_int(font, "font", where)
        gridpos = DEFAULT_GRIDPOS if gridpos is None else _c_int(gridpos, "gridpos", where)
        checked.append((int(font), int(gridpos), _text(text1, "text1", where),
                        _text(text2, "text2", where)))
    return tuple(checked)


def check_images(viewports_images):
    """[(MjrRect, bottom-row-first uint8 copy)] from a (viewport, image) pair or a list."""
    name, what = "set_images", "(viewport: MjrRect, image: (height, width, 3) uint8 array)"
    checked = []
    for index, entry in enumerate(_entries(viewports_images, what, name)):
        viewport, image = _pair(entry, index, what, name)
        where = f"{name}(): entry {index}"
        rect = _rect(viewport, where)
        if not isinstance(image, np.ndarray):
            raise TypeError(f"{where}: the image must be a NumPy array of shape "
                            f"(height, width, 3), not {type(image).__name__}")
        target = (rect.height, rect.width)
        if image.shape[:2] != target:
            raise ValueError(f"{where}: image shape {image.shape[:2]} does not match the "
                             f"viewport's (height, width) {target}")
        if image.ndim != 3:
            raise ValueError(f"{where}: the image must have 3 dimensions (height, width, "
                             f"3), got shape {image.shape}")
        if image.shape[2] != 3:
            raise ValueError(f"{where}: the image must have 3 channels (RGB), "
                             f"got {image.shape[2]}")
        if image.dtype.itemsize != 1 or image.dtype.kind not in "uib":
            raise ValueError(f"{where}: the image must be uint8, not {image.dtype}")
        # OpenGL draws rows from the bottom; the caller's image starts at its top row
        pixels = np.ascontiguousarray(image[::-1]).view(np.uint8)
        checked.append((rect, pixels))
    return tuple(checked)


class UserOverlays:
    """The caller's figures, texts and images, drawn by `draw` each frame."""

    KINDS = ("figures", "texts", "images")

    def __init__(self):
        self.figures = self.texts = self.images = ()

    def draw(self, view, con):
        """Draw them all: texts in `view` (the 3D view), the others where they were set."""
        self._draw("figures", lambda rect, figure: mjr_figure(rect, figure, con))
        self._draw("texts", lambda font, gridpos, text1, text2:
                   mjr_overlay(font, gridpos, view, text1, text2, con))
        if self.images:
            # glDrawPixels passes the depth test, and MuJoCo's depth is reversed: after
            # mjr_render alone the pixels would be hidden.  mjr_rectangle sets MuJoCo's 2D
            # state (no depth test) first; its rectangle, transparent, changes nothing.
            mjr_rectangle(MjrRect(0, 0, 1, 1), 0.0, 0.0, 0.0, 0.0)
        self._draw("images", lambda rect, pixels: mjr_drawPixels(pixels, None, rect, con))

    def _draw(self, kind, draw_one):
        entries = getattr(self, kind)
        try:
            for entry in entries:
                draw_one(*entry)
        except Exception:             # noqa: BLE001  (reported once; the viewer goes on)
            report(f"drawing the {kind} of set_{kind}(); they are cleared")
            if getattr(self, kind) is entries:
                setattr(self, kind, ())
