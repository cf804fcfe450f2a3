"""MjSpec: a model specification (mjSpec) with the official Python API.

It builds on the generated struct class (fields such as `option`, `compiler`,
`nkey`) and adds what is written by hand: making and parsing specs, compiling,
saving, copying, element lookups and lists, delete and attach.  Element wrappers
come from `_element`, one per element, so that `delete` can mark the wrappers of
everything it frees (see lifetime.py).
"""

import copy as _copy
import re

from .. import _marshal as _m
from .._library import ffi, lib
from .._overrides import _model, mj_compile, mj_saveXMLString
from ..structs import mjspec as _generated
from . import kinds, lifetime
from .assets import vfs_of


def _spec_error(c_spec, what):
    return ValueError(_m.string(lib.mjs_getError(c_spec)) or f"{what} failed")


def _parsed(pointer, error, what):
    _m.check_error()
    if pointer == ffi.NULL:
        raise ValueError(_m.error_text(error, what))
    return pointer


class MjSpec(_generated.MjSpec):
    """A model specification: build or edit a model in code, then `compile()` it.

    `MjSpec()` is an empty model; `MjSpec.from_string(xml)` and
    `MjSpec.from_file(path)` parse MJCF.  Element wrappers (`spec.body('torso')`,
    `spec.geoms`) point into the spec and keep it alive; after `spec.delete(e)`
    every wrapper of what was freed raises DeletedElementError on use.
    """

    def __init__(self):
        self._adopt_spec(lib.mjcffi_guard_mj_makeSpec(), {})
        _m.check_error()

    # --------------------------------------------------------- construction

    def _adopt_spec(self, pointer, assets):
        if pointer == ffi.NULL:
            raise MemoryError("MuJoCo could not allocate the mjSpec")
        self._init_root(ffi.gc(pointer, lib.mj_deleteSpec))
        self.__dict__.update(_registry=lifetime.Registry(), _assets=dict(assets),
                             _attached=[])

    @classmethod
    def _new(cls, pointer, assets):
        self = cls.__new__(cls)
        self._adopt_spec(pointer, assets)
        return self

    @classmethod
    def from_string(cls, xml, include=None, assets=None, vfs=None):
        """A spec parsed from MJCF text; `include` and `assets` map file names to
        bytes (the files it includes and the assets it reads); `vfs` instead of both."""
        merged = {**(include or {}), **(assets or {})}
        pointer = cls._parse(lib.mjcffi_guard_mj_parseXMLString, _m.text(xml, "xml"),
                             merged, vfs, "mj_parseXMLString")
        return cls._new(pointer, merged)

    @classmethod
    def from_file(cls, filename, include=None, assets=None, vfs=None):
        """A spec parsed from an MJCF file (a path); `include`, `assets`, `vfs` as
        in from_string."""
        merged = {**(include or {}), **(assets or {})}
        path = _m.text(str(filename), "filename")
        pointer = cls._parse(lib.mjcffi_guard_mj_parseXML, path, merged, vfs, "mj_parseXML")
        return cls._new(pointer, merged)

    @staticmethod
    def _parse(parser, source, assets, vfs, what):
        if vfs is not None and assets:
            raise ValueError("Cannot specify both 'assets' and 'vfs'.")
        own_vfs = vfs_of(assets)
        try:
            chosen = vfs if vfs is not None else own_vfs
            error, error_sz = _m.error_buffer()
            c_vfs = _m.opt_struct(chosen, "mjVFS", "vfs")
            return _parsed(parser(source, c_vfs, error, error_sz), error, what)
        finally:
            if own_vfs is not None:
                own_vfs.close()

    @classmethod
    def from_zip(cls, file):
        """A spec from a zip archive (path or file object): the model is the .xml file
        nearest its top (there must be one only at that depth); the other files,
        named relative to the model's folder, are its assets."""
        import posixpath
        import zipfile
        with zipfile.ZipFile(file) as archive:
            files = {name: archive.read(name) for name in archive.namelist()
                     if not name.endswith("/")}
        xmls = [name for name in files if name.endswith(".xml")]
        top = min((name.count("/") for name in xmls), default=0)
        models = [name for name in xmls if name.count("/") == top]
        if len(models) != 1:
            raise ValueError(f"the zip file must hold one .xml file nearest its top, "
                             f"found {len(models)}")
        root = posixpath.dirname(models[0])
        xml = files.pop(models[0]).decode("utf-8")
        assets = {posixpath.relpath(name, root) if root else name: content
                  for name, content in files.items()}
        return cls.from_string(xml, assets=assets)

    # ------------------------------------------------------------- assets

    @property
    def assets(self):
        """File name -> bytes: the assets the spec reads when it compiles."""
        return self._assets

    @assets.setter
    def assets(self, value):
        if not isinstance(value, dict):
            raise TypeError(f"assets must be a dict, not {type(value).__name__}")
        self.__dict__["_assets"] = dict(value)

    # ---------------------------------------------------------- compiling

    def compile(self, vfs=None):
        """The compiled MjModel; MuJoCo's compile error becomes ValueError."""
        if vfs is not None:
            return mj_compile(self, vfs)
        own_vfs = vfs_of(self._assets)
        try:
            return mj_compile(self, own_vfs)
        finally:
            if own_vfs is not None:
                own_vfs.close()

    def recompile(self, m, d, vfs=None):
        """(model, data): the spec compiled again, with the state of `d` carried over
        by name, as new objects; `m` and `d` are left as they were."""
        c_m, c_d = _m.struct(m, "mjModel", "m"), _m.struct(d, "mjData", "d")
        new_m = lib.mjcffi_guard_mj_copyModel(ffi.NULL, c_m)
        _m.check_error()
        new_d = lib.mjcffi_guard_mj_copyData(ffi.NULL, new_m, c_d)
        _m.check_error()
        own_vfs = vfs_of(self._assets) if vfs is None else None
        try:
            c_vfs = _m.opt_struct(vfs if vfs is not None else own_vfs, "mjVFS", "vfs")
            status = lib.mjcffi_guard_mj_recompile(self._ptr, c_vfs, new_m, new_d)
            _m.check_error()
        finally:
            if own_vfs is not None:
                own_vfs.close()
        if status != 0:
            # MuJoCo freed the copies: nothing of Python's pointed at them
            raise _spec_error(self._ptr, "mj_recompile")
        return self._wrap_compiled(new_m, new_d)

    @staticmethod
    def _wrap_compiled(c_model, c_data):
        from ..callbacks import _track
        from ..data import MjData
        model = _model(c_model)
        data = MjData.__new__(MjData)
        data._init_root(ffi.gc(c_data, lib.mj_deleteData), _model=model)
        _track(data)
        return model, data

    # -------------------------------------------------------------- saving

    def to_xml(self):
        """The spec as MJCF text; it compiles first, as the official does."""
        compiled = self
        if self.compiler.fusestatic or self.compiler.discardvisual:
            compiled = self.copy()      # compiling would free wrapped elements
        compiled.compile()
        return mj_saveXMLString(compiled)

    def to_file(self, filename):
        """Write to_xml() to `filename`."""
        with open(filename, "w", encoding="utf-8") as file:
            file.write(self.to_xml())

    # ------------------------------------------------------------- copying

    def copy(self):
        """An independent deep copy of the spec (mj_copySpec), assets included."""
        pointer = lib.mjcffi_guard_mj_copySpec(self._ptr)
        _m.check_error()
        return type(self)._new(pointer, self._assets)

    def __copy__(self):
        return self.copy()

    def __deepcopy__(self, memo):
        other = self.copy()
        other.__dict__["_assets"] = _copy.deepcopy(self._assets, memo)
        return other

    # ------------------------------------------------------------ elements

    def _element(self, element, type_):
        """The one wrapper of generic element pointer `element` (None for NULL)."""
        if element == ffi.NULL:
            return None
        return lifetime.wrap_element(
            self, element, type_,
            lambda: kinds.wrapper_class(type_)._wrap(kinds.cast(element, type_), self._root))

    def _elements(self, type_):
        found = []
        element = lib.mjcffi_guard_mjs_firstElement(self._ptr, type_)
        _m.check_error()
        while element != ffi.NULL:
            found.append(self._element(element, type_))
            element = lib.mjcffi_guard_mjs_nextElement(self._ptr, element)
            _m.check_error()
        return found

    def _find(self, type_, name):
        element = lib.mjcffi_guard_mjs_findElement(self._ptr, type_, _m.text(name, "name"))
        _m.check_error()
        return self._element(element, type_)

    def find_all(self, type):
        """Every element of `type` (an mjtObj, or a name such as 'site'), in order."""
        return self._elements(kinds.object_type(type))

    @property
    def worldbody(self):
        """The world body, root of the kinematic tree."""
        body = lib.mjcffi_guard_mjs_findBody(self._ptr, b"world")
        _m.check_error()
        return self._element(body.element, kinds.mjtObj.mjOBJ_BODY)

    def _live_addresses(self):
        live = set()
        for type_ in kinds.BY_TYPE:
            element = lib.mjcffi_guard_mjs_firstElement(self._ptr, type_)
            while element != ffi.NULL:
                live.add(lifetime.address(element))
                element = lib.mjcffi_guard_mjs_nextElement(self._ptr, element)
        _m.check_error()
        return live

    def delete(self, element):
        """Remove `element` (a body: with its subtree) from the spec.  Every wrapper of
        what MuJoCo freed is marked deleted: using it raises DeletedElementError."""
        c_element = self._element_pointer(element, "element")
        status = lib.mjcffi_guard_mjs_delete(self._ptr, c_element)
        _m.check_error()
        if status != 0:
            raise _spec_error(self._ptr, "mjs_delete")
        lifetime.end_missing(self, self._live_addresses())
        if not lifetime.deleted(element):
            lifetime.invalidate(element)        # a wrapper made outside the registries

    def _element_pointer(self, element, name):
        """The mjsElement * of an element wrapper of this spec."""
        label = element.__dict__.get("_deleted") if hasattr(element, "__dict__") else None
        if label is not None or lifetime.is_deleted(element):
            kind = re.search(r"Mjs(\w+)", str(label or type(element).__name__))
            raise ValueError(f"{kind.group(1).lower() if kind else 'element'} "
                             f"is not in this model")
        try:
            c_element = element._ptr.element
        except AttributeError:
            raise TypeError(f"{name} must be a spec element, not "
                            f"{type(element).__name__}") from None
        owner = lib.mjcffi_guard_mjs_getSpec(c_element)
        _m.check_error()
        if owner != self._ptr:
            raise ValueError(f"{name} belongs to another spec")
        return c_element

    # ---------------------------------------------------------------- attach

    def attach(self, child, prefix=None, suffix=None, site=None, frame=None):
        """Attach spec `child` at `frame` or `site` (elements of this spec, or their
        names); its names get `prefix` and `suffix`.  Returns the attached element
        (the frame holding the child's world body).  MuJoCo attaches a spec once unless
        deep copy is on: attach `child.copy()` to place it again."""
        if not isinstance(child, _generated.MjSpec):
            raise TypeError(f"child must be an MjSpec, not {type(child).__name__}")
        if site is not None and frame is not None:
            raise ValueError("give a site or a frame, not both")
        parent = self._attach_point(site, frame)
        result = lib.mjcffi_guard_mjs_attach(
            parent, child._ptr.element, _m.text(prefix or "", "prefix"),
            _m.text(suffix or "", "suffix"))
        _m.check_error()
        if result == ffi.NULL:
            raise _spec_error(self._ptr, "mjs_attach")
        self._attached.append(child)        # MuJoCo may read the child until compiled
        self._assets.update(getattr(child, "_assets", {}))
        return self._element(result, result.elemtype) \
            if int(result.elemtype) in kinds.BY_TYPE else None

    def _attach_point(self, site, frame):
        if site is not None:
            if isinstance(site, str):
                site = self._require("site", site)
            return self._element_pointer(site, "site")
        if frame is not None:
            if isinstance(frame, str):
                frame = self._require("frame", frame)
            return self._element_pointer(frame, "frame")
        raise ValueError("One of frame or site must be specified.")

    def _require(self, kind, name):
        found = self._find(kinds.BY_LOOKUP[kind][2], name)
        if found is None:
            raise ValueError(f"no {kind} named {name!r} in the spec")
        return found


def _lookup(type_, kind):
    def find(self, name):
        return self._find(type_, name)
    find.__name__ = kind
    find.__doc__ = f"The {kind} named `name`, or None."
    return find


def _listing(type_, plural):
    def elements(self):
        return self._elements(type_)
    elements.__name__ = plural
    return property(elements, doc=f"Every {plural[:-1]} of the spec, in order.")


for _plural, _kind, _type, _ in kinds.KINDS:
    setattr(MjSpec, _kind, _lookup(int(_type), _kind))
    setattr(MjSpec, _plural, _listing(int(_type), _plural))
