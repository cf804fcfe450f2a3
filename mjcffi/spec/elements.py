"""Hand-written methods of spec elements: tree traversal, frames, attach_body,
make_flex and the built-in meshes, sensor sizes and tendon paths.

Each class here subclasses the generated one in structs/mjspec.py (same name) and
registers itself, so that every wrapper a spec hands out is of the subclass.  The
methods follow the official bindings (mujoco/_specs); beyond them, a body has
`children()` (its direct child bodies) and `subtree()` (itself and every body below
it, depth first, in the order of the compiled model's body ids).

Every argument that is an element is checked before MuJoCo sees it: the wrong
class is a TypeError, an element that was deleted or that belongs to another spec a
ValueError; MuJoCo's own refusals (its spec error) come back as ValueError.

Attaching moves elements from one spec into another without copying.  Their
wrappers then move into the registry of the spec that holds them (so that
`parent.body('child-b') is b`, and deleting from the parent ends them), and the
parent keeps the child's memory alive for as long as it lives (MuJoCo counts the
references too; this only makes it independent of that).
"""

import builtins
import operator
import weakref

import numpy as np

from .._support import marshal as _marshal
from .._generated.enums import mjtMeshBuiltin, mjtObj, mjtWrap
from .._support.library import ffi, lib
from .._support.views import int_argument
from .._support import elements as _elements
from ..structs import mjspec as _generated
from . import lifetime

NULL = ffi.NULL

# The element kinds a body holds, in the order of the official error message.
TREE_KINDS = {
    "body": mjtObj.mjOBJ_BODY, "frame": mjtObj.mjOBJ_FRAME, "geom": mjtObj.mjOBJ_GEOM,
    "site": mjtObj.mjOBJ_SITE, "joint": mjtObj.mjOBJ_JOINT, "light": mjtObj.mjOBJ_LIGHT,
    "camera": mjtObj.mjOBJ_CAMERA,
}
_PLURALS = {"body": "bodies", "frame": "frames", "geom": "geoms", "site": "sites",
            "joint": "joints", "light": "lights", "camera": "cameras"}


# ---------------------------------------------------------------- arguments

def _where(self, method):
    return f"{type(self).__name__}.{method}"


def _element(value, cls, where, name):
    """The C pointer (mjsBody *, ...) of `value`, a live element wrapper of `cls`."""
    if isinstance(value, _elements.DeletedElement):
        raise ValueError(f"{where}: {name} was deleted from its spec and cannot be used")
    if not isinstance(value, cls):
        raise TypeError(f"{where}: {name} must be an {cls.__name__}, "
                        f"not {type(value).__name__}")
    return value._ptr


def _spec_of(pointer):
    """The mjSpec * that holds element `pointer` (a typed mjs* pointer) now."""
    return lib.mjs_getSpec(pointer.element)


def _held_spec(pointer, where):
    """The mjSpec * that holds element `pointer`: ValueError for a struct of an
    element class that no spec holds (a default class's template, default.geom),
    where MuJoCo would read the spec it has not and crash."""
    if lib.mjs_getCompiler(pointer.element) == NULL:
        raise ValueError(f"{where}: the element is not attached to a spec (it is a "
                         f"default class's template, such as default.geom)")
    return lib.mjs_getSpec(pointer.element)


def _same_spec(self, pointer, where, name):
    if _spec_of(pointer) != _spec_of(self._ptr):
        raise ValueError(f"{where}: {name} belongs to another spec")


def _text(value, where, name):
    """`value` (str, or None for '') as bytes for MuJoCo."""
    return _marshal.text("" if value is None else value, f"{where}: {name}")


def _opt_text(value, where, name):
    return NULL if value is None else _marshal.text(value, f"{where}: {name}")


def _integer(value, where, name):
    """`value` as a C int: an int (not a bool) within its range (int_argument)."""
    if isinstance(value, bool):
        raise TypeError(f"{where}: {name} must be an int, not bool")
    return int_argument(value, f"{where}: {name}", "int")


def _number(value, where, name):
    if isinstance(value, (str, bytes)) or value is None:
        raise TypeError(f"{where}: {name} must be a number, not {type(value).__name__}")
    try:
        return float(value)
    except (TypeError, ValueError):
        raise TypeError(f"{where}: {name} must be a number, "
                        f"not {type(value).__name__}") from None


def _numbers(value, size, dtype, where, name):
    """`value`, a sequence of `size` numbers, as a C array (ints for dtype int)."""
    if isinstance(value, (str, bytes)) or not hasattr(value, "__len__"):
        raise TypeError(f"{where}: {name} must be a sequence of {size} numbers, "
                        f"not {type(value).__name__}")
    try:
        raw = np.asarray(value)
        # complex would lose its imaginary part, bools are no ints (as _integer)
        if raw.dtype.kind == "c" or (dtype == "int" and raw.dtype.kind == "b"):
            raise TypeError
        array = np.asarray(raw, dtype=float)
    except (TypeError, ValueError):
        raise TypeError(f"{where}: {name} must be a sequence of {size} real numbers"
                        + (" (ints)" if dtype == "int" else "")) from None
    if array.shape != (size,):
        raise ValueError(f"{where}: {name} must have {size} elements, got shape "
                         f"{array.shape}")
    if dtype == "int":
        if not (np.all(np.isfinite(array)) and np.all(array == np.round(array))):
            raise TypeError(f"{where}: {name} must hold ints")
        return ffi.new("int[]", [_integer(int(v), where, name) for v in array])
    return ffi.new("double[]", array.tolist())


def _opt_numbers(value, size, dtype, where, name):
    return NULL if value is None else _numbers(value, size, dtype, where, name)


def _spec_error(pointer, what):
    """ValueError with MuJoCo's error of the spec holding element `pointer`."""
    message = _marshal.string(lib.mjs_getError(_spec_of(pointer)))
    return ValueError(message or f"{what} failed")


# ----------------------------------------------------------------- wrappers

# spec address -> its root (the gc'd mjSpec * every wrapper keeps alive); filled in
# by attach, after which a wrapper's own root may be another spec's
_ROOTS: weakref.WeakValueDictionary = weakref.WeakValueDictionary()
# parent spec root -> the roots of the specs attached to it, kept alive with it
_KEPT: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


_ELEMENT = ffi.typeof("mjsElement *")


def _address(pointer):
    return int(ffi.cast("uintptr_t", pointer))


def _wrap(self, pointer):
    """The one wrapper of element `pointer` (None for NULL), found from `self`."""
    return _wrap_in(self._root, pointer)


def _wrap_in(root, pointer):
    """The one wrapper of element `pointer` (None for NULL), registered with the spec
    that holds it now: `root`'s, or after an attach, the parent's."""
    if pointer == NULL:
        return None
    element = pointer if ffi.typeof(pointer) is _ELEMENT else pointer.element
    if element.elemtype != mjtObj.mjOBJ_DEFAULT:      # mjs_getSpec means nothing there
        spec = _address(lib.mjs_getSpec(element))
        if spec != _address(root):
            root = _ROOTS.get(spec, root)
    return _elements.wrap(pointer, root)


def _children(self, kind, recurse):
    """The elements of `kind` ('geom') in this body, or in its subtree if `recurse`."""
    body, type_ = self._ptr, TREE_KINDS[kind]
    found, element = [], lib.mjcffi_guard_mjs_firstChild(body, type_, recurse)
    _marshal.check_error()
    while element != NULL:
        found.append(_wrap(self, element))
        element = lib.mjcffi_guard_mjs_nextChild(body, element, recurse)
        _marshal.check_error()
    return found


def _rehome(child_root, parent_root):
    """After an attach: the wrappers of elements that moved from the child spec into
    the parent go over to the parent's registry, and the two specs keep each other
    alive (the moved elements point into both; see lifetime._Release).  A root
    lifetime did not make (a spec from a raw function) is kept by the parent only."""
    parent = _address(parent_root)
    _ROOTS[parent] = parent_root
    if _address(child_root) == parent:
        return
    if not lifetime.keep_together(parent_root, child_root):
        _KEPT.setdefault(parent_root, {})[_address(child_root)] = child_root
    source, target = _elements._registry(child_root), _elements._registry(parent_root)
    for key, wrapper in list(source.items()):
        if _address(lib.mjs_getSpec(wrapper._ptr.element)) == parent:
            del source[key]
            target[key] = wrapper
            # what it hands out from now on (add_geom, ...) is the parent's too
            wrapper.__dict__["_root"] = parent_root


# ----------------------------------------------------------------- mixins

class _Element:
    """What every element has: its compilation signature, id and compiler."""

    @property
    def signature(self):
        """The compilation signature of the spec holding the element: the `signature`
        of the model it last compiled to, 0 once an element was added since.  (MuJoCo
        keeps it on the spec's mjsElement; an element's own field is not kept.)"""
        return _held_spec(self._ptr, _where(self, "signature")).element.signature

    @property
    def id(self):
        """The element's id in the last compiled model, -1 before it is compiled."""
        value = lib.mjcffi_guard_mjs_getId(self._ptr.element)
        _marshal.check_error()
        return value

    @property
    def compiler(self):
        """The compiler options of the spec the element was defined in."""
        pointer = lib.mjcffi_guard_mjs_getCompiler(self._ptr.element)
        _marshal.check_error()
        if pointer == NULL:
            raise ValueError(f"{_where(self, 'compiler')}: Element is not attached to a "
                             f"spec.")
        return _generated.MjsCompiler._wrap(pointer, self._root)


class _Classed:
    """An element that takes defaults: its default class."""

    @property
    def classname(self):
        """The default class (MjsDefault) of the element; assign an MjsDefault of the
        same spec to change it."""
        _held_spec(self._ptr, _where(self, "classname"))
        pointer = lib.mjcffi_guard_mjs_getDefault(self._ptr.element)
        _marshal.check_error()
        return _wrap(self, pointer)

    @classname.setter
    def classname(self, default):
        where = _where(self, "classname")
        pointer = _element(default, _generated.MjsDefault, where, "the default")
        # a default's spec is found by its name (mjs_getSpec does not serve defaults)
        name = lib.mjs_getString(lib.mjs_getName(pointer.element))
        if lib.mjs_findDefault(_held_spec(self._ptr, where), name) != pointer:
            raise ValueError(f"{where}: the default belongs to another spec")
        lib.mjcffi_guard_mjs_setDefault(self._ptr.element, pointer)
        _marshal.check_error()


class _InTree:
    """An element in the kinematic tree: its body and its frame."""

    @property
    def parent(self):
        """The body that holds the element (None for the world body)."""
        pointer = lib.mjcffi_guard_mjs_getParent(self._ptr.element)
        _marshal.check_error()
        return _wrap(self, pointer)

    @property
    def frame(self):
        """The frame the element is placed in, or None."""
        pointer = lib.mjcffi_guard_mjs_getFrame(self._ptr.element)
        _marshal.check_error()
        return _wrap(self, pointer)

    def set_frame(self, frame):
        """Place the element in `frame`, an MjsFrame of the same body."""
        where = _where(self, "set_frame")
        pointer = _element(frame, _generated.MjsFrame, where, "frame")
        _same_spec(self, pointer, where, "frame")
        if _encloses(self._ptr.element, pointer):
            raise ValueError(f"{where}: a frame cannot be placed in itself or in a frame "
                             f"inside it")
        status = lib.mjcffi_guard_mjs_setFrame(self._ptr.element, pointer)
        _marshal.check_error()
        if status != 0:
            raise _spec_error(self._ptr, "mjs_setFrame")


def _encloses(element, frame):
    """Whether `frame` (an mjsFrame *) is `element` or lies inside it: placing the
    element in it would close a loop of frames, which MuJoCo takes and then
    recurses on without end when it compiles."""
    current = frame.element
    while current != NULL:
        if current == element:
            return True
        current = lib.mjcffi_guard_mjs_getFrame(current)
        _marshal.check_error()
        current = NULL if current == NULL else current.element
    return False


def _attach(self, child, cls, where, prefix, suffix):
    """Attach element `child` (of `cls`, usually of another spec) to `self`, with
    `prefix` and `suffix` added to the names it brings; the attached element."""
    pointer = _element(child, cls, where, type(child).__name__[3:].lower()
                       if isinstance(child, cls) else "child")
    _held_spec(self._ptr, where)
    held = _held_spec(pointer, where)
    # one attached by reference before is listed by the spec it came from still,
    # whose wrappers MuJoCo then moves half-way, or through the spec it moved to
    # (compared first: that one may be freed, which the wrapper does not prevent)
    if _address(held) != _address(child._root) or held != lib.mjs_getOriginSpec(
            pointer.element):
        raise ValueError(f"{where}: this {type(child).__name__[3:].lower()} was attached "
                         f"before (moved, not copied, into a spec): it cannot be attached "
                         f"again.  To attach copies, set copy_during_attach on the "
                         f"receiving spec before the first attach, or attach from a "
                         f"copy() of the spec it came from")
    result = lib.mjcffi_guard_mjs_attach(self._ptr.element, pointer.element,
                                         _text(prefix, where, "prefix"),
                                         _text(suffix, where, "suffix"))
    _marshal.check_error()
    if result == NULL:
        raise _spec_error(self._ptr, "mjs_attach")
    _rehome(child._root, self._root)
    if result == pointer.element:
        return child               # attached by reference: the same element
    return _wrap(self, result)     # a copy (deep copy on, or a world body)


# ----------------------------------------------------------------- bodies

def _first(kind):
    def first(self):
        element = lib.mjcffi_guard_mjs_firstChild(self._ptr, TREE_KINDS[kind], 0)
        _marshal.check_error()
        return _wrap(self, element)
    first.__name__ = f"first_{kind}"
    first.__doc__ = f"The body's first {kind} (direct child), or None."
    return first


def _next(kind):
    cls = getattr(_generated, "Mjs" + kind.capitalize())

    def next_(self, child):
        where = _where(self, f"next_{kind}")
        pointer = _element(child, cls, where, kind)
        _same_spec(self, pointer, where, kind)
        element = lib.mjcffi_guard_mjs_nextChild(self._ptr, pointer.element, 0)
        _marshal.check_error()
        return _wrap(self, element)
    next_.__name__ = f"next_{kind}"
    next_.__doc__ = (f"The {kind} after `{kind}` among the body's direct children, or None "
                     f"(also when `{kind}` is not a child of this body).")
    return next_


def _direct(kind):
    def elements(self):
        return _children(self, kind, False)
    elements.__name__ = _PLURALS[kind]
    return property(elements, doc=f"The body's direct child {_PLURALS[kind]}, in order.")


class MjsBody(_InTree, _Classed, _Element, _generated.MjsBody):
    """mjsBody: body specification, with tree traversal (first_geom/next_geom, the
    `geoms`, `bodies`, ... lists, find_all, children, subtree) and editing (to_frame,
    attach_frame, make_flex)."""

    def find_all(self, type):
        """Every element of `type` in the body's subtree (the body itself excluded),
        body by body, depth first.  `type` is an mjtObj or its name: one of body,
        frame, geom, site, joint, light, camera."""
        if isinstance(type, str):
            kind = type if type in TREE_KINDS else None
        elif isinstance(type, mjtObj):
            kind = next((k for k, v in TREE_KINDS.items() if v == type), None)
        else:
            raise TypeError(f"MjsBody.find_all takes an mjtObj or str, "
                            f"not {builtins.type(type).__name__}")
        if kind is None:
            raise ValueError("body.find_all supports the types: "
                             + ", ".join(TREE_KINDS) + ".")
        return _children(self, kind, True)

    def find_child(self, name):
        """The body named `name` in this body's subtree, or None."""
        pointer = lib.mjcffi_guard_mjs_findChild(
            self._ptr, _marshal.text(name, "MjsBody.find_child: name"))
        _marshal.check_error()
        return _wrap(self, pointer)

    def children(self):
        """The body's direct child bodies, in order (the `bodies` list)."""
        return _children(self, "body", False)

    def subtree(self):
        """This body and every body below it, depth first: the order of body ids in
        the compiled model.  A list made now: editing the tree later does not change
        it (wrappers of bodies deleted later raise when used)."""
        return [self] + _children(self, "body", True)

    def to_frame(self):
        """Turn this body into a frame of its parent, holding its children; returns the
        frame.  The body is freed: this wrapper cannot be used afterwards."""
        where = _where(self, "to_frame")
        if lib.mjs_getParent(self._ptr.element) == NULL:
            raise ValueError(f"{where}: the world body cannot be converted to a frame")
        # MuJoCo frees the body (its children move to the frame): refused while NumPy
        # views of it are held, and its wrapper is ended first
        _elements.check_releasable([self], "convert a body to a frame")
        handle, root = ffi.new("mjsBody **", self._ptr), self._root
        _elements.invalidate([self])
        frame = lib.mjcffi_guard_mjs_bodyToFrame(handle)
        _marshal.check_error()
        if frame == NULL:
            raise _spec_error(handle[0], "mjs_bodyToFrame")
        return _wrap_in(root, frame)

    def attach_frame(self, frame, prefix=None, suffix=None):
        """Attach `frame` (an MjsFrame of another spec, with everything in it) to this
        body; its names get `prefix` and `suffix`.  Returns the attached frame: `frame`
        itself (its elements move into this spec), or a copy if the spec copies
        during attach."""
        return _attach(self, frame, _generated.MjsFrame, _where(self, "attach_frame"),
                       prefix, suffix)

    def make_flex(self, name, type=None, dim=3, dof=None, count=None, cellcount=None,
                  spacing=None, scale=None, radius=0.0, mass=1.0, inertiabox=0.005,
                  equality=0, rigid=0, flatskin=0, elastic2d=0, pos=None, quat=None,
                  origin=None, file=None, mesh=None, vfs=None):
        """Add a flexcomp to this body (it must have a name): a flex with the bodies and
        joints it needs, as <flexcomp> in MJCF; returns the MjsFlex.  `type` (grid, box,
        cylinder, ellipsoid, disc, circle, mesh, gmsh, direct), `dof`, and the numbers
        follow the flexcomp attributes; `mesh` names a mesh asset of the spec to take
        the points from, `file` a file (read through `vfs`, an MjVfs), not both."""
        where = _where(self, "make_flex")
        if mesh is not None and file is not None:
            raise ValueError(f"{where}: both 'file' and 'mesh' specified")
        if mesh is not None:
            text = _marshal.text(mesh, f"{where}: mesh")
            found = lib.mjcffi_guard_mjs_findElement(_spec_of(self._ptr), mjtObj.mjOBJ_MESH,
                                                     text)
            _marshal.check_error()
            if found == NULL:
                raise ValueError(f"{where}: mesh '{mesh}' not found")
            file = mesh         # MuJoCo takes a mesh asset's name where a file goes
        args = (
            _marshal.text(name, f"{where}: name"), _opt_text(type, where, "type"),
            _integer(dim, where, "dim"), _opt_text(dof, where, "dof"),
            _opt_numbers(count, 3, "int", where, "count"),
            _opt_numbers(cellcount, 3, "int", where, "cellcount"),
            _opt_numbers(spacing, 3, "double", where, "spacing"),
            _opt_numbers(scale, 3, "double", where, "scale"),
            _number(radius, where, "radius"), _number(mass, where, "mass"),
            _number(inertiabox, where, "inertiabox"), _integer(equality, where, "equality"),
            _integer(rigid, where, "rigid"), _integer(flatskin, where, "flatskin"),
            _integer(elastic2d, where, "elastic2d"),
            _opt_numbers(pos, 3, "double", where, "pos"),
            _opt_numbers(quat, 4, "double", where, "quat"),
            _opt_numbers(origin, 3, "double", where, "origin"),
            _opt_text(file, where, "file"), _marshal.opt_struct(vfs, "mjVFS", "vfs"))
        flex = lib.mjcffi_guard_mjs_makeFlex(self._ptr, *args)
        _marshal.check_error()
        if flex == NULL:
            raise _spec_error(self._ptr, "mjs_makeFlex")
        return _wrap(self, flex)


for _kind in TREE_KINDS:
    setattr(MjsBody, f"first_{_kind}", _first(_kind))
    setattr(MjsBody, f"next_{_kind}", _next(_kind))
    setattr(MjsBody, _PLURALS[_kind], _direct(_kind))


# ---------------------------------------------------- frames and sites

class MjsFrame(_InTree, _Element, _generated.MjsFrame):
    """mjsFrame: frame specification, with attach_body."""

    def attach_body(self, body, prefix=None, suffix=None):
        """Attach `body` (an MjsBody of another spec, with its subtree) in this frame;
        its names get `prefix` and `suffix`.  Returns the attached body: `body` itself
        (its elements move into this spec, and so do their wrappers), or a copy if
        the spec copies during attach."""
        return _attach(self, body, _generated.MjsBody, _where(self, "attach_body"),
                       prefix, suffix)


class MjsSite(_InTree, _Classed, _Element, _generated.MjsSite):
    """mjsSite: site specification, with attach_body."""

    def attach_body(self, body, prefix=None, suffix=None):
        """Attach `body` (an MjsBody of another spec, with its subtree) at this site;
        its names get `prefix` and `suffix`.  Returns the attached body, as
        MjsFrame.attach_body."""
        return _attach(self, body, _generated.MjsBody, _where(self, "attach_body"),
                       prefix, suffix)


class MjsGeom(_InTree, _Classed, _Element, _generated.MjsGeom):
    """mjsGeom: geom specification."""


class MjsJoint(_InTree, _Classed, _Element, _generated.MjsJoint):
    """mjsJoint: joint specification."""


class MjsCamera(_InTree, _Classed, _Element, _generated.MjsCamera):
    """mjsCamera: camera specification."""


class MjsLight(_InTree, _Classed, _Element, _generated.MjsLight):
    """mjsLight: light specification."""


# ----------------------------------------------------------------- meshes

# What a built-in shape writes: a refused one may have written some of it already.
_MESH_DATA = ("uservert", "usernormal", "usertexcoord", "userface", "userfacenormal",
              "userfacetexcoord", "usernode", "usertet")


def _builtin(mesh, builtin, params, where):
    """Fill `mesh` with MuJoCo's built-in shape `builtin` made from `params`; if
    MuJoCo refuses them, the mesh keeps the data it had."""
    _held_spec(mesh._ptr, where)        # MuJoCo reports a refusal through the spec
    values = ffi.new("double[]", [float(p) for p in params])
    before = {name: np.array(getattr(mesh, name)) for name in _MESH_DATA}
    status = lib.mjcffi_guard_mjs_makeMesh(mesh._ptr, builtin, values, len(params))
    _marshal.check_error()
    if status != 0:
        error = _spec_error(mesh._ptr, where)
        for name, data in before.items():
            if not np.array_equal(np.array(getattr(mesh, name)), data):
                setattr(mesh, name, data)
        raise error


def _pair(value, dtype, where, name):
    return list(_numbers(value, 2, dtype, where, name))


def _lattice(self, method, builtin, count, spacing, dim=None):
    """A make_* of the grid family: count[3], spacing[3] and, for some, dim."""
    where = _where(self, method)
    for value, name in ((count, "count"), (spacing, "spacing")):
        if isinstance(value, (str, bytes)) or not hasattr(value, "__len__"):
            raise TypeError(f"{where}: {name} must be a sequence of 3 numbers, "
                            f"not {type(value).__name__}")
    if len(count) != 3 or len(spacing) != 3:
        raise ValueError(f"{where}: count and spacing must have 3 elements")
    params = list(_numbers(count, 3, "int", where, "count")) + \
        list(_numbers(spacing, 3, "double", where, "spacing"))
    if dim is not None:
        params.append(_integer(dim, where, "dim"))
    _builtin(self, builtin, params, where)


class MjsMesh(_Classed, _Element, _generated.MjsMesh):
    """mjsMesh: mesh specification, with MuJoCo's built-in shapes (make_sphere, ...;
    see mesh/builtin in the MJCF reference): each replaces the mesh's vertices and
    faces, and raises ValueError for parameters MuJoCo refuses."""

    def make_sphere(self, subdivision):
        """An icosphere: `subdivision` (0 to 4) subdivisions of an icosahedron."""
        where = _where(self, "make_sphere")
        _builtin(self, mjtMeshBuiltin.mjMESH_BUILTIN_SPHERE,
                 [_integer(subdivision, where, "subdivision")], where)

    def make_hemisphere(self, resolution):
        """A quad-projected hemisphere, `resolution` (0 to 10) edges per quadrant."""
        where = _where(self, "make_hemisphere")
        _builtin(self, mjtMeshBuiltin.mjMESH_BUILTIN_HEMISPHERE,
                 [_integer(resolution, where, "resolution")], where)

    def make_cone(self, nedge, radius):
        """A prism (radius 1), truncated cone or cone (radius 0) over a regular polygon
        of `nedge` (at least 3) vertices."""
        where = _where(self, "make_cone")
        _builtin(self, mjtMeshBuiltin.mjMESH_BUILTIN_CONE,
                 [_integer(nedge, where, "nedge"), _number(radius, where, "radius")], where)

    def make_supersphere(self, resolution, e, n):
        """A superellipsoid with east-west exponent `e` and north-south exponent `n`."""
        where = _where(self, "make_supersphere")
        _builtin(self, mjtMeshBuiltin.mjMESH_BUILTIN_SUPERSPHERE,
                 [_integer(resolution, where, "resolution"), _number(e, where, "e"),
                  _number(n, where, "n")], where)

    def make_supertorus(self, resolution, radius, s, t):
        """A supertoroid of major radius 1 and minor radius `radius` (in (0, 1]), with
        squareness `s` (minor sections) and `t` (major sections)."""
        where = _where(self, "make_supertorus")
        _builtin(self, mjtMeshBuiltin.mjMESH_BUILTIN_SUPERTORUS,
                 [_integer(resolution, where, "resolution"), _number(radius, where, "radius"),
                  _number(s, where, "s"), _number(t, where, "t")], where)

    def make_wedge(self, resolution=(0, 0), fov=(0.0, 0.0), gamma=0):
        """A slice of a unit spherical shell for tactile sensors: `resolution` (phi,
        theta), field of view `fov` (degrees) and foveal deformation `gamma`."""
        where = _where(self, "make_wedge")
        _builtin(self, mjtMeshBuiltin.mjMESH_BUILTIN_WEDGE,
                 _pair(resolution, "int", where, "resolution")
                 + _pair(fov, "double", where, "fov") + [_number(gamma, where, "gamma")],
                 where)

    def make_plate(self, resolution=(0, 0)):
        """A rectangular plate of `resolution` (x, y) cells, for tactile sensors."""
        where = _where(self, "make_plate")
        _builtin(self, mjtMeshBuiltin.mjMESH_BUILTIN_PLATE,
                 _pair(resolution, "int", where, "resolution"), where)

    def make_grid(self, count, spacing, dim=3):
        """A regular grid of `count` (3 ints) points `spacing` apart: tetrahedra for
        `dim` 3, triangles for `dim` 2."""
        _lattice(self, "make_grid", mjtMeshBuiltin.mjMESH_BUILTIN_GRID, count, spacing, dim)

    def make_box(self, count, spacing, dim=3):
        """A box of `count` (3 ints, at least 2) points `spacing` apart: tetrahedra for
        `dim` 3, an open-top surface for `dim` 2."""
        _lattice(self, "make_box", mjtMeshBuiltin.mjMESH_BUILTIN_BOX, count, spacing, dim)

    def make_cylinder(self, count, spacing, dim=3):
        """A cylinder of `count` (3 ints) points `spacing` apart, as make_box."""
        _lattice(self, "make_cylinder", mjtMeshBuiltin.mjMESH_BUILTIN_CYLINDER, count,
                 spacing, dim)

    def make_ellipsoid(self, count, spacing, dim=3):
        """An ellipsoid of `count` (3 ints) points `spacing` apart, as make_box."""
        _lattice(self, "make_ellipsoid", mjtMeshBuiltin.mjMESH_BUILTIN_ELLIPSOID, count,
                 spacing, dim)

    def make_square(self, count, spacing):
        """A triangulated square of `count` (x, y, 1) points `spacing` apart."""
        _lattice(self, "make_square", mjtMeshBuiltin.mjMESH_BUILTIN_SQUARE, count, spacing)

    def make_disc(self, count, spacing):
        """A triangulated disc of `count` (radial, angular, 1) points `spacing` apart."""
        _lattice(self, "make_disc", mjtMeshBuiltin.mjMESH_BUILTIN_DISC, count, spacing)


# -------------------------------------------------- sensors and tendons

class MjsSensor(_Element, _generated.MjsSensor):
    """mjsSensor: sensor specification, with get_data_size."""

    def get_data_size(self):
        """The number of values the sensor outputs (its `sensor_dim` once compiled)."""
        value = lib.mjcffi_guard_mjs_sensorDim(self._ptr)
        _marshal.check_error()
        return value


class MjsTendonPath:
    """The wrap objects (MjsWrap) of a tendon in path order, read live from the
    tendon: indexing and len() follow edits made later."""

    __slots__ = ("_tendon",)

    def __init__(self, tendon):
        self._tendon = tendon

    def __len__(self):
        count = lib.mjcffi_guard_mjs_getWrapNum(self._tendon._ptr)
        _marshal.check_error()
        return count

    def __getitem__(self, index):
        if isinstance(index, slice):
            return [self[i] for i in range(*index.indices(len(self)))]
        try:
            i = operator.index(index)
        except TypeError:
            raise TypeError(f"tendon path indices must be ints or slices, "
                            f"not {type(index).__name__}") from None
        count = len(self)
        if not -count <= i < count:
            raise IndexError("Index out of range.")
        pointer = lib.mjcffi_guard_mjs_getWrap(self._tendon._ptr, i % count)
        _marshal.check_error()
        return _wrap(self._tendon, pointer)

    def __iter__(self):
        for i in range(len(self)):
            yield self[i]

    def __repr__(self):
        return f"<MjsTendonPath of {len(self)} wraps>"


class MjsTendon(_Element, _generated.MjsTendon):
    """mjsTendon: tendon specification, with its `path`."""

    @property
    def path(self):
        """The tendon's wrap objects in order (an MjsTendonPath)."""
        return MjsTendonPath(self)

    def default(self):
        """The default class (MjsDefault) of the tendon."""
        _held_spec(self._ptr, _where(self, "default"))
        pointer = lib.mjcffi_guard_mjs_getDefault(self._ptr.element)
        _marshal.check_error()
        return _wrap(self, pointer)


class MjsWrap(_generated.MjsWrap):
    """mjsWrap: one wrap object of a tendon's path: what it wraps and its parameters."""

    @property
    def target(self):
        """The wrapped site, geom or joint (None for a pulley)."""
        pointer = lib.mjcffi_guard_mjs_getWrapTarget(self._ptr)
        _marshal.check_error()
        return _wrap(self, pointer)

    @property
    def sidesite(self):
        """The side site of a geom wrap, or None."""
        pointer = lib.mjcffi_guard_mjs_getWrapSideSite(self._ptr)
        _marshal.check_error()
        return _wrap(self, pointer)

    @property
    def coef(self):
        """The coefficient of a joint wrap (None for other wraps)."""
        if self._ptr.type != mjtWrap.mjWRAP_JOINT:
            return None
        value = lib.mjcffi_guard_mjs_getWrapCoef(self._ptr)
        _marshal.check_error()
        return value

    @property
    def divisor(self):
        """The divisor of a pulley (None for other wraps)."""
        if self._ptr.type != mjtWrap.mjWRAP_PULLEY:
            return None
        value = lib.mjcffi_guard_mjs_getWrapDivisor(self._ptr)
        _marshal.check_error()
        return value


# ---------------------------------------------------------------- actuators

def _one(value, where, name):
    """An optional number MuJoCo takes by pointer (kv[1]): -1 leaves it unset (NULL)."""
    number = _number(value, where, name)
    return NULL if number == -1 else ffi.new("double[1]", [number])


def _set_to(actuator, function, where, *args):
    """Call MuJoCo's mjs_setTo* `function`; its error text becomes ValueError, and
    the actuator keeps the values it had (MuJoCo may have set some before it
    found the error: the gain before refusing a negative one)."""
    # these write numbers and enums of the struct only, never its pointers, so
    # the struct's bytes are what to restore
    saved = bytes(ffi.buffer(actuator._ptr))
    error = getattr(lib, "mjcffi_guard_" + function)(actuator._ptr, *args)
    _marshal.check_error()
    message = _marshal.string(error) if error != NULL else ""
    if message:
        ffi.buffer(actuator._ptr)[:] = saved
        raise ValueError(f"{where}: {message}")


class MjsActuator(_Classed, _Element, _generated.MjsActuator):
    """mjsActuator: actuator specification, with the shortcuts of the MJCF actuator
    elements (set_to_motor, set_to_position, ...): each sets the gain, bias and
    dynamics as that element does; -1 leaves an optional parameter to MuJoCo."""

    def set_to_motor(self):
        """Make it a motor: direct force, gain 1."""
        _set_to(self, "mjs_setToMotor", _where(self, "set_to_motor"))

    def set_to_position(self, kp, kv=-1, dampratio=-1, timeconst=-1, inheritrange=False):
        """Make it a position servo of gain `kp`, with damping `kv` or `dampratio`,
        an activation filter of `timeconst`, and the joint range scaled by
        `inheritrange`."""
        where = _where(self, "set_to_position")
        _set_to(self, "mjs_setToPosition", where, _number(kp, where, "kp"),
                _one(kv, where, "kv"), _one(dampratio, where, "dampratio"),
                _one(timeconst, where, "timeconst"),
                _number(inheritrange, where, "inheritrange"))

    def set_to_intvelocity(self, kp, kv=-1, dampratio=-1, timeconst=-1,
                           inheritrange=False):
        """Make it an integrated-velocity servo (as set_to_position, on an
        integrated activation)."""
        where = _where(self, "set_to_intvelocity")
        _set_to(self, "mjs_setToIntVelocity", where, _number(kp, where, "kp"),
                _one(kv, where, "kv"), _one(dampratio, where, "dampratio"),
                _one(timeconst, where, "timeconst"),
                _number(inheritrange, where, "inheritrange"))

    def set_to_velocity(self, kv):
        """Make it a velocity servo of gain `kv`."""
        where = _where(self, "set_to_velocity")
        _set_to(self, "mjs_setToVelocity", where, _number(kv, where, "kv"))

    def set_to_orientation(self, kp, kv=-1, dampratio=-1, ctrlspec=0):
        """Make it an orientation servo (SO(3)) of gain `kp`, with damping `kv` or
        `dampratio`; `ctrlspec` selects its input signature."""
        where = _where(self, "set_to_orientation")
        _set_to(self, "mjs_setToOrientation", where, _number(kp, where, "kp"),
                _one(kv, where, "kv"), _one(dampratio, where, "dampratio"),
                _integer(ctrlspec, where, "ctrlspec"))

    def set_to_pid(self, kp, kv=-1, dampratio=-1, ki=-1, imax=-1, slewmax=-1,
                   inheritrange=0, ctrlspec=0):
        """Make it a PID controller: gains `kp`, `kv` (or `dampratio`) and `ki`,
        integral clamp `imax`, slew-rate limit `slewmax`."""
        where = _where(self, "set_to_pid")
        _set_to(self, "mjs_setToPID", where, _number(kp, where, "kp"),
                _one(kv, where, "kv"), _one(dampratio, where, "dampratio"),
                _one(ki, where, "ki"), _one(imax, where, "imax"),
                _one(slewmax, where, "slewmax"), _number(inheritrange, where, "inheritrange"),
                _integer(ctrlspec, where, "ctrlspec"))

    def set_to_damper(self, kv):
        """Make it an active damper of gain `kv`."""
        where = _where(self, "set_to_damper")
        _set_to(self, "mjs_setToDamper", where, _number(kv, where, "kv"))

    def set_to_cylinder(self, timeconst, bias, area, diameter=-1):
        """Make it a hydraulic or pneumatic cylinder: activation time constant, bias,
        and piston `area` (or `diameter`)."""
        where = _where(self, "set_to_cylinder")
        _set_to(self, "mjs_setToCylinder", where, _number(timeconst, where, "timeconst"),
                _number(bias, where, "bias"), _number(area, where, "area"),
                _number(diameter, where, "diameter"))

    def set_to_muscle(self, timeconst=(-1, -1), tausmooth=None, range=(-1, -1), force=-1,
                      scale=-1, lmin=-1, lmax=-1, vmax=-1, fpmax=-1, fvmax=-1):
        """Make it a muscle: activation and deactivation `timeconst`, `tausmooth`
        (required), operating `range` of lengths, peak `force` (or `scale`), and the
        force-length-velocity curve (lmin, lmax, vmax, fpmax, fvmax)."""
        where = _where(self, "set_to_muscle")
        if tausmooth is None:
            raise TypeError(f"{where}: tausmooth is required")
        _set_to(self, "mjs_setToMuscle", where,
                _numbers(timeconst, 2, "double", where, "timeconst"),
                _number(tausmooth, where, "tausmooth"),
                _numbers(range, 2, "double", where, "range"),
                *[_number(v, where, n) for v, n in ((force, "force"), (scale, "scale"),
                                                   (lmin, "lmin"), (lmax, "lmax"),
                                                   (vmax, "vmax"), (fpmax, "fpmax"),
                                                   (fvmax, "fvmax"))])

    def set_to_adhesion(self, gain):
        """Make it an active adhesion actuator of `gain`."""
        where = _where(self, "set_to_adhesion")
        _set_to(self, "mjs_setToAdhesion", where, _number(gain, where, "gain"))

    def set_to_dcmotor(self, motorconst, resistance, nominal=(0, 0, 0), saturation=(0, 0, 0),
                       inductance=(0, 0), cogging=(0, 0, 0), controller=(0, 0, 0, 0, 0, 0),
                       thermal=(0, 0, 0, 0, 0, 0), lugre=(0, 0, 0, 0, 0), ctrlspec=0):
        """Make it a DC motor: `motorconst` (2: torque and back-EMF constants) and
        armature `resistance`, with the optional models of the MJCF dcmotor element
        (nominal, saturation, inductance, cogging, controller, thermal, lugre)."""
        where = _where(self, "set_to_dcmotor")
        arrays = [_numbers(value, size, "double", where, name) for value, size, name in (
            (nominal, 3, "nominal"), (saturation, 3, "saturation"),
            (inductance, 2, "inductance"), (cogging, 3, "cogging"),
            (controller, 6, "controller"), (thermal, 6, "thermal"), (lugre, 5, "lugre"))]
        _set_to(self, "mjs_setToDCMotor", where,
                _numbers(motorconst, 2, "double", where, "motorconst"),
                _number(resistance, where, "resistance"), *arrays,
                _integer(ctrlspec, where, "ctrlspec"))


# ------------------------------------------------ the other elements

def _plain(name, *mixins):
    """A subclass of generated class `name` with `mixins` (the common properties)."""
    base = getattr(_generated, name)
    return type(name, (*mixins, base), {"__doc__": base.__doc__,
                                        "__module__": __name__})


MjsFlex = _plain("MjsFlex", _Element)
MjsHField = _plain("MjsHField", _Element)
MjsSkin = _plain("MjsSkin", _Element)
MjsTexture = _plain("MjsTexture", _Classed, _Element)
MjsMaterial = _plain("MjsMaterial", _Classed, _Element)
MjsPair = _plain("MjsPair", _Classed, _Element)
MjsExclude = _plain("MjsExclude", _Element)
MjsEquality = _plain("MjsEquality", _Classed, _Element)
MjsNumeric = _plain("MjsNumeric", _Element)
MjsText = _plain("MjsText", _Element)
MjsTuple = _plain("MjsTuple", _Element)
MjsKey = _plain("MjsKey", _Element)
MjsPlugin = _plain("MjsPlugin", _Element)

CLASSES = (MjsBody, MjsFrame, MjsSite, MjsGeom, MjsJoint, MjsCamera, MjsLight, MjsMesh,
           MjsSensor, MjsTendon, MjsWrap, MjsFlex, MjsHField, MjsSkin, MjsTexture,
           MjsMaterial, MjsPair, MjsExclude, MjsEquality, MjsActuator, MjsNumeric, MjsText,
           MjsTuple, MjsKey, MjsPlugin)
_elements.register(*CLASSES)

__all__ = [cls.__name__ for cls in CLASSES] + ["MjsTendonPath"]
