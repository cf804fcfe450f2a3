"""Render mjcffi/_c/generated/guards.h and guards.c: one guarded call per MuJoCo function.

`mjcffi_guard_F` calls F with a setjmp target armed, so that mju_error inside
F returns to the caller instead of exiting the process.  A void F gets an int
guard (0: ok, 1: error caught); any other F a guard of the same return type
that returns the zero value on a caught error.  Either way the message waits
for mjcffi_take_error().  The machinery (the thread-local chain of guards, the
log handler, the message) is hand-written in mjcffi/_c/guard.c.

A function that writes an mjData (a non-const `mjData *` argument) holds it for
the call (mjcffi_data_enter/leave in mjcffi/_c/claims.c): another thread's call on the
same mjData is refused, and so is, inside a call on this thread, one of
RESTARTS, which reset the arena that the running call is filling.

A function taking an mjSpec or a spec element holds the spec for the call
(mjcffi_spec_enter/leave in mjcffi/_c/claims.c): another thread's call on the same
spec is refused.  The spec is found before the call (mjcffi_spec_of), so a call that
deletes the element or the spec releases it all the same.  One taking an mjBatch
holds it (mjcffi_batch_enter/leave): a second call on it while it runs is refused.

A few calls are first checked by hand-written C (PRECHECKS): mjr_makeContext
refuses to run without an OpenGL library, as an error inside it cannot be
caught twice.

Variadic functions (mju_error, mju_warning, mju_info) get a guard that takes
the fixed arguments only and passes the last one, the message, through "%s":
a message from Python is never a format string.
"""

import re

from .outputs import HEADER_C

_C_HEAD = """\
/* One guard per MuJoCo function: the same call, with mju_error turned into a
   return.  The machinery is in ../guard.c; mjcffi_take_error() gives the message. */

#include <string.h>

#include <mujoco/mujoco.h>
#include <mujoco/mjbatch.h>

#include "guard_chain.h"
#include "claims.h"
#include "guards.h"
"""

_H_HEAD = """\
/* mjcffi_guard_F(args): F(args) with MuJoCo's fatal errors caught, thread-locally.
   A void F gives int: 0 ok, 1 error caught.  Any other F gives F's result, or
   zero when an error was caught.  mjcffi_take_error() (in ../guard.h) returns
   the message.  Read into the cffi cdef and included by the compiled module. */
"""

# Calls that reset an mjData's arena or rerun the pipeline that fills it: never
# nested inside another call on the same mjData (a callback's re-entry).
RESTARTS = frozenset({
    "mj_step", "mj_step1", "mj_step2", "mj_forward", "mj_inverse", "mj_forwardSkip",
    "mj_inverseSkip", "mj_fwdPosition", "mj_invPosition", "mj_collision",
    "mj_makeConstraint", "mj_island", "mj_fwdConstraint", "mj_Euler", "mj_RungeKutta",
    "mj_implicit", "mj_resetData", "mj_resetDataDebug", "mj_resetDataKeyframe",
    "mj_copyData", "mjv_copyData", "mj_setState", "mj_copyState", "mj_deleteData",
    "mj_recompile", "mj_setConst", "mj_setLengthRange", "mjd_transitionFD", "mjd_inverseFD",
    "mj_compareFwdInv", "mj_checkPos", "mj_checkVel", "mj_checkAcc", "mjb_getData",
})

# Calls checked before MuJoCo runs by a hand-written C function of mjcffi/_c/gl.c (0: go on),
# with another called when MuJoCo raised: (enter, failed).
PRECHECKS = {"mjr_makeContext": ("mjcffi_render_enter", "mjcffi_render_failed")}

_ARRAY = re.compile(r"^(.*?)\s*((?:\[\d*\])+)$")


def _named(decl, name):
    """C declaration of parameter `name` from its abstract type spelling."""
    if "(*)" in decl:                           # a function pointer
        return decl.replace("(*)", f"(*{name})", 1)
    match = _ARRAY.match(decl)
    if match:                                   # keep `mjtNum res[3]`: cffi accepts it
        return f"{match.group(1)} {name}{match.group(2)}"
    return f"{decl}{name}" if decl.endswith("*") else f"{decl} {name}"


def _signature(func):
    """(return decl, [(name, decl)], variadic) of a parsed or _funcinfo Function."""
    restype = func.restype if isinstance(func.restype, str) else func.restype.decl
    args = [(a.name, a.ctype if hasattr(a, "ctype") else a.type.decl) for a in func.args]
    variadic = bool(args) and args[-1][1] == "..."
    if variadic:
        args = args[:-1]
        if not args or args[-1][1] != "const char *":
            raise ValueError(f"{func.name}: a variadic function without a message argument")
    return restype, args, variadic


def _held_data(func, args):
    """The name of the mjData argument `func` writes, or None."""
    names = [name for name, decl in args if decl.replace(" ", "") == "mjData*"]
    if len(names) > 1:
        raise ValueError(f"{func.name}: more than one mjData to hold")
    return names[0] if names else None


_SPEC_ARG = re.compile(r"^(?:const)?(mjSpec|mjs[A-Z]\w*)\*$")
_NOT_ELEMENTS = frozenset({"mjsOrientation", "mjsCompiler"})   # parts, not elements


def _held_specs(args):
    """The C expressions of the specs `args` reach: an mjSpec, or the spec of an element."""
    found = []
    for name, decl in args:
        match = _SPEC_ARG.match(decl.replace(" ", ""))
        if not match or match.group(1) in _NOT_ELEMENTS:
            continue
        if match.group(1) == "mjSpec":
            found.append(name)
        elif match.group(1) == "mjsElement":
            found.append(f"mjcffi_spec_of({name})")
        else:
            found.append(f"mjcffi_spec_of({name} ? {name}->element : NULL)")
    return found


def _guard(func):
    """(prototype, definition) of mjcffi_guard_<func.name>."""
    restype, args, variadic = _signature(func)
    held = _held_data(func, args)
    void = restype == "void"
    params = ", ".join(_named(decl, name) for name, decl in args) or "void"
    head = _named("int" if void else restype, f"mjcffi_guard_{func.name}({params})")
    call_args = [name for name, _ in args]
    if variadic:
        call_args.insert(len(call_args) - 1, '"%s"')
    call = f"{func.name}({', '.join(call_args)})"
    specs = _held_specs(args)
    batch = next((name for name, decl in args if decl.replace(" ", "") == "mjBatch*"), None)
    release = [f"  mjcffi_spec_leave(mjcffi_s{i});" for i in reversed(range(len(specs)))]
    release += [f"  mjcffi_data_leave({held});"] if held else []
    release += [f"  mjcffi_batch_leave({batch});"] if batch else []
    zero = ["  memset(&mjcffi_result, 0, sizeof mjcffi_result);"] if not void else []
    failed = "1" if void else "mjcffi_result"
    lines = [head + " {",
             "  mjcffi_guard mjcffi_g;"]
    if not void:
        lines.append(f"  {_named(restype, 'mjcffi_result')};")
    if held:
        restarts = int(func.name in RESTARTS)
        lines += [f'  if (mjcffi_data_enter({held}, {restarts}, "{func.name}")) {{',
                  *["  " + line for line in zero],
                  f"    return {failed};", "  }"]
    if batch:
        lines += [f'  if (mjcffi_batch_enter({batch}, "{func.name}")) {{',
                  *([f"    mjcffi_data_leave({held});"] if held else []),
                  *["  " + line for line in zero], f"    return {failed};", "  }"]
    for i, spec in enumerate(specs):
        lines.append(f"  const mjSpec* mjcffi_s{i} = {spec};")
    for i in range(len(specs)):
        undo = [f"    mjcffi_spec_leave(mjcffi_s{j});" for j in reversed(range(i))]
        undo += [f"    mjcffi_data_leave({held});"] if held else []
        undo += [f"    mjcffi_batch_leave({batch});"] if batch else []
        lines += [f'  if (mjcffi_spec_enter(mjcffi_s{i}, "{func.name}")) {{', *undo,
                  *["  " + line for line in zero], f"    return {failed};", "  }"]
    precheck, on_failure = PRECHECKS.get(func.name, (None, None))
    if precheck:
        lines += [f'  if ({precheck}("{func.name}")) {{', *["  " + line for line in zero],
                  f"    return {failed};", "  }"]
    lines += ["  mjcffi_guard_enter(&mjcffi_g);",
              "  if (setjmp(mjcffi_g.env)) {",
              "    mjcffi_guard_leave(&mjcffi_g, 1);",
              *([f"    {on_failure}();"] if on_failure else []),
              *["  " + line for line in release],
              *["  " + line for line in zero],
              f"    return {failed};", "  }"]
    if void:
        lines += [f"  {call};",
                  "  mjcffi_guard_leave(&mjcffi_g, 0);",
                  *release,
                  "  return 0;", "}"]
    else:
        lines += [f"  mjcffi_result = {call};",
                  "  mjcffi_guard_leave(&mjcffi_g, 0);",
                  *release,
                  "  return mjcffi_result;", "}"]
    return head + ";", "\n".join(lines)


def generate(functions):
    """{relative path: text} of guards.h and guards.c for `functions` (name -> Function).

    Takes codegen.parse's Declarations.functions, or mjcffi._generated.funcinfo.FUNCTIONS.
    """
    protos, bodies = [], []
    for name in functions:
        proto, body = _guard(functions[name])
        protos.append(proto)
        bodies.append(body)
    header = HEADER_C + _H_HEAD + "\n" + "\n".join(protos) + "\n"
    source = HEADER_C + _C_HEAD + "\n" + "\n\n".join(bodies) + "\n"
    return {"mjcffi/_c/generated/guards.h": header, "mjcffi/_c/generated/guards.c": source}
