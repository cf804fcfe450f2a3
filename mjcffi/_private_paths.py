"""The official bindings' private modules that real code names, without a file here.

`mujoco._errors`, `_callbacks`, `_render`, `_rollout`, `_specs` and `_batch` are the
official bindings' compiled modules; code and pickles name them (`from
mujoco._errors import FatalError`).  Each is a module made here, holding mjcffi's
equivalent of every official name it has one for, imported on first use, and
importable as `mjcffi._errors` (and as `mujoco._errors` under the swap).
`mjcffi._enums`, `_constants`, `_structs` and `_functions` are modules of their own.

Names the official modules hold that mjcffi has no equivalent of are left out:
`_errors.UnexpectedError` (mjcffi raises no such error) and `_specs.MjByteVec`
(no spec field of MuJoCo 4.0 is a byte vector).
"""

import importlib
import importlib.util
import sys

# module -> {official name: where mjcffi has it}: "Name" is mjcffi.Name, ".mod:Name" is
# mjcffi.mod.Name (names of MuJoCo 4.0's official modules)
MODULES = {
    "_errors": {"FatalError": "FatalError"},
    "_callbacks": {f"{verb}_{name}": f"{verb}_{name}" for verb in ("get", "set") for name in (
        "mjcb_act_bias", "mjcb_act_dyn", "mjcb_act_gain", "mjcb_contactfilter",
        "mjcb_control", "mjcb_passive", "mjcb_sensor", "mjcb_time", "mju_user_free",
        "mju_user_malloc", "mju_user_warning")},
    "_render": {name: name for name in (
        "MjrContext", "MjrRendererInfo", "mjr_addAux", "mjr_blitAux", "mjr_blitBuffer",
        "mjr_changeFont", "mjr_defaultRendererInfo", "mjr_drawPixels", "mjr_figure",
        "mjr_findRect", "mjr_finish", "mjr_getError", "mjr_getRendererInfo", "mjr_label",
        "mjr_maxViewport", "mjr_overlay", "mjr_readPixels", "mjr_rectangle", "mjr_render",
        "mjr_resizeOffscreen", "mjr_restoreBuffer", "mjr_setAux", "mjr_setBuffer",
        "mjr_text", "mjr_uploadHField", "mjr_uploadMesh", "mjr_uploadTexture")},
    "_rollout": {"Rollout": ".rollout:Rollout"},
    "_specs": {
        **{name: name for name in (
            "MjCharVec", "MjDoubleVec", "MjFloatVec", "MjIntVec", "MjOption", "MjSpec",
            "MjStatistic", "MjStringVec", "MjVfs", "MjVisualHeadlight", "MjVisualRgba",
            "MjsActuator", "MjsAuthored", "MjsBody", "MjsCamera", "MjsCompiler",
            "MjsDefault", "MjsElement", "MjsEquality", "MjsExclude", "MjsFlex", "MjsFrame",
            "MjsGeom", "MjsHField", "MjsJoint", "MjsKey", "MjsLight", "MjsMaterial",
            "MjsMesh", "MjsNumeric", "MjsOrientation", "MjsPair", "MjsPlugin", "MjsSensor",
            "MjsSite", "MjsSkin", "MjsTendon", "MjsTendonPath", "MjsText", "MjsTexture",
            "MjsTuple", "MjsWrap")},
        "MjVisual": ".spec.spec:MjVisual",      # a spec's visual (spec.visual), as official
    },
    "_batch": {"Batch": ".batch:Batch"},
}

_PACKAGE = __name__.rpartition(".")[0]     # mjcffi


def resolve(target):
    """The object `target` (a value of MODULES) names, imported now."""
    module, _, attr = target.rpartition(":")
    owner = importlib.import_module(module or _PACKAGE, _PACKAGE)
    return getattr(owner, attr)


class _Loader:
    """Makes one module of MODULES: its names resolve on first use (PEP 562)."""

    def __init__(self, short):
        self.short = short

    def create_module(self, spec):
        return None                     # a plain module

    def exec_module(self, module):
        table = MODULES[self.short]
        module.__doc__ = (f"The official `mujoco.{self.short}` path: mjcffi's "
                          f"{', '.join(sorted(table))}.")
        module.__all__ = sorted(table)

        def __getattr__(name):
            target = table.get(name)
            if target is None:
                raise AttributeError(f"module {module.__name__!r} has no attribute {name!r}")
            value = resolve(target)
            setattr(module, name, value)
            return value

        def __dir__():
            return sorted(set(vars(module)) | set(table))

        module.__getattr__ = __getattr__
        module.__dir__ = __dir__


class PrivatePathFinder:
    """A meta path finder for `mjcffi._errors` and the other modules of MODULES."""

    @staticmethod
    def find_spec(fullname, path=None, target=None):
        package, dot, short = fullname.partition(".")
        if package != _PACKAGE or short not in MODULES:
            return None
        return importlib.util.spec_from_loader(fullname, _Loader(short))


def install():
    """Put the finder on sys.meta_path (once)."""
    if PrivatePathFinder not in sys.meta_path:
        sys.meta_path.append(PrivatePathFinder)
