"""Objects of the official bindings passed to mjcffi: errors that say so.

Both bindings load in one process, and their classes share names (MjModel, MjData,
MjvOption, ...): "m must be MjModel, not MjModel" said nothing.  The argument checks
call `not_accepted` on their error path only, so the checks cost nothing more.

Support module: imports only the standard library.
"""

# What to do instead, by the class expected; the rest: make one with mjcffi
_INSTEAD = {
    "MjModel": "load the model with mjcffi (mjcffi.MjModel.from_xml_path / "
               "from_binary_path / from_xml_string)",
    "MjData": "make the data with mjcffi.MjData(model) from an mjcffi.MjModel",
    "MjSpec": "load the spec with mjcffi (mjcffi.MjSpec.from_file / from_string)",
    "MjvScene": "make the scene with mjcffi.MjvScene(model, maxgeom)",
    "MjrContext": "make the context with mjcffi.MjrContext(model, fontscale) in an mjcffi "
                  "GL context",
}


def is_official(value):
    """Whether `value` (or the class `value`) comes from the official `mujoco` package
    (mujoco._structs.MjModel, ...); never true of mjcffi's own classes."""
    cls = value if isinstance(value, type) else type(value)
    module = getattr(cls, "__module__", None) or ""
    return module.partition(".")[0] == "mujoco" and not hasattr(cls, "_cname")


def type_name(value):
    """The name of `value`'s class for an error: with its module when it comes from
    the official bindings (mujoco._structs.MjModel), plain otherwise."""
    cls = value if isinstance(value, type) else type(value)
    if is_official(cls):
        return f"{cls.__module__}.{cls.__qualname__}"
    return cls.__name__


def not_accepted(name, expected, value):
    """The TypeError for an official object `value` given as argument `name`, where an
    mjcffi `expected` (a class name: 'MjModel'; 'Mjs' for any spec element) is needed."""
    what = f"the class {type_name(value)} itself" if isinstance(value, type) else \
        type_name(value)
    if expected.startswith("Mjs"):
        instead = "take the element from an mjcffi.MjSpec (mjcffi.MjSpec.from_file / from_string)"
        wanted = "an mjcffi spec element" if expected == "Mjs" else f"an mjcffi.{expected}"
    else:
        instead = _INSTEAD.get(expected, f"make one with mjcffi.{expected}()")
        wanted = f"an mjcffi.{expected}"
    view = (f"; mjcffi.{expected}.from_official({name}) views an official one without a "
            f"copy" if expected in _VIEWS and not isinstance(value, type) else "")
    return TypeError(f"{name} must be {wanted}, not {what}: objects of the official bindings "
                     f"are not accepted here; {instead}, or pass mjcffi objects{view}")


# the classes whose official objects mjcffi can view (mjcffi/_support/official_objects.py)
_VIEWS = ("MjModel", "MjData")
