"""What the fuzzer calls: a Target has Params; a call varies one of them.

A call is named by its key, `target|param|label`:
- `fn:mj_jac|body|2**31-1`: mj_jac with a valid call's arguments, except
  body=2**31-1 (the label names a maker of values.py's table for the param's kind);
- `fn:mj_jac|-|valid`: the valid call itself;
- `named:geom|key|-1`, ...: the same for the other entry points (entries.py);
- `case:<name>|-|<label>`: a hand-written case (entries.py) that is its own call.
The key is all a worker needs to rebuild the call, so that a crash found in a
batch can be replayed alone (`python -m tests.fuzz --replay KEY`).
"""

from dataclasses import dataclass

from . import values
from .values import Ctx, NotApplicable

# The documented exception types: what any public entry point may raise.
def documented():
    import mjcffi
    return (TypeError, ValueError, IndexError, KeyError, mjcffi.FatalError)


@dataclass
class Param:
    name: str
    kind: str                   # a key of values.KINDS, or one the fuzzer only passes None for
    elem: str = ""
    const: bool = True
    nullable: bool = False


class Target:
    group = "entry"
    allowed = ()                # exception types documented for this entry point only

    def __init__(self, name):
        self.name = name
        self.params = []

    # subclasses: valid(env) -> {param: value}; call(env, kwargs) -> result
    def valid(self, env):
        raise NotImplementedError

    def call(self, env, kwargs):
        raise NotImplementedError

    def count(self, param, env):
        """For an id parameter, the count it must stay below (for `count`, `count+1`)."""
        return None

    def labels(self, param):
        """The variation labels of `param`."""
        return list(values.table(param.kind))

    def keys(self):
        """Every call key of this target: the valid call, then each param's variations."""
        out = [f"{self.name}|-|valid"]
        for p in self.params:
            out.extend(f"{self.name}|{p.name}|{label}" for label in self.labels(p))
        return out

    def make(self, param_name, label, env):
        """(thunk, description) of one call; NotApplicable if the variation means nothing."""
        kwargs = self.valid(env)
        extra = {}
        if param_name != "-":
            param = next(p for p in self.params if p.name == param_name)
            maker = values.table(param.kind)[label]
            ctx = Ctx(env=env, kind=param.kind, valid=kwargs.get(param_name),
                      elem=param.elem, const=param.const, count=None, extra=extra)
            if label.startswith("count"):
                ctx.count = self.count(param, env)
            kwargs[param_name] = maker(ctx)
        elif label != "valid":
            raise NotApplicable(label)

        def thunk():
            return self.call(env, kwargs)
        thunk.keep = extra                     # objects the value needs alive
        return thunk, _describe(self, kwargs, param_name)


def _short(value):
    import numpy as np
    if isinstance(value, np.ndarray):
        flags = "" if value.flags.c_contiguous else " non-contiguous"
        ro = "" if value.flags.writeable else " read-only"
        return f"<array {value.shape} {value.dtype}{flags}{ro}>"
    if hasattr(value, "_cname") and not isinstance(value, type):
        return f"<{type(value).__name__}>"
    text = repr(value)
    if len(text) > 60:
        text = text[:57] + "..."
    return text


def _describe(target, kwargs, varied):
    args = ", ".join(("*" if k == varied else "") + f"{k}={_short(v)}"
                     for k, v in kwargs.items())
    name = target.name.split(":", 1)[-1]
    return f"{name}({args})"


class Case(Target):
    """A hand-written call with labelled variants, each its own function of the Env."""

    def __init__(self, name, variants, allowed=()):
        super().__init__("case:" + name)
        self.variants = variants            # label -> function(env)
        self.allowed = allowed

    def keys(self):
        return [f"{self.name}|-|{label}" for label in self.variants]

    def make(self, param_name, label, env):
        function = self.variants[label]

        def thunk():
            return function(env)
        thunk.keep = {}
        doc = (function.__doc__ or "").strip().splitlines()
        return thunk, f"{self.name[5:]}: {label}" + (f" ({doc[0]})" if doc else "")
