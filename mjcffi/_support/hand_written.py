"""How the generated function layer reaches the hand-written functions.

`mujoco._functions.mj_step` is a path of the official bindings, and mjcffi's mj_step is
hand-written (mjcffi/functions/_overrides.py), a tier above the generated
mjcffi._functions, which may not import it.  So the package registers a resolver here
when it is imported (mjcffi/__init__.py), and mjcffi._functions asks it for the few
names it does not define.
"""

resolve = None      # name -> the hand-written function; set by mjcffi/__init__.py


def function(name):
    """The hand-written function `name`, through the registered resolver."""
    if resolve is None:           # only while mjcffi itself is still being imported
        raise AttributeError(f"mjcffi._functions.{name} is hand-written: "
                             f"use mjcffi.{name}")
    return resolve(name)
