"""MjSpec: a model specification (mjSpec) with the official Python API.

It builds on the generated struct class (fields such as `option`, `compiler`,
`nkey`) and adds what is written by hand: making and parsing specs, compiling,
saving, copying, element lookups and lists, defaults, delete, attach, and the
edits that free elements (fuse_static, discard_visual, dedup_assets).  Element
wrappers come from the element layer, one per element; whatever frees elements
goes through `lifetime.freeing`, which ends the wrappers of what was freed.
"""

import copy as _copy
import functools
import warnings

import numpy as np

from .._support import marshal as _m
from .._generated.enums import mjtCTimer
from .._support.errors import FatalError
from .._support.library import ffi, lib
from .._support.loading import save_xml_string
from ..model import MjModel
from .._support.plugins import load_bundled
from .._support.views import Nested, view
from .._support import elements as _elements
from .._support import spec_claims as _claims
from ..structs import mjspec as _generated
from ..structs import mjmodel as _visualize
from . import attach as _attach
from . import lifetime
from .._support import spec_kinds as kinds
from .assets import check_assets, relative_names, vfs_pointer


def _spec_error(c_spec, what):
    return ValueError(_m.string(lib.mjs_getError(c_spec)) or f"{what} failed")


def _call(guard, *args):
    """A guarded MuJoCo call's result, after raising what it left (FatalError)."""
    result = guard(*args)
    _m.check_error()
    return result


def _both_given(include, assets, vfs):
    if vfs is not None and (include is not None or assets is not None):
        raise ValueError("Cannot specify both 'vfs' and 'include'/'assets'.")


def _each(c_spec, type_):
    """The mjsElement * of every element of mjtObj `type_` in a spec."""
    element = _call(lib.mjcffi_guard_mjs_firstElement, c_spec, type_)
    while element != ffi.NULL:
        yield element
        element = _call(lib.mjcffi_guard_mjs_nextElement, c_spec, element)


def _element_name(element):
    return _m.string(lib.mjs_getString(lib.mjs_getName(element)))


def _check_compilable(c_spec):
    """ValueError for what MuJoCo's compiler takes without a check and crashes on,
    values the MJCF parser refuses but a spec edited in code may hold: a plugin
    element that names no plugin (spec.add_plugin() left as made), a mesh whose
    maxhullvert is 0 to 3 (qhull cannot make such a hull)."""
    for element in _each(c_spec, kinds.mjtObj.mjOBJ_PLUGIN):
        if not _m.string(lib.mjs_getString(lib.mjs_asPlugin(element).plugin_name)):
            raise ValueError(f"plugin {_element_name(element)!r} names no plugin: set its "
                             f"plugin_name (such as 'mujoco.pid', activated with "
                             f"activate_plugin) or delete it")
    for element in _each(c_spec, kinds.mjtObj.mjOBJ_MESH):
        if 0 <= lib.mjs_asMesh(element).maxhullvert <= 3:
            raise ValueError(f"mesh {_element_name(element)!r}: maxhullvert must be larger "
                             f"than 3 (or -1: no limit)")


def _classed(c_spec):
    """The listed elements of a spec that have a default class (mjsElement *)."""
    return [e for items in lifetime.elements_in_order(c_spec).values() for e in items
            if _call(lib.mjcffi_guard_mjs_getDefault, e) != ffi.NULL]


def _reclass_orphans(c_spec, classed):
    """After a default class was deleted: the elements of `classed` whose class went
    with it take the main class.  MuJoCo leaves them naming the deleted class,
    which saving the spec (to_xml) dereferences and crashes on.  Their values are
    their own (a class only gives the values an element starts with), so they
    compile as before, and to_xml writes them in full."""
    main = _call(lib.mjcffi_guard_mjs_getSpecDefault, c_spec)
    for c_element in classed:
        if _call(lib.mjcffi_guard_mjs_getDefault, c_element) == ffi.NULL:
            _call(lib.mjcffi_guard_mjs_setDefault, c_element, main)


def _held(method):
    """The method holds its spec for its whole run, the calls it makes and what it reads
    between them (one thread at a time per spec: mjcffi/_support/spec_claims.py)."""
    what = f"MjSpec.{method.__name__}".encode()

    @functools.wraps(method)
    def run(self, *args, **kwargs):
        with _claims.holding(self._ptr, what):
            return method(self, *args, **kwargs)
    return run


def _label(element):
    """How an error names `element`: "MjsBody 'arm'", or its class alone."""
    name = getattr(element, "name", "")
    return f"{type(element).__name__} {name!r}" if name else type(element).__name__


class MjVisual(_visualize.MjVisual):
    """A spec's visual options: MjVisual, also with `global`, as the official
    spec.visual has (`getattr(spec.visual, 'global')`; `global_` is the same)."""


setattr(MjVisual, "global", _visualize.MjVisual.global_)


class MjSpec(_generated.MjSpec):
    """A model specification: build or edit a model in code, then `compile()` it.

    `MjSpec()` is an empty model; `MjSpec.from_string(xml)` and
    `MjSpec.from_file(path)` parse MJCF.  Element wrappers (`spec.body('torso')`,
    `spec.geoms`) point into the spec and keep it alive.  When MuJoCo frees an
    element (delete, fuse_static, discard_visual, dedup_assets, a compile that
    fuses or discards), its wrapper ends: it still reads the values it had, as
    official, but writes and MuJoCo calls raise.  An operation that would free an
    element whose NumPy views (`geom.size`) are still held is refused instead.
    """

    visual = Nested("visual", lambda: MjVisual, "visual options")

    def __init__(self):
        load_bundled()
        self._adopt_spec(_call(lib.mjcffi_guard_mj_makeSpec), {})

    # --------------------------------------------------------- construction

    def _adopt_spec(self, pointer, assets):
        if pointer == ffi.NULL:
            raise MemoryError("MuJoCo could not allocate the mjSpec")
        self._adopt_root(lifetime.own_spec(pointer), assets)

    def _adopt_root(self, root, assets):
        self._init_root(root)
        self.__dict__.update(_assets=dict(assets), _attached=[], _parent=None,
                             _override_assets=True, _compiled=False, _deep_copy=False,
                             _by_reference=False)

    @classmethod
    def _of(cls, spec):
        """This class over the mjSpec of `spec`, a generated MjSpec wrapper that owns it
        (what mjcffi.mj_parseXMLString and the other raw functions return)."""
        if spec is None or isinstance(spec, cls):
            return spec
        self = cls.__new__(cls)
        self._adopt_root(spec._root, {})
        return self

    @classmethod
    def _new(cls, pointer, assets):
        self = cls.__new__(cls)
        self._adopt_spec(pointer, assets)
        return self

    @classmethod
    def from_string(cls, xml, include=None, assets=None, vfs=None):
        """A spec parsed from MJCF text.  `include` maps the names of the files it
        includes to their bytes; `assets` (file name -> bytes) become the spec's
        `assets`, read when it compiles; `vfs`, an MjVfs, instead of both."""
        _both_given(include, assets, vfs)
        text = _m.text(xml, "xml")
        pointer = cls._parse(lambda c_vfs, error, size: lib.mjcffi_guard_mj_parseXMLString(
            text, c_vfs, error, size), include, assets, vfs, "mj_parseXMLString")
        return cls._new(pointer, check_assets(assets) if assets else {})

    @classmethod
    def from_file(cls, filename, include=None, assets=None, vfs=None):
        """A spec read from a file: MJCF, or any format a decoder is registered for
        (chosen by the file's extension); `include`, `assets`, `vfs` as in
        from_string."""
        _both_given(include, assets, vfs)
        path = _m.text(filename, "filename")
        pointer = cls._parse(lambda c_vfs, error, size: lib.mjcffi_guard_mj_parse(
            path, ffi.NULL, c_vfs, error, size), include, assets, vfs, "mj_parse")
        return cls._new(pointer, check_assets(assets) if assets else {})

    @staticmethod
    def _parse(parser, include, assets, vfs, what):
        load_bundled()              # MJCF may name a plugin, a file may need a decoder
        files = {**check_assets(include or {}, "include"), **check_assets(assets or {})}
        with vfs_pointer(files, vfs) as c_vfs:
            error, error_sz = _m.error_buffer()
            pointer = _call(parser, c_vfs, error, error_sz)
        if pointer == ffi.NULL:
            raise ValueError(_m.error_text(error, what))
        return pointer

    @classmethod
    def from_zip(cls, file):
        """A spec from a zip archive (a path or a binary file object), as to_zip writes
        it: the model is the .xml file nearest the archive's top (there must be one
        only at that depth); the other files, named relative to the model's folder,
        are its assets."""
        import posixpath
        import zipfile
        if not zipfile.is_zipfile(file):
            raise ValueError(f"File {file} is not a zip file.")
        with zipfile.ZipFile(file) as archive:
            files = {name: archive.read(name) for name in archive.namelist()
                     if not name.endswith("/")}
        xmls = [name for name in files if name.endswith(".xml")]
        top = min((name.count("/") for name in xmls), default=0)
        models = [name for name in xmls if name.count("/") == top]
        if len(models) != 1:
            raise ValueError(f"the zip file must hold one .xml file nearest its top, "
                             f"found {len(models)}")
        xml = files.pop(models[0]).decode("utf-8")
        return cls.from_string(xml, assets=relative_names(files, posixpath.dirname(models[0])))

    @_held
    def to_zip(self, file):
        """Write the spec (to_xml(), as '<modelname>.xml') and its assets to a zip
        archive: `file` is a path (its folder is made) or a binary file object."""
        import os
        import zipfile
        files = dict(self._assets)
        files[self.modelname + ".xml"] = self.to_xml()
        if isinstance(file, (str, os.PathLike)):
            folder = os.path.dirname(os.fspath(file))
            if folder:
                os.makedirs(folder, exist_ok=True)
        elif not hasattr(file, "write"):
            raise TypeError(f"file must be a path or a binary file object, "
                            f"not {type(file).__name__}")
        with zipfile.ZipFile(file, "w") as archive:
            for name, content in files.items():
                archive.writestr(zipfile.ZipInfo(name), content)

    # ------------------------------------------------------- spec settings

    @property
    def assets(self):
        """File name -> bytes: the files the spec reads when it compiles.  Setting it
        adds the given files to them (as official)."""
        return self._assets

    @assets.setter
    def assets(self, value):
        self._assets.update(check_assets(value))

    @property
    def override_assets(self):
        """Whether `attach` may replace an asset of this spec by a child's of the same
        name (True); if False, such an attach is refused."""
        return self._override_assets

    @override_assets.setter
    def override_assets(self, value):
        self.__dict__["_override_assets"] = bool(value)

    @property
    def copy_during_attach(self):
        """Write-only: True makes `attach` attach a copy of the child (mjs_setDeepCopy)."""
        raise ValueError("copy_during_attach can only be set.")

    @copy_during_attach.setter
    def copy_during_attach(self, value):
        _call(lib.mjcffi_guard_mjs_setDeepCopy, self._ptr, 1 if value else 0)
        self.__dict__["_deep_copy"] = bool(value)

    @property
    def parent(self):
        """The spec this one was attached to with `attach`, or None."""
        return self._parent

    @property
    def meshdir(self):
        """compiler.meshdir: the folder of mesh and height field files."""
        return self.compiler.meshdir

    @meshdir.setter
    def meshdir(self, value):
        self.compiler.meshdir = value

    @property
    def texturedir(self):
        """compiler.texturedir: the folder of texture files."""
        return self.compiler.texturedir

    @texturedir.setter
    def texturedir(self, value):
        self.compiler.texturedir = value

    @property
    def timer(self):
        """The last compilation's times by mjtCTimer (seconds), a view into the spec."""
        return view(_call(lib.mjcffi_guard_mjs_getTimer, self._ptr), np.dtype(np.float64),
                    (int(mjtCTimer.mjNCTIMER),), self._root)

    def activate_plugin(self, name):
        """Make the registered plugin `name` (such as 'mujoco.pid') usable in the
        spec, as MJCF's <extension><plugin plugin="..."/>."""
        if _call(lib.mjcffi_guard_mjs_activatePlugin, self._ptr, _m.text(name, "name")):
            raise ValueError(f"no plugin named {name!r} is registered")

    # ---------------------------------------------------------- compiling

    def _frees_when_compiled(self):
        return bool(self._ptr.compiler.fusestatic or self._ptr.compiler.discardvisual)

    def _compile(self, c_spec, c_vfs):
        pointer = _call(lib.mjcffi_guard_mj_compile, c_spec, c_vfs)
        if pointer == ffi.NULL:
            raise _spec_error(c_spec, "mj_compile")
        return _model(pointer)

    def _warn(self):
        """MuJoCo's warnings of the last compilation, as UserWarnings."""
        for i in range(_call(lib.mjcffi_guard_mjs_numWarnings, self._ptr)):
            text = _m.string(_call(lib.mjcffi_guard_mjs_getWarning, self._ptr, i))
            if text:
                warnings.warn(text, UserWarning, stacklevel=3)

    @_held
    def compile(self, vfs=None):
        """The compiled MjModel.  Assets come from `assets`, or from `vfs` (an MjVfs;
        not both).  MuJoCo's compile error becomes ValueError, its warnings
        UserWarnings.  With compiler.fusestatic or discardvisual set, compiling
        frees the fused bodies or the visual elements, as fuse_static() and
        discard_visual() do."""
        _check_compilable(self._ptr)
        self.__dict__["_compiled"] = False
        with vfs_pointer(self._assets, vfs) as c_vfs:
            if self._frees_when_compiled():
                model = lifetime.freeing(self, "compile",
                                         lambda c, _: self._compile(c, c_vfs))
            else:
                model = self._compile(self._ptr, c_vfs)
        self.__dict__["_compiled"] = True
        self._warn()
        return model

    @_held
    def recompile(self, m, d, vfs=None):
        """(model, data): the spec compiled again, with the state of `d` (data of
        model `m`) carried over by name, as new objects; `m` and `d` are left as
        they were.  Assets as in compile().  A spec that was not compiled yet is
        compiled first (MuJoCo's mj_recompile reads what compiling left)."""
        c_m, c_d = _m.model_data(m, d)
        _check_compilable(self._ptr)
        if not self._compiled:
            self.compile(vfs)
        with vfs_pointer(self._assets, vfs) as c_vfs:
            new_m = _call(lib.mjcffi_guard_mj_copyModel, ffi.NULL, c_m)
            if new_m == ffi.NULL:
                raise MemoryError("MuJoCo could not copy the model")
            new_d = _call(lib.mjcffi_guard_mj_copyData, ffi.NULL, new_m, c_d)
            if new_d == ffi.NULL:
                lib.mj_deleteModel(new_m)
                raise MemoryError("MuJoCo could not copy the data")

            ran = []

            def recompile(c_spec, _):
                ran.append(True)
                return _call(lib.mjcffi_guard_mj_recompile, c_spec, c_vfs, new_m, new_d)

            try:
                if self._frees_when_compiled():
                    status = lifetime.freeing(self, "recompile", recompile,
                                              rehearsal=lambda c, _: self._compile(c, c_vfs))
                else:
                    status = recompile(self._ptr, None)
            except BaseException:
                if not ran:             # refused before MuJoCo took the copies
                    lib.mj_deleteData(new_d)
                    lib.mj_deleteModel(new_m)
                raise
        if status != 0:
            # MuJoCo freed the copies: nothing of Python's pointed at them
            self.__dict__["_compiled"] = False
            raise _spec_error(self._ptr, "mj_recompile")
        self._warn()
        return self._wrap_compiled(new_m, new_d)

    @staticmethod
    def _wrap_compiled(c_model, c_data):
        from .._support.callbacks import _track
        from ..data import MjData
        model = _model(c_model)
        data = MjData.__new__(MjData)
        data._init_root(ffi.gc(c_data, lib.mj_deleteData), _model=model)
        _track(data)
        return model, data

    # ------------------------------------------------ edits that free elements

    def _counted(self, action, function, *extra):
        """Run mjs_fuseStatic, mjs_discardVisual or mjs_dedupAssets (`function`) as a
        freeing operation; its count, or MuJoCo's error as ValueError."""
        guard = getattr(lib, "mjcffi_guard_" + function)

        def run(c_spec, _):
            return _call(guard, c_spec, *extra)

        count = lifetime.freeing(self, action, run)
        if count < 0:
            raise _spec_error(self._ptr, function)
        return count

    @_held
    def fuse_static(self, vfs=None):
        """Fuse each static body (no joints, `fuse` not false) with its parent: it
        becomes a frame in the parent, holding what the body held; the wrappers
        of the fused bodies end (see MjSpec).  Assets as in compile().  Returns
        the number fused."""
        with vfs_pointer(self._assets, vfs) as c_vfs:
            return self._counted("fuse_static", "mjs_fuseStatic", c_vfs)

    @_held
    def discard_visual(self, vfs=None):
        """Discard the visual elements: every material and texture, the geoms that
        neither collide nor are referred to, and the meshes then unused; their
        wrappers end (see MjSpec).  Assets as in compile(), read only if a body's
        inertia comes from a discarded geom.  Returns the number discarded."""
        with vfs_pointer(self._assets, vfs) as c_vfs:
            return self._counted("discard_visual", "mjs_discardVisual", c_vfs)

    @_held
    def dedup_assets(self):
        """Merge the textures and meshes that would compile to the same asset: the first
        of each group keeps its name, references to the others are rewritten to it
        and the others deleted (their wrappers end, see MjSpec).  Returns the number
        merged."""
        return self._counted("dedup_assets", "mjs_dedupAssets")

    @_held
    def adopt_inertial(self, body, vfs=None):
        """Make the inertial that compilation infers for `body` (a body of this spec)
        its explicit inertial.  Assets as in compile()."""
        c_body = self._typed(body, "body", kinds.mjtObj.mjOBJ_BODY)
        with vfs_pointer(self._assets, vfs) as c_vfs:
            if _call(lib.mjcffi_guard_mjs_adoptInertial, c_body, c_vfs) != 0:
                raise _spec_error(self._ptr, "mjs_adoptInertial")

    @_held
    def copy_back(self, model):
        """Write to the spec the values that were changed in `model`, the model last
        compiled from it, as what compiles to them.  ValueError, with nothing
        written, if a change cannot be expressed in the spec."""
        c_model = _m.struct(model, "mjModel", "model")
        if _call(lib.mjcffi_guard_mj_copyBack, self._ptr, c_model) != 1:
            raise _spec_error(self._ptr, "mj_copyBack")

    # -------------------------------------------------------------- saving

    @_held
    def to_xml(self):
        """The spec as MJCF text.  It compiles the spec first, as the official does
        (see compile(): fusestatic and discardvisual change the spec)."""
        self.compile()
        return save_xml_string(self._ptr)

    def to_file(self, filename):
        """Write to_xml() to `filename`."""
        with open(filename, "w", encoding="utf-8") as file:
            file.write(self.to_xml())

    @_held
    def encode(self, filename, model=None, content_type=None):
        """Write the spec, or `model` compiled from it, to `filename` with the encoder
        registered for its extension or `content_type` (.xml, .mjb, .txt, .mjz).
        With a model, its changed values are copied back first.  Returns the number
        of bytes written; MuJoCo's failure (no encoder, ...) is a FatalError."""
        path = _m.text(filename, "filename")
        c_model = _m.opt_struct(model, "mjModel", "model")
        c_type = ffi.NULL if content_type is None else _m.text(content_type, "content_type")
        error, error_sz = _m.error_buffer()
        with vfs_pointer(self._assets, None) as c_vfs:
            written = _call(lib.mjcffi_guard_mj_encode, self._ptr, c_model, path, c_type,
                            c_vfs, error, error_sz)
        if written < 0:
            raise FatalError(_m.error_text(error, "mj_encode"))
        return written

    # ------------------------------------------------------------- copying

    @_held
    def copy(self):
        """An independent deep copy of the spec (mj_copySpec), with its assets,
        override_assets and parent."""
        other = type(self)._new(_call(lib.mjcffi_guard_mj_copySpec, self._ptr), self._assets)
        other.__dict__.update(_override_assets=self._override_assets, _parent=self._parent,
                              _deep_copy=self._deep_copy, _by_reference=self._by_reference)
        return other

    def __copy__(self):
        return self.copy()

    def __deepcopy__(self, memo):
        other = self.copy()
        other.__dict__["_assets"] = _copy.deepcopy(self._assets, memo)
        return other

    # ------------------------------------------------------------ elements

    def _element(self, element):
        """The one wrapper of element pointer `element` (None for NULL)."""
        return lifetime.wrap(self, element)

    def _elements(self, type_):
        found = []
        element = _call(lib.mjcffi_guard_mjs_firstElement, self._ptr, type_)
        while element != ffi.NULL:
            found.append(self._element(element))
            element = _call(lib.mjcffi_guard_mjs_nextElement, self._ptr, element)
        return found

    def _find(self, type_, name):
        found = lib.mjcffi_guard_mjs_findElement(self._ptr, type_, _m.text(name, "name"))
        _m.check_error()
        return _elements.wrap(found, self)

    def find_all(self, type):
        """Every element of `type` (an mjtObj, or a name such as 'site'), in order."""
        return self._elements(kinds.object_type(type))

    @property
    def worldbody(self):
        """The world body, root of the kinematic tree."""
        return self._element(_call(lib.mjcffi_guard_mjs_findBody, self._ptr, b"world"))

    @property
    def default(self):
        """The main default class ('main'), the root of all others."""
        return self._element(_call(lib.mjcffi_guard_mjs_getSpecDefault, self._ptr))

    def find_default(self, classname):
        """The default class named `classname`, or None."""
        return self._element(_call(lib.mjcffi_guard_mjs_findDefault, self._ptr,
                                   _m.text(classname, "classname")))

    @_held
    def add_default(self, classname, parent=None):
        """A new default class `classname` under `parent` (a default of this spec;
        None: the main one).  ValueError if the name is taken."""
        c_name = _m.text(classname, "classname")
        c_parent = ffi.NULL if parent is None else self._typed(
            parent, "parent", kinds.mjtObj.mjOBJ_DEFAULT)
        pointer = _call(lib.mjcffi_guard_mjs_addDefault, self._ptr, c_name, c_parent)
        if pointer == ffi.NULL:
            raise ValueError(f"default class {classname!r} exists already")
        return self._element(pointer)

    @_held
    def delete(self, element):
        """Remove `element` from the spec: with a body, frame or default, all it holds;
        with them, the elements that refer to what was removed.  The wrappers of
        what MuJoCo freed end (see MjSpec).  Refused (ValueError) while NumPy
        views of an element it would free are held."""
        attached = "Cannot delete element from an attached mjSpec."
        c_element = self._element_pointer(element, "element", attached_message=attached)
        if c_element == _call(lib.mjcffi_guard_mjs_findBody, self._ptr, b"world").element:
            raise ValueError("the world body cannot be deleted")

        def delete(c_spec, counterpart):
            if _call(lib.mjcffi_guard_mjs_delete, c_spec, counterpart(c_element)) != 0:
                raise _spec_error(c_spec, "mjs_delete")

        is_default = int(c_element.elemtype) == int(kinds.mjtObj.mjOBJ_DEFAULT)
        classed = _classed(self._ptr) if is_default else ()
        lifetime.freeing(self, f"delete {_label(element)}", delete)
        if is_default:
            _reclass_orphans(self._ptr, classed)

    def _element_pointer(self, element, name, owner_message=None, attached_message=None):
        """The mjsElement * of an element wrapper of this spec.  An element moved into
        the spec this one is attached to gets `attached_message`; one of another
        spec `owner_message`."""
        if lifetime.is_deleted(element):
            kind = type(element).__name__
            raise ValueError(f"{kind[3:].lower() if kind.startswith('Mjs') else 'element'} "
                             f"is not in this model")
        try:
            c_element = element._ptr.element
        except AttributeError:
            raise TypeError(f"{name} must be a spec element, not "
                            f"{type(element).__name__}") from None
        if isinstance(element, MjSpec) or not isinstance(c_element, ffi.CData) or \
                ffi.typeof(c_element) is not ffi.typeof("mjsElement *") or \
                c_element == ffi.NULL:      # the plugin slot of a body, say
            raise TypeError(f"{name} must be a spec element, not {type(element).__name__}")
        if int(c_element.elemtype) != int(kinds.mjtObj.mjOBJ_DEFAULT) and \
                _call(lib.mjcffi_guard_mjs_getCompiler, c_element) == ffi.NULL:
            raise ValueError(f"{name} is not attached to a spec: a default class's "
                             f"template ({type(element).__name__} of an MjsDefault)")
        if int(c_element.elemtype) not in kinds.BY_TYPE and \
                int(c_element.elemtype) != int(kinds.mjtObj.mjOBJ_DEFAULT):
            raise TypeError(f"{name} must be a spec element such as an MjsBody, not "
                            f"{type(element).__name__}")
        if int(c_element.elemtype) == int(kinds.mjtObj.mjOBJ_DEFAULT):
            # mjs_getSpec reads no spec from a default: it is found by its name
            found = _call(lib.mjcffi_guard_mjs_findDefault, self._ptr,
                          lib.mjs_getString(lib.mjs_getName(c_element)))
            if found == ffi.NULL or found.element != c_element:
                raise ValueError(owner_message or f"{name} belongs to another spec")
            return c_element
        owner = _call(lib.mjcffi_guard_mjs_getSpec, c_element)
        if owner != self._ptr:
            origin = _call(lib.mjcffi_guard_mjs_getOriginSpec, c_element)
            if attached_message and origin == self._ptr and self._parent is not None:
                raise ValueError(attached_message)
            raise ValueError(owner_message or f"{name} belongs to another spec")
        return c_element

    def _typed(self, element, name, type_):
        """The typed struct pointer (mjsBody *, ...) of `element`, which must be an
        element of this spec of mjtObj `type_`."""
        cls = _generated.MjsDefault if int(type_) == int(kinds.mjtObj.mjOBJ_DEFAULT) \
            else _attach.wrapper_class(type_)
        if not isinstance(element, cls):
            raise TypeError(f"{name} must be an {cls.__name__}, not {type(element).__name__}")
        self._element_pointer(element, name)
        return element._ptr

    # ---------------------------------------------------------------- attach

    @_held
    def attach(self, child, prefix=None, suffix=None, site=None, frame=None):
        """Attach spec `child` at `frame` or `site` (an element of this spec or its
        name); its names get `prefix` (default '/') and `suffix`.  Returns the frame
        that the child's world body became.  Its assets join this spec's, renamed
        likewise (ValueError, and nothing attached, if one is taken and
        override_assets is False).  MuJoCo attaches a spec once unless
        copy_during_attach is set: attach `child.copy()` to place it again."""
        if not isinstance(child, MjSpec):
            raise TypeError(f"child must be an MjSpec, not {type(child).__name__}")
        prefix = _attach.DEFAULT_PREFIX if prefix is None else prefix
        suffix = "" if suffix is None else suffix
        c_prefix, c_suffix = _m.text(prefix, "prefix"), _m.text(suffix, "suffix")
        point = _attach.attach_point(self, site, frame)
        assets = _attach.renamed_assets(self, child, prefix, suffix)
        result = _call(lib.mjcffi_guard_mjs_attach, point, child._ptr.element,
                       c_prefix, c_suffix)
        if result == ffi.NULL:
            raise _spec_error(self._ptr, "mjs_attach")
        self._assets.update(assets)
        _attach.warn_mixed_assets(self, child)
        if child.assets:
            _attach.rename_files(child, prefix, suffix)
        self._attached.append(child)        # MuJoCo may read the child until compiled
        child.__dict__.update(_parent=self, _by_reference=not self._deep_copy)
        return self._element(result)

    # -------------------------------------------------------------- display

    def _repr_html_(self):
        """Jupyter's display: the model name, timestep, element counts and the body
        tree with each body's geoms, joints and sites (at most 200 bodies; see
        mjcffi/_support/display.py).  A spec another thread holds shows a short note."""
        from .._support import display
        return display.safe(self, lambda: display.spec_html(self))

    # ----------------------------------------------------------- orientation

    @staticmethod
    def resolve_orientation(degree, sequence=None, orientation=None):
        """The quaternion [w, x, y, z] of `orientation` (an MjsOrientation, such as
        body.alt), its angles in degrees if `degree`, its Euler sequence `sequence`
        (such as compiler.eulerseq; None: 'xyz')."""
        if not isinstance(orientation, _generated.MjsOrientation):
            raise TypeError(f"orientation must be an MjsOrientation, "
                            f"not {type(orientation).__name__}")
        if sequence is None:
            sequence = "xyz"
        elif not isinstance(sequence, (str, bytes)):
            try:
                sequence = "".join(sequence)
            except TypeError:
                raise TypeError(f"sequence must be str such as 'xyz' or a sequence of "
                                f"its letters, not {type(sequence).__name__}") from None
        c_sequence = _m.text(sequence, "sequence")
        if len(c_sequence) != 3:
            raise ValueError(f"sequence must be 3 axes such as 'xyz', got {sequence!r}")
        quat = ffi.new("double[4]")
        error = _call(lib.mjcffi_guard_mjs_resolveOrientation, quat, 1 if degree else 0,
                      c_sequence, orientation._ptr)
        if error != ffi.NULL:
            raise ValueError(_m.string(error))
        return list(quat)


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


def _model(pointer):
    """An MjModel owning `pointer`, a new mjModel."""
    return MjModel._from_root(ffi.gc(pointer, lib.mj_deleteModel))
