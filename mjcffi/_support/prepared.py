"""Prepared calls: a MuJoCo function with its arguments checked and converted once.

    jac = mjcffi.mj_jac.prepare(m, d, jacp, jacr, point, body)
    for _ in range(1000):
        point[:] = ...          # the arrays are live: the next call reads the new values
        jac()                   # the guarded C call, no marshalling

Every function of the function layer has `prepare`.  It runs the function's
checks and conversions now (so a bad argument raises here, as the plain call
would) and returns a `Prepared` call.  Calling that makes the same guarded C
call with the C arguments made then: a mju_error raises FatalError, a Python
callback's exception is raised, and the mjData is held for the call, all as in
a plain call, and the outputs are the same bits.

What a prepared call binds, it binds for its life: the model, the data and the
arrays, kept alive by it.  It also holds a weak reference to each array (and to
the arrays its memory comes from), for which NumPy refuses `resize` even with
`refcheck=False`: the block a prepared call writes into is never freed under it.
So an input array must be used as it is, zero-copy: prepare refuses one that the
plain call would have converted (a list, another dtype, a non-contiguous
array), since the copy would never see later changes.  It refuses an array on an
mjData's stack (mj_stackAllocNum, ...) too: MuJoCo releases that memory
(mj_freeStack, mj_resetData) and hands it to the next allocation.  A function whose checks
read what can change between calls (an id stored in a struct such as
mjvPerturb.select, an mjData count such as nefc, an OpenGL context, the index
values of an input array) is prepared with its checks bound instead: each call
of it runs the plain function again, checks and all (`Prepared.rechecks`).

Support module: imports only the standard library, NumPy, errors.py and stack.py.
"""

import inspect
import reprlib
import weakref
from typing import Any, Callable, Generic, ParamSpec, Protocol, TypeVar

import numpy as np

from . import stack as _stack
from .errors import ArgumentError, with_note

P = ParamSpec("P")
R = TypeVar("R")

__all__ = ["Prepared", "Preparer", "Function", "preparable"]


class Prepared(Protocol[R]):
    """A prepared call (what `F.prepare(...)` returns): call it with no arguments.

    It is the call itself, a plain function, so that calling it costs one Python call
    and the guarded C call.  `function` is F, `arguments` its arguments by name (kept
    alive here), `rechecks` whether each call runs F's checks again (see this module's
    docstring); its repr names F and the arguments."""

    function: Callable[..., R]
    arguments: dict
    rechecks: bool

    def __call__(self) -> R: ...


def _describe(value):
    """A short account of an argument: arrays by dtype and shape, structs by class."""
    if value is None or isinstance(value, (bool, int, float, str, bytes)):
        return reprlib.repr(value)
    shape, dtype = getattr(value, "shape", None), getattr(value, "dtype", None)
    if shape is not None and dtype is not None:
        return f"<{type(value).__name__} {dtype} {tuple(shape)}>"
    return f"<{type(value).__name__}>"


class Preparer(Generic[P, R]):
    """`F.prepare`: `F.prepare(*args)` checks and converts F's arguments once and
    returns a Prepared call (see mjcffi/_support/prepared.py).

    `marshal(*args, prepare=True)` runs F's checks and conversions and returns the
    guarded C call; None for a function whose checks F makes itself at each call
    (most hand-written ones).  `recheck`: each call runs F.  `unsupported`: why F
    raises NotImplementedError, which prepare raises too.
    """

    __slots__ = ("function", "_marshal", "_recheck", "_unsupported", "_signature")

    def __init__(self, function, marshal, recheck, unsupported=None):
        self.function = function
        self._marshal = marshal
        self._recheck = recheck or marshal is None
        self._unsupported = unsupported
        self._signature = None

    def __call__(self, *args: P.args, **kwargs: P.kwargs) -> Prepared[R]:
        function = self.function
        try:
            bound = self.__signature__.bind(*args, **kwargs)
        except TypeError as exc:
            raise TypeError(f"{function.__name__}.prepare(): {exc}") from None
        if self._unsupported is not None:
            raise NotImplementedError(f"{function.__name__}: {self._unsupported}")
        if self._marshal is not None:
            call = self._marshal(*args, prepare=True, **kwargs)   # raises what F would
        if self._marshal is None or self._recheck:
            def call():
                return function(*args, **kwargs)
        bound.apply_defaults()
        if _stack.made:
            _refuse_stack_arrays(function, bound.arguments)
        call._locks = _locks(bound.arguments)
        call.function = function
        call.arguments = dict(bound.arguments)
        call.rechecks = self._recheck
        described = ", ".join(f"{name}={_describe(value)}"
                              for name, value in call.arguments.items())
        again = " (rechecked)" if self._recheck else ""
        call.__name__ = call.__qualname__ = f"{function.__name__}.prepare({described}){again}"
        call.__doc__ = Prepared.__doc__
        return call

    @property
    def __signature__(self):
        if self._signature is None:
            self._signature = inspect.signature(self.function)
        return self._signature

    def __repr__(self):
        return f"<prepare of {self.function.__module__}.{self.function.__name__}>"


def _locks(arguments):
    """A weak reference to each array argument and to each array its memory comes
    from (its `base` chain): NumPy refuses to resize an array that has one, even
    with refcheck=False, so the memory stays where the C pointers point.  The
    prepared call keeps them, and the lock ends with it.  No cost per call."""
    locks = []
    for value in arguments.values():
        while isinstance(value, np.ndarray):
            locks.append(weakref.ref(value))
            value = value.base
    return locks


def _refuse_stack_arrays(function, arguments):
    """ArgumentError if an argument is (a view of) an array on an mjData's stack."""
    for name, value in arguments.items():
        if isinstance(value, np.ndarray) and _stack.of(value) is not None:
            raise with_note(
                ArgumentError(f"{function.__name__}.prepare(): {name} is an array on an "
                              f"MjData's stack (mj_stackAllocNum, mj_stackAllocInt, "
                              f"mj_stackAllocByte); a prepared call would go on writing "
                              f"through its pointer after MuJoCo releases it (mj_freeStack, "
                              f"mj_resetData, the reset of a bad state) and hands that "
                              f"memory to the next allocation"),
                f"pass an array of your own (np.array({name}) copies it), or call "
                f"{function.__name__} without prepare while the stack frame lives")


class Function(Protocol[P, R]):
    """What the type checker sees of a function of the function layer: itself, and
    its `prepare`."""

    prepare: Preparer[P, R]

    def __call__(self, *args: P.args, **kwargs: P.kwargs) -> R: ...


def preparable(marshal: Callable[..., Callable[[], Any]] | None, recheck: bool = False,
               unsupported: str | None = None
               ) -> Callable[[Callable[P, R]], Function[P, R]]:
    """Give the decorated function its `prepare` (a Preparer of `marshal`); the function
    itself is returned unchanged, so a plain call costs nothing more."""
    def attach(function):
        function.prepare = Preparer(function, marshal, recheck, unsupported)
        return function
    return attach
