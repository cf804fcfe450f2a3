"""python -m codegen [--out DIR]: regenerate mjcffi's generated files.

Reads the headers of the installed mujoco-core wheel.  Run by maintainers;
the output is committed, and a test fails when it drifts.
"""

import argparse
import pathlib

from . import (comments, extents, fields, functions, guards, headers, named, outputs, parse,
               simconst, simfunctions, simgetters, structs)

REPO = pathlib.Path(__file__).resolve().parent.parent


def generate():
    """Relative path -> text of every generated file."""
    text = headers.mujoco_declarations()
    decls = parse.parse(text)
    header_texts = headers.header_texts()
    notes = comments.read(header_texts)
    known = {name: value for enum in decls.enums.values() for name, value in enum.members}
    described = fields.describe(decls, notes, extents.from_xmacros(known), known)
    files = {
        "mjcffi/_c/generated/cdef.h": outputs.cdef(text),
        "mjcffi/_generated/enums.py": outputs.enums(decls),
        "mjcffi/_generated/constants.py": outputs.constants(header_texts, headers.macro_values()),
        "mjcffi/_generated/structinfo.py": outputs.struct_info(described),
        "mjcffi/_generated/funcinfo.py": outputs.function_info(decls, notes),
        **outputs.generated_package(),
        **guards.generate(decls.functions),
        **structs.generate(described, decls, header_texts, notes),
        **functions.generate(decls, notes, described, header_texts),
        **named.generate(described),
        **simgetters.generate(described, decls),
        **simconst.generate(decls, header_texts),
    }
    # mujoco-py's functions call mjcffi's: read from this run's mjcffi/_functions/
    files.update(simfunctions.generate(decls, notes, header_texts, functions.text_of(files)))
    return files


def main(argv=None):
    parser = argparse.ArgumentParser(prog="python -m codegen", description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=pathlib.Path, default=REPO,
                        help="root to write into (default: the repository)")
    args = parser.parse_args(argv)
    for relpath, text in generate().items():
        path = args.out / relpath
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(text)
        print(f"wrote {path} ({len(text):,} chars)")


if __name__ == "__main__":
    main()
