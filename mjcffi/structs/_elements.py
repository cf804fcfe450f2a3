"""Spec elements as Python objects: their str, vector and enum attributes, the one
wrapper of each element, its end when the element is deleted, and add_*.

Hand-written support of the generated mjcffi/structs/mjspec.py (as _handles.py
and _checks.py are); codegen/structs.py writes, for the fields of the spec
structs, the builders below:

- `string_field`: an mjString as str (mjs_getString / mjs_setString);
- `vector_field`: an mjDoubleVec, mjFloatVec or mjIntVec as a NumPy array, an
  mjByteVec as bytes, an mjStringVec as a list of str, an mjIntVecVec or
  mjFloatVecVec as a list of arrays (written once: MuJoCo only appends to them).  Reading gives a copy:
  changing it changes nothing in the spec; assign to the attribute to do that
  (`body.userdata = [1, 2]`).  MuJoCo's C API reads only strings and double
  vectors back, so the others are read from the std::vector that mjspec.h hides
  behind `void`: three pointers (begin, end, capacity), and a std::string as
  libc++ lays it out (see _read_string; tests/test_spec_elements.py checks each
  kind against what was written and against the official binding);
- `enum_field`: an mjt* field as its IntEnum, taking any int;
- `element_name`: the element's name (mjs_getName / mjs_setName);
- `element_setattr`: a quicker `__setattr__` for fixed arrays;
- `adder`: `add_*` and `wrap_*` methods over the mjs_add* / mjs_wrap* functions,
  taking keyword arguments for the new element's attributes; `frame_adder` the
  add_* of a frame, which add to its body and place the element in the frame.

Every element reached through them has one wrapper (`wrap`), which keeps its spec
alive; `invalidate` ends wrappers of deleted elements, so that using one raises
RuntimeError instead of reading freed memory.
"""

import operator
import weakref

import numpy as np

from .. import _marshal
from .._library import ffi, lib
from .._views import FixedArray, Struct, _scalar_error

NULL = ffi.NULL


# ------------------------------------------------------------------ attributes

def _where(self, name):
    return f"{type(self).__name__}.{name}"


def _text(self, name, value):
    """`value` as NUL-terminated UTF-8 for MuJoCo."""
    if not isinstance(value, str):
        raise TypeError(f"{_where(self, name)} takes a str, not {type(value).__name__}")
    if "\0" in value:
        raise ValueError(f"{_where(self, name)} cannot hold a NUL character")
    return value.encode()


def string_field(name, doc):
    """A `mjString *name` field as str, read and written through MuJoCo."""
    def get(self):
        return ffi.string(lib.mjs_getString(getattr(self._ptr, name))).decode()

    def set_value(self, value):
        lib.mjs_setString(getattr(self._ptr, name), _text(self, name, value))
    return property(get, set_value, doc=doc)


def element_name(doc="the element's name"):
    """The `name` of an element: mjs_getName / mjs_setName on its mjsElement.  The
    name's mjString lives as long as the element, so its address is kept on the
    wrapper after the first read (mjs_getName is the slow part)."""
    def name_of(self):
        state = self.__dict__
        pointer = state.get("_name")
        if pointer is None:
            pointer = state["_name"] = lib.mjs_getName(self._ptr.element)
        return pointer

    def get(self):
        return ffi.string(lib.mjs_getString(name_of(self))).decode()

    def set_value(self, value):
        text = _text(self, "name", value)
        failed = lib.mjcffi_guard_mjs_setName(self._ptr.element, text)
        _marshal.check_error()
        if failed:
            raise ValueError(f"{_where(self, 'name')}: MuJoCo refused the name {value!r}")
    return property(get, set_value, doc=doc)


# std::vector<T>: begin, end, end of storage
def _span(pointer):
    begin, end = ffi.cast("char **", pointer)[0:2]
    return begin, int(ffi.cast("uintptr_t", end)) - int(ffi.cast("uintptr_t", begin))


def _read_numbers(pointer, ctype, dtype):
    vector = ffi.cast(ctype, pointer)
    begin = vector[0]
    if begin == NULL:                  # an empty vector that never held anything
        return np.zeros(0, dtype)
    return np.array(ffi.unpack(begin, vector[1] - begin), dtype)


def _read_nested(ctype, dtype):
    """A reader of std::vector<std::vector<T>> (mjIntVecVec, mjFloatVecVec): a list of
    arrays, one per inner vector of 24 bytes."""
    def read(pointer):
        begin, size = _span(pointer)
        return [_read_numbers(begin + 24 * i, ctype, dtype) for i in range(size // 24)]
    return read


def _append_nested(append, dtype):
    """A writer of a vector of vectors.  MuJoCo can only append to one, so only an
    empty one is written (as the XML parser fills it, once)."""
    def write(self, name, pointer, value):
        if isinstance(value, (str, bytes)) or not hasattr(value, "__iter__"):
            raise TypeError(f"{_where(self, name)} takes a list of sequences of numbers, "
                            f"not {type(value).__name__}")
        rows = [_numbers(self, name, row, dtype) for row in value]
        if _span(pointer)[1]:
            raise ValueError(f"{_where(self, name)} is set already: MuJoCo can only "
                             f"append to it, so it is written once")
        for row in rows:
            append(pointer, ffi.cast(ctype_of[dtype], ffi.from_buffer(row)), row.size)
    ctype_of = {np.int32: "int *", np.float32: "float *"}
    return write


def _read_bytes(pointer):
    begin, size = _span(pointer)
    return ffi.buffer(begin, size)[:] if size and begin != NULL else b""


def _read_strings(pointer):
    begin, size = _span(pointer)
    return [_read_string(begin + 24 * i) for i in range(size // 24)]


def _read_string(entry):
    """One libc++ std::string (MuJoCo's wheels use libc++): 24 bytes; bit 0 of the first
    byte set for a long string (capacity, size, pointer), clear for a short one (size
    times 2, then the characters in place)."""
    head = ffi.cast("unsigned char *", entry)[0]
    if head & 1:
        words = ffi.cast("size_t *", entry)
        return ffi.unpack(ffi.cast("char **", entry)[2], words[1]).decode()
    return ffi.unpack(ffi.cast("char *", entry) + 1, head >> 1).decode()


def _numbers(self, name, value, dtype):
    """`value`, a sequence of numbers, as a contiguous 1-D array of `dtype`."""
    if isinstance(value, (str, bytes)) or not hasattr(value, "__len__") and \
            not isinstance(value, np.ndarray):
        raise TypeError(f"{_where(self, name)} takes a sequence of numbers, "
                        f"not {type(value).__name__}")
    try:
        array = np.asarray(value)
    except (TypeError, ValueError) as exc:
        raise TypeError(f"{_where(self, name)} takes a sequence of numbers: {exc}") from None
    if array.size and array.dtype.kind not in "biuf":
        raise TypeError(f"{_where(self, name)} takes numbers, not {array.dtype}")
    if array.ndim > 1:
        array = array.reshape(-1)        # the official takes nested sequences flattened
    if array.ndim != 1:
        raise TypeError(f"{_where(self, name)} takes a sequence, not a scalar")
    if np.dtype(dtype).kind == "i" and array.size and array.dtype.kind == "f":
        if not np.all(array == np.round(array)):
            raise TypeError(f"{_where(self, name)} takes ints")
    return np.ascontiguousarray(array, dtype)


def _write_vector(setter, ctype, dtype):
    def write(self, name, pointer, value):
        array = _numbers(self, name, value, dtype)
        setter(pointer, ffi.cast(ctype, ffi.from_buffer(array)), array.size)
    return write


def _write_bytes(self, name, pointer, value):
    if isinstance(value, str):
        raise TypeError(f"{_where(self, name)} takes bytes, not str")
    try:
        data = bytes(memoryview(value).cast("B")) if not isinstance(value, bytes) else value
    except TypeError:
        data = bytes(_numbers(self, name, value, np.uint8))
    lib.mjs_setBuffer(pointer, data, len(data))


def _write_strings(self, name, pointer, value):
    if isinstance(value, str) or not hasattr(value, "__iter__"):
        raise TypeError(f"{_where(self, name)} takes a list of str, not {type(value).__name__}")
    texts = [_text(self, name, v) for v in value]
    lib.mjs_setStringVec(pointer, b"")
    for text in texts:
        lib.mjs_appendString(pointer, text)


_VECTORS = {
    "mjDoubleVec": (lambda p: _read_numbers(p, "double **", np.float64),
                    _write_vector(lib.mjs_setDouble, "double *", np.float64)),
    "mjFloatVec": (lambda p: _read_numbers(p, "float **", np.float32),
                   _write_vector(lib.mjs_setFloat, "float *", np.float32)),
    "mjIntVec": (lambda p: _read_numbers(p, "int **", np.int32),
                 _write_vector(lib.mjs_setInt, "int *", np.int32)),
    "mjIntVecVec": (_read_nested("int **", np.int32),
                    _append_nested(lib.mjs_appendIntVec, np.int32)),
    "mjFloatVecVec": (_read_nested("float **", np.float32),
                      _append_nested(lib.mjs_appendFloatVec, np.float32)),
    "mjByteVec": (_read_bytes, _write_bytes),
    "mjStringVec": (_read_strings, _write_strings),
}


def vector_field(name, kind, doc):
    """A `kind *name` field (mjDoubleVec, ...): read as a copy, written whole."""
    read, write = _VECTORS[kind]

    def get(self):
        return read(getattr(self._ptr, name))

    def set_value(self, value):
        write(self, name, getattr(self._ptr, name), value)
    return property(get, set_value, doc=doc)


def enum_field(name, enum, doc):
    """An mjt* field as its IntEnum (an int for a value that is no member, such as a
    bitmask); it takes any int."""
    members = None

    def get(self):
        nonlocal members
        if members is None:
            from .. import _enums
            members = {int(m): m for m in getattr(_enums, enum)}
        value = getattr(self._ptr, name)
        return members.get(value, value)

    def set_value(self, value):
        try:
            number = operator.index(value)
        except TypeError:
            raise TypeError(f"{_where(self, name)} takes an {enum} or int, "
                            f"not {type(value).__name__}") from None
        try:
            setattr(self._ptr, name, number)
        except OverflowError as exc:
            raise _scalar_error(self, name, number, exc) from None
    return property(get, set_value, doc=doc)


_SEQUENCES = (list, tuple)
_FLAT: dict = {}          # element class -> {its 1-D fixed arrays of numbers: their length}


def _flat_arrays(cls):
    found = _FLAT.get(cls)
    if found is None:
        found = _FLAT[cls] = {}
        for name in cls._fields:
            field = getattr(cls, name, None)
            if isinstance(field, FixedArray) and field.dtype.kind in "biuf":
                shape = field.shape(None)
                if len(shape) == 1:
                    found[name] = shape[0]
    return found


def element_setattr():
    """`__setattr__` of the element classes: a list or tuple of the right length for
    a 1-D fixed array is converted by cffi (geom.size = [1, 1, 1]), and an array
    written into the field's view, both quicker than the general path; anything
    else, and any value these refuse, goes through Struct.__setattr__, which names
    the field."""
    return _setattr


def _setattr(self, name, value):
    if value.__class__ in _SEQUENCES:
        if _flat_arrays(self.__class__).get(name) == len(value):
            try:
                setattr(self._ptr, name, value)
                return
            except (TypeError, OverflowError):
                pass
    else:
        view = self.__dict__.get(name)
        if view.__class__ is np.ndarray:
            try:
                view[...] = value
                return
            except (ValueError, TypeError, OverflowError):
                pass
    Struct.__setattr__(self, name, value)


# -------------------------------------------------------------------- wrappers

# mjtObj -> (the element's class name, its mjs_as* function)
_KINDS = {
    "mjOBJ_BODY": "Body", "mjOBJ_XBODY": "Body", "mjOBJ_JOINT": "Joint", "mjOBJ_GEOM": "Geom",
    "mjOBJ_SITE": "Site", "mjOBJ_CAMERA": "Camera", "mjOBJ_LIGHT": "Light",
    "mjOBJ_FLEX": "Flex", "mjOBJ_MESH": "Mesh", "mjOBJ_SKIN": "Skin", "mjOBJ_HFIELD": "HField",
    "mjOBJ_TEXTURE": "Texture", "mjOBJ_MATERIAL": "Material", "mjOBJ_PAIR": "Pair",
    "mjOBJ_EXCLUDE": "Exclude", "mjOBJ_EQUALITY": "Equality", "mjOBJ_TENDON": "Tendon",
    "mjOBJ_ACTUATOR": "Actuator", "mjOBJ_SENSOR": "Sensor", "mjOBJ_NUMERIC": "Numeric",
    "mjOBJ_TEXT": "Text", "mjOBJ_TUPLE": "Tuple", "mjOBJ_KEY": "Key", "mjOBJ_PLUGIN": "Plugin",
    "mjOBJ_FRAME": "Frame",
}
_BY_TYPE = {getattr(lib, obj): kind for obj, kind in _KINDS.items() if hasattr(lib, obj)}

# spec address -> {element address: its wrapper}
_REGISTRIES: dict = {}


def _address(pointer):
    return int(ffi.cast("uintptr_t", pointer))


def _registry(root):
    key = _address(root)
    registry = _REGISTRIES.get(key)
    if registry is None:
        registry = _REGISTRIES[key] = weakref.WeakValueDictionary()
    return registry


def wrap(pointer, owner):
    """The one wrapper of the element `pointer` points to (an mjs* struct or its
    mjsElement), of its class (MjsGeom for a geom), keeping `owner`'s spec alive;
    None for NULL."""
    if pointer == NULL:
        return None
    root = getattr(owner, "_root", owner)
    if ffi.typeof(pointer) is ffi.typeof("mjsElement *"):
        element = pointer
        kind = _BY_TYPE.get(element.elemtype)
        if kind is None:
            raise ValueError(f"no element wrapper for element type {element.elemtype}")
        pointer = getattr(lib, "mjs_as" + kind)(element)
        cls = _BY_KIND[kind]
    else:
        element = pointer.element
        cls = _class_of(ffi.typeof(pointer))
    registry = _registry(root)
    key = _address(element)
    found = registry.get(key)
    if found is not None and type(found) is cls:
        return found
    made = registry[key] = cls._wrap(pointer, root)
    return made


_CLASSES: dict = {}        # cffi type `mjs* *` -> its element class (see `register`)
_BY_KIND: dict = {}        # 'Geom' -> MjsGeom


def register(*classes):
    """Record the generated element classes (mjspec.py calls this once), so that a
    pointer of any element finds its class."""
    for cls in classes:
        _CLASSES[ffi.typeof(ffi.getctype(cls._ctype, "*"))] = cls
        _BY_KIND[cls.__name__[3:]] = cls


def _class_of(ctype):
    """The element class of a `mjs* *` cffi type."""
    cls = _CLASSES.get(ctype)
    if cls is None:
        raise TypeError(f"{ctype.cname} is no spec element")
    return cls


def registered(owner):
    """The live wrappers of `owner`'s spec."""
    return list(_registry(getattr(owner, "_root", owner)).values())


class DeletedElement(Struct):
    """What the wrapper of a deleted element becomes: any use raises RuntimeError."""

    def __getattribute__(self, name):
        if name.startswith("__") or name == "_deleted":
            return object.__getattribute__(self, name)
        raise RuntimeError(f"{object.__getattribute__(self, '_deleted')} was deleted from "
                           f"its spec: its wrapper cannot be used")

    def __setattr__(self, name, value):
        self.__getattribute__("_ptr")

    def __repr__(self):
        return f"<{self._deleted} (deleted)>"

    def __eq__(self, other):
        return self is other

    __hash__ = object.__hash__


def _end(wrapper, label):
    state = wrapper.__dict__
    state.clear()
    state["_deleted"] = label
    wrapper.__class__ = DeletedElement


def invalidate(elements):
    """End the wrappers of `elements` (wrappers, or mjs* / mjsElement pointers) before
    MuJoCo frees them; their names go into the error their later use raises."""
    for item in elements:
        if isinstance(item, DeletedElement):
            continue
        if isinstance(item, Struct):
            wrapper = item
        else:
            element = item if ffi.typeof(item) is ffi.typeof("mjsElement *") else item.element
            wrapper = None
            for registry in _REGISTRIES.values():
                wrapper = registry.get(_address(element))
                if wrapper is not None:
                    break
            if wrapper is None:
                continue
        label = type(wrapper).__name__
        try:
            name = wrapper.name
        except AttributeError:
            name = ""
        label += f" {name!r}" if name else ""
        for registry in _REGISTRIES.values():
            key = _address(wrapper._ptr.element)
            if registry.get(key) is wrapper:
                del registry[key]
        _end(wrapper, label)


def invalidate_missing(owner, alive):
    """After MuJoCo freed elements (delete of a subtree, fuse_static): end every
    wrapper of `owner`'s spec whose element address is not in `alive`."""
    registry = _registry(getattr(owner, "_root", owner))
    for key, wrapper in list(registry.items()):
        if key not in alive:
            del registry[key]
            _end(wrapper, f"a {type(wrapper).__name__}")


# ----------------------------------------------------------------------- add_*

def configure(element, attrs):
    """Set `attrs` on a new element, naming the attribute in any error."""
    cls = type(element)
    for key, value in attrs.items():
        if key != "name" and key not in cls._fields or key == "element":
            valid = ", ".join(sorted(set(cls._fields) - {"element"} | {"name"}))
            raise TypeError(f"{cls.__name__} has no attribute {key!r}; valid keywords: {valid}")
        try:
            setattr(element, key, value)
        except (TypeError, ValueError) as exc:
            text = str(exc)
            if f"{cls.__name__}.{key}" not in text:
                text = f"{cls.__name__}.{key}: {text}"
            raise type(exc)(text) from None
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
    struct may be left out: NULL).  Other keywords set the new element's attributes."""
    guard = getattr(lib, "mjcffi_guard_" + function)
    named = [(n, k) for n, k in params if k != "default"]
    takes_default = len(named) < len(params)

    def add(self, *args, default=None, **attrs):
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
            c_args.insert([k for _, k in params].index("default"),
                          _marshal.opt_struct(default, "mjsDefault", "default"))
        pointer = guard(self._ptr, *c_args)
        _marshal.check_error()
        element = wrap(pointer, self)
        if attrs:
            try:
                configure(element, attrs)
            except BaseException:
                _discard(element)       # no half-set element left in the spec
                raise
        return element
    add.__doc__ = doc
    add.__name__ = function
    return add


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
