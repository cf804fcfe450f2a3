"""The add_* and wrap_* methods of spec elements: `adder` and `frame_adder`, what
codegen/structs.py builds them with in the generated mjcffi/structs/mjspec.py.

Each is a method over an mjs_add* / mjs_wrap* function that takes keyword
arguments for the new element's attributes (see `configure` for the official's
rules: euler=, axisangle=, xyaxes=, zaxis= and their i* forms, size=[r]
padded); `frame_adder` gives the add_* of a frame, which add to its body and
place the element in the frame.  An element whose keywords are refused is
deleted again: none is left half set in the spec.
"""

import numpy as np

from . import marshal as _marshal
from .library import ffi, lib
from .element_fields import _SCALABLE, _SEQUENCES, _array_length, _setters
from .elements import invalidate, wrap

NULL = ffi.NULL


# the keywords that set an alternative orientation (the official's): for `alt`,
# and `ialt` (a body's inertial frame) with an 'i' in front
_ORIENTATIONS = {"axisangle": "mjORIENTATION_AXISANGLE", "xyaxes": "mjORIENTATION_XYAXES",
                 "zaxis": "mjORIENTATION_ZAXIS", "euler": "mjORIENTATION_EULER"}
_ORIENTATION_SIZES = {"axisangle": 4, "xyaxes": 6, "zaxis": 3, "euler": 3}

# fixed arrays whose keyword takes 1 to all of their numbers, the rest left 0, or a
# number (the official's: geom size=[r] for a sphere, damping=d of a joint)
_PADDED = {("mjsGeom", "size"), ("mjsSite", "size"), ("mjsFlex", "size"),
           ("mjsJoint", "damping"), ("mjsJoint", "stiffness"), ("mjsTendon", "damping"),
           ("mjsTendon", "stiffness"), ("mjsActuator", "damping")}

# add_* that take only some of their element's attributes (the official's)
_ONLY = {"mjs_addFreeJoint": ("align", "group", "name")}


def _keywords(cls):
    """The keywords add_* takes for an element of `cls`: its attributes, and the
    orientation keywords of its `alt` and `ialt`."""
    valid = set(cls._fields) - {"element"} | {"name"}
    for field, prefix in (("alt", ""), ("ialt", "i")):
        if field in cls._fields:
            valid |= {prefix + key for key in _ORIENTATIONS}
    return valid


def _orientations(cls, attrs):
    """Take the orientation keywords out of `attrs`: [(field, type, key, numbers)]."""
    found = []
    for field, prefix in (("alt", ""), ("ialt", "i")):
        given = [key for key in _ORIENTATIONS if prefix + key in attrs]
        if len(given) > 1:
            names = [prefix + key for key in _ORIENTATIONS]
            raise ValueError(f"Only one of: {', '.join(names[:-1])}, or {names[-1]} "
                             f"can be set.")
        for key in given:
            value = attrs.pop(prefix + key)
            found.append((field, getattr(lib, _ORIENTATIONS[key]), key,
                           _sized(cls, prefix + key, value, _ORIENTATION_SIZES[key])))
    return found


def _sized(cls, key, value, length, padded=False, scalable=False):
    """A fixed array's keyword, by the official's rules: `length` numbers; 1 to
    `length` if `padded` (zeros after), or a number; a number if `scalable`."""
    if np.iscomplexobj(value):
        raise TypeError(f"{cls.__name__}.{key} takes real numbers, not complex")
    if isinstance(value, (int, float, np.number)) and not isinstance(value, bool):
        if padded:
            return [value] + [0] * (length - 1)
        if scalable:
            return [value] * length
    if isinstance(value, (str, bytes)) or not hasattr(value, "__len__"):
        raise TypeError(f"{cls.__name__}.{key} takes a list/array of size {length}, "
                        f"not {type(value).__name__}")
    # the official's keywords are C++ arrays of numbers: unlike the attribute, they
    # refuse a column (n, 1) or a nested list
    if any(isinstance(item, (list, tuple)) or getattr(item, "ndim", 0) for item in value):
        raise TypeError(f"{cls.__name__}.{key} as a keyword takes a flat list/array of "
                        f"size {length}, not a nested one or a column (as the official)")
    size = len(value)
    if padded:
        if not 1 <= size <= length:
            raise ValueError(f"{key} should be a list/array of size 1 to {length}.")
        return list(value) + [0] * (length - size)
    if size != length:
        scalar = "a scalar or " if scalable else ""
        raise ValueError(f"{key} should be {scalar}a list/array of size {length}.")
    return value


def _keyword_rule(cls, key):
    """How a keyword's value is converted by the official's keyword rules: a fixed
    array's ("array", length, padded, scalable) (see `_sized`), a char array's
    ("chars", size) (see `_char_keyword`), or None: taken as the attribute takes it."""
    field = getattr(cls, key, None)
    length = _array_length(field)
    if length is not None:
        return ("array", length, (cls._cname, key) in _PADDED, (cls._cname, key) in _SCALABLE)
    size = getattr(field, "fget", None) and getattr(field.fget, "char_size", None)
    if size is not None:
        return ("chars", size)
    return None


def _char_keyword(cls, name, size, value):
    """A char array given as a keyword of add_*: as the official, a str or a list of
    1-character str of exactly `size` characters."""
    if isinstance(value, str):
        chars = list(value)
    elif isinstance(value, list):
        if not all(isinstance(c, str) and len(c) == 1 for c in value):
            raise ValueError(f"{name} list elements must be single characters.")
        chars = value
    else:
        raise TypeError(f"{name} must be a string or a list of single-character strings.")
    if len(chars) != size:
        raise ValueError(f"{name} should have length {size}, got {len(chars)}.")
    return chars


_PLANS: dict = {}          # class -> (its keywords, its orientation keywords)


def _plan(cls):
    plan = _PLANS.get(cls)
    if plan is None:
        valid = frozenset(_keywords(cls))
        orientation = frozenset(prefix + key for prefix in ("", "i")
                                for key in _ORIENTATIONS) & valid
        plan = _PLANS[cls] = (valid, orientation)
    return plan


_KEYWORD_SETTERS: dict = {}   # class -> {keyword: set(element, value) by keyword rules}


def _keyword_setters(cls):
    """The keyword setters of `cls`'s attributes (the orientation keywords aside):
    each converts by `_keyword_rule` and sets as the attribute does, in one call."""
    table = _KEYWORD_SETTERS.get(cls)
    if table is None:
        setters = _setters(cls)
        table = _KEYWORD_SETTERS[cls] = {
            key: _keyword_setter(cls, key, setters.get(key)) for key in _plan(cls)[0]}
    return table


def _keyword_setter(cls, key, setter):
    rule = _keyword_rule(cls, key)
    if setter is None:
        def setter(element, value):
            setattr(element, key, value)
    if rule is None:
        return setter
    if rule[0] == "array":
        length = rule[1]

        def set_array(element, value):
            if value.__class__ in _SEQUENCES and len(value) == length:
                try:
                    setattr(element._ptr, key, value)     # the common case, through cffi
                    return
                except (TypeError, OverflowError):
                    pass
            setter(element, _sized(cls, key, value, *rule[1:]))
        return set_array

    def set_chars(element, value):
        setter(element, _char_keyword(cls, key, rule[1], value))
    return set_chars


def configure(element, attrs, valid=None):
    """Set `attrs` on a new element, naming the attribute in any error; `valid` limits
    the keywords taken (all of the element's attributes, and the orientation
    keywords euler=, axisangle=, xyaxes=, zaxis= and their i* forms)."""
    cls = type(element)
    known, orientation_keys = _plan(cls)
    allowed = known if valid is None else valid
    for key in attrs:
        if key not in allowed:
            raise TypeError(f"Invalid {key} keyword argument. Valid options are: "
                            f"{', '.join(sorted(allowed))}.")
    orientations = ()
    if not orientation_keys.isdisjoint(attrs):
        attrs = dict(attrs)
        orientations = _orientations(cls, attrs)
    setters = _KEYWORD_SETTERS.get(cls) or _keyword_setters(cls)
    for key, value in attrs.items():
        try:
            setters[key](element, value)
        except (TypeError, ValueError) as exc:
            text = str(exc)
            if key not in text:
                text = f"{cls.__name__}.{key}: {text}"
            raise type(exc)(text) from None
    for field, kind, key, value in orientations:
        alt = getattr(element, field)
        alt.type = kind
        setattr(alt, key, value)
    return element


def _discard(element):
    """Delete a new element whose keywords were refused: only its wrapper knows it."""
    pointer = element._ptr.element
    invalidate([element])
    lib.mjcffi_guard_mjs_delete(lib.mjs_getSpec(pointer), pointer)


def _argument(value, kind, name):
    """The C value of one argument of an mjs_add* / mjs_wrap* function after the first:
    `kind` is 'text', 'double' or the mjs* struct it points to (None: NULL)."""
    if kind == "text":
        return _marshal.text(value, name)
    if kind == "double":
        try:
            return float(value)
        except (TypeError, ValueError):
            raise TypeError(f"{name} takes a number, not {type(value).__name__}") from None
    return _marshal.opt_struct(value, kind, name)


def adder(function, result, params, doc):
    """A method over the mjs_add* / mjs_wrap* function `function` giving a `result()`:
    `params` are (name, kind) of its arguments after the first, kind 'default' for the
    mjsDefault that `default=` gives; the others are taken by position or name (a
    struct may be left out: NULL).  Other keywords set the new element's attributes
    (see `configure`)."""
    guard = getattr(lib, "mjcffi_guard_" + function)
    named = [(n, k) for n, k in params if k != "default"]
    takes_default = len(named) < len(params)
    default_at = [k for _, k in params].index("default") if takes_default else None
    only = _ONLY.get(function)

    plain = (NULL,) if takes_default else ()    # the C arguments of add_*() alone
    wraps = function.startswith("mjs_wrap")

    def add(self, *args, default=None, **attrs):
        if args or named or default is not None:
            c_args = arguments(args, default, attrs)
            _same_spec(self, c_args, named, function)
        else:
            c_args = plain
        if attrs and wraps:
            # a refused keyword could not be undone: MuJoCo deletes no wrap
            raise TypeError(f"{function[4:]} takes no attribute keywords "
                            f"({', '.join(sorted(attrs))}); set them on the wrap it returns")
        pointer = guard(self._ptr, *c_args)
        _marshal.check_error()
        element = wrap(pointer, self)
        if attrs:
            try:
                configure(element, attrs, only)
            except BaseException:
                _discard(element)       # no half-set element left in the spec
                raise
        return element

    def arguments(args, default, attrs):
        """The C arguments after the parent; takes its own keywords out of `attrs`."""
        if takes_default and len(args) > len(named):     # the official's first: default
            if default is not None:
                raise TypeError(f"{function[4:]} got two default classes")
            default, args = args[0], args[1:]
        elif default is not None and not takes_default and not args and named and \
                named[0][1].startswith("mjs") and named[0][0] not in attrs:
            default, args = None, (default,)        # the official's add_frame(default=frame)
        if len(args) > len(named):
            raise TypeError(f"{function[4:]} takes {len(named)} positional arguments, "
                            f"not {len(args)}")
        if default is not None and not takes_default:
            raise TypeError(f"{function} takes no default class")
        values = list(args)
        for name, kind in named[len(args):]:
            if name in attrs and (kind in ("text", "double") or name not in result()._fields):
                values.append(attrs.pop(name))
            elif kind in ("text", "double"):
                raise TypeError(f"{function[4:]} needs its argument {name!r}")
            else:
                values.append(None)
        c_args = [_argument(v, k, n) for v, (n, k) in zip(values, named)]
        if takes_default:
            c_args.insert(default_at, NULL if default is None else
                          _marshal.opt_struct(default, "mjsDefault", "default"))
        return c_args
    add.__doc__ = doc
    add.__name__ = function
    return add


def _same_spec(parent, c_args, named, function):
    """Refuse an element argument (add_frame's parent frame) of another spec than
    `parent`'s: MuJoCo would link the two specs' trees."""
    spec = lib.mjs_getSpec(parent._ptr.element)
    for c_arg, (name, kind) in zip(c_args, named):
        if kind not in ("text", "double") and c_arg != NULL and \
                lib.mjs_getSpec(c_arg.element) != spec:
            raise ValueError(f"{function[4:]}: {name} belongs to another spec")


def frame_adder(function, result, params, doc):
    """A method of MjsFrame over the body's `function` (mjs_addGeom): the element is
    added to the frame's body and placed in the frame (mjs_setFrame); add_frame
    makes a child frame.  Arguments as for `adder`."""
    add_to_body = adder(function, result, params, doc)
    nested = function == "mjs_addFrame"

    def add(self, *args, default=None, **attrs):
        body = wrap(lib.mjs_getParent(self._ptr.element), self)
        if nested:
            return add_to_body(body, *(args or (self,)), default=default, **attrs)
        element = add_to_body(body, *args, default=default, **attrs)
        failed = lib.mjcffi_guard_mjs_setFrame(element._ptr.element, self._ptr)
        try:
            _marshal.check_error()
            if failed:
                raise ValueError(f"{function[4:]}: MuJoCo refused the frame")
        except BaseException:
            _discard(element)
            raise
        return element
    add.__doc__ = f"{doc} (in this frame)"
    add.__name__ = function
    return add
