"""`MjSpec.attach`: a child spec placed at a frame or site of its parent, as the
official binding does it.

Beyond mjs_attach, the official binding carries the child's `assets` dict into the
parent under the names the child's files take there (prefix before the base name,
suffix before the extension), renames the mesh and texture files of the child to
match, and records the parent as the child's `parent`.  A name already taken in
the parent's assets is refused (unless `override_assets`) before anything is
attached, so that a refused attach leaves both specs as they were.
"""

import warnings

from .._support import marshal as _m
from .._support.library import ffi, lib
from .._support import spec_kinds as kinds
from ..structs import mjspec as _mjspec
from .assets import attached_name

DEFAULT_PREFIX = "/"      # the official prefix when none is given


def attach_point(spec, site, frame):
    """The mjsElement * in `spec` to attach at: `site` or `frame`, an element or a
    name; exactly one of them."""
    if site is None and frame is None:
        raise ValueError("One of frame or site must be specified.")
    if site is not None and frame is not None:
        raise ValueError("Only one of frame or site can be specified.")
    kind, point = ("frame", frame) if frame is not None else ("site", site)
    if isinstance(point, str):
        point = spec._find(kinds.BY_LOOKUP[kind][2], point)
        if point is None:
            raise ValueError(f"{kind.capitalize()} not found.")
    expected = wrapper_class(kinds.BY_LOOKUP[kind][2])
    if not isinstance(point, expected):
        raise TypeError(f"{kind} must be an {expected.__name__} or its name, "
                        f"not {type(point).__name__}")
    return spec._element_pointer(point, kind, owner_message=(
        f"{kind.capitalize()} spec does not match parent spec."))


def renamed_assets(parent, child, prefix, suffix):
    """{name in the parent: content} of the child's assets; ValueError naming the
    first that is taken already, unless the parent overrides its assets."""
    renamed = {}
    for name, content in child.assets.items():
        new_name = attached_name(name, prefix, suffix)
        if new_name in parent.assets and not parent.override_assets:
            raise ValueError(f"Asset {name} already exists in parent spec.")
        renamed[new_name] = content
    return renamed


def _first(c_spec, type_):
    element = lib.mjcffi_guard_mjs_firstElement(c_spec, type_)
    _m.check_error()
    return element != ffi.NULL


def warn_mixed_assets(parent, child):
    """The official warnings (of class Warning, as official): a spec with an assets
    dict and one without, both with meshes or textures, may lose files when
    attached again."""
    types = (int(kinds.mjtObj.mjOBJ_MESH), int(kinds.mjtObj.mjOBJ_TEXTURE))
    child_files = any(_first(child._ptr, t) for t in types)
    parent_files = any(_first(parent._ptr, t) for t in types)
    if not child.assets and child_files and parent.assets:
        warnings.warn("Attaching a child without asset dict to a parent with an asset dict "
                      "might result in missing assets when attaching again.", Warning,
                      stacklevel=3)
    if not parent.assets and parent_files and child.assets:
        warnings.warn("Attaching a child with asset dict to a parent without an asset dict "
                      "might result in missing assets when attaching again.", Warning,
                      stacklevel=3)


def rename_files(child, prefix, suffix):
    """Rename the mesh and texture files of `child` as its assets are renamed."""
    for type_ in (kinds.mjtObj.mjOBJ_MESH, kinds.mjtObj.mjOBJ_TEXTURE):
        cast = getattr(lib, "mjs_as" + kinds.BY_TYPE[int(type_)][3])
        element = lib.mjcffi_guard_mjs_firstElement(child._ptr, type_)
        while element != ffi.NULL:
            file = cast(element).file
            name = _m.string(lib.mjs_getString(file))
            if name:
                lib.mjs_setString(file, _m.text(attached_name(name, prefix, suffix), "file"))
            element = lib.mjcffi_guard_mjs_nextElement(child._ptr, element)
        _m.check_error()


def wrapper_class(type_):
    """The generated struct class of an element kind (MjsBody, ...)."""
    return getattr(_mjspec, "Mjs" + kinds.BY_TYPE[int(type_)][3])
