"""Render mjcffi/_guards.h and mjcffi/_guards.c: one guarded call per MuJoCo function.

`mjcffi_guard_F` calls F with a setjmp target armed, so that mju_error inside
F returns to the caller instead of exiting the process.  A void F gets an int
guard (0: ok, 1: error caught); any other F a guard of the same return type
that returns the zero value on a caught error.  Either way the message waits
for mjcffi_take_error().  The machinery (the thread-local chain of guards, the
log handler, the message) is hand-written in mjcffi/_helper.c.

Variadic functions (mju_error, mju_warning, mju_info) get a guard that takes
the fixed arguments only and passes the last one, the message, through "%s":
a message from Python is never a format string.
"""

import re

from .outputs import HEADER_C

_C_HEAD = """\
/* One guard per MuJoCo function: the same call, with mju_error turned into a
   return.  The machinery is in _helper.c; mjcffi_take_error() gives the message. */

#include <string.h>

#include <mujoco/mujoco.h>
#include <mujoco/mjbatch.h>

#include "_guard_chain.h"
#include "_guards.h"
"""

_H_HEAD = """\
/* mjcffi_guard_F(args): F(args) with MuJoCo's fatal errors caught, thread-locally.
   A void F gives int: 0 ok, 1 error caught.  Any other F gives F's result, or
   zero when an error was caught.  mjcffi_take_error() (in _helper.h) returns
   the message.  Read into the cffi cdef and included by the compiled module. */
"""

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


def _guard(func):
    """(prototype, definition) of mjcffi_guard_<func.name>."""
    restype, args, variadic = _signature(func)
    void = restype == "void"
    params = ", ".join(_named(decl, name) for name, decl in args) or "void"
    head = _named("int" if void else restype, f"mjcffi_guard_{func.name}({params})")
    call_args = [name for name, _ in args]
    if variadic:
        call_args.insert(len(call_args) - 1, '"%s"')
    call = f"{func.name}({', '.join(call_args)})"
    lines = [head + " {",
             "  mjcffi_guard mjcffi_g;"]
    if not void:
        lines.append(f"  {_named(restype, 'mjcffi_result')};")
    lines += ["  mjcffi_guard_enter(&mjcffi_g);",
              "  if (setjmp(mjcffi_g.env)) {",
              "    mjcffi_guard_leave(&mjcffi_g, 1);"]
    if void:
        lines += ["    return 1;", "  }",
                  f"  {call};",
                  "  mjcffi_guard_leave(&mjcffi_g, 0);",
                  "  return 0;", "}"]
    else:
        lines += ["    memset(&mjcffi_result, 0, sizeof mjcffi_result);",
                  "    return mjcffi_result;", "  }",
                  f"  mjcffi_result = {call};",
                  "  mjcffi_guard_leave(&mjcffi_g, 0);",
                  "  return mjcffi_result;", "}"]
    return head + ";", "\n".join(lines)


def generate(functions):
    """{relative path: text} of _guards.h and _guards.c for `functions` (name -> Function).

    Takes codegen.parse's Declarations.functions, or mjcffi._funcinfo.FUNCTIONS.
    """
    protos, bodies = [], []
    for name in functions:
        proto, body = _guard(functions[name])
        protos.append(proto)
        bodies.append(body)
    header = HEADER_C + _H_HEAD + "\n" + "\n".join(protos) + "\n"
    source = HEADER_C + _C_HEAD + "\n" + "\n\n".join(bodies) + "\n"
    return {"mjcffi/_guards.h": header, "mjcffi/_guards.c": source}
