"""Write mjcffi/sim/generated/const.py: MuJoCo's constants under mujoco-py's names.

mujoco-py's `mujoco_py.generated.const` named each #define constant and each
enum member of MuJoCo without its `mj` prefix: mjMINVAL is MINVAL, mjOBJ_BODY
is OBJ_BODY, mjNDISABLE is NDISABLE.  Here the same names are made from the
headers of the installed MuJoCo, so the values are MuJoCo 4's: the numeric
#defines as mjcffi/_generated/constants.py has them, then the members of every enum
in the order of the headers.
"""

import ast

from . import headers, outputs

PREFIX = "mj"


def _public(name):
    """mujoco-py's name of a MuJoCo constant: the name without its `mj` prefix."""
    if not name.startswith(PREFIX):
        raise ValueError(f"MuJoCo constant {name} lacks the {PREFIX!r} prefix")
    return name[len(PREFIX):]


def _define_values(header_texts):
    """[(C name, value)] of the numeric #defines, read back from the text of
    mjcffi/_generated/constants.py, so both files hold the same constants."""
    text = outputs.constants(header_texts, headers.macro_values())
    values = []
    for node in ast.parse(text).body:
        if isinstance(node, ast.Assign):
            values.append((node.targets[0].id, ast.literal_eval(node.value)))
    return values


def _lines(groups):
    """`NAME = value` lines, a comment naming each group; ValueError when two
    constants would get one name."""
    lines, seen = [], {}
    for title, members in groups:
        lines += ["", f"# {title}"]
        for cname, value in members:
            name = _public(cname)
            if name in seen:
                raise ValueError(f"{cname} and {seen[name]} both become {name}")
            seen[name] = cname
            lines.append(f"{name} = {value!r}")
    return lines


def generate(decls, header_texts):
    """{"mjcffi/sim/generated/const.py": text}."""
    groups = [("numeric #defines", _define_values(header_texts))]
    groups += [(enum.name, enum.members) for enum in decls.enums.values() if enum.members]
    lines = [outputs.HEADER_PY.rstrip("\n"),
             '"""MuJoCo\'s constants under mujoco-py\'s names: each #define and enum member',
             "of MuJoCo without its `mj` prefix (mjOBJ_BODY is OBJ_BODY).",
             "",
             "Values are those of the MuJoCo headers mjcffi was generated from.",
             '"""',
             *_lines(groups)]
    return {"mjcffi/sim/generated/const.py": "\n".join(lines) + "\n"}
