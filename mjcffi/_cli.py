"""What the command-line tools share (python -m mjcffi, mjcffi.tune, mjcffi.accuracy,
mjcffi.viewer): their convention is argparse's.  A user error is one `prog: error: ...`
line on stderr (parser.error) and exit status 2, found before any work starts;
tracebacks are for bugs.  Here: argparse types for numbers, a model loader whose
error is one line, and checks of output paths and of Ray that create nothing.
"""

import argparse
import math
import os
import sys

import mjcffi
from mjcffi.user_handlers import get_mju_user_warning, set_mju_user_warning


def positive(text):
    """argparse type: a positive, finite number."""
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not a number: {text!r}") from None
    if not (math.isfinite(value) and value > 0):
        raise argparse.ArgumentTypeError(f"must be positive and finite, got {text!r}")
    return value


def _whole(text):
    try:
        return int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not a whole number: {text!r}") from None


def positive_int(text):
    """argparse type: a whole number of at least 1."""
    value = _whole(text)
    if value < 1:
        raise argparse.ArgumentTypeError(f"must be positive, got {value}")
    return value


def non_negative_int(text):
    """argparse type: a whole number of at least 0."""
    value = _whole(text)
    if value < 0:
        raise argparse.ArgumentTypeError(f"must be 0 or more, got {value}")
    return value


def one_line(*texts):
    """The non-blank lines of `texts` joined into one line."""
    return "; ".join(line.strip() for text in texts for line in str(text).splitlines()
                     if line.strip())


def load_model(path):
    """The MjModel in the file at `path` (.mjb: binary, else MJCF), or ValueError with a
    one-line message: MuJoCo's error and the warnings it gave on the way."""
    if not os.path.isfile(path):
        raise ValueError(f"no such model file: {path}" if not os.path.exists(path)
                         else f"not a model file: {path}")
    warnings = []
    previous = get_mju_user_warning()
    # taken in, not printed: MuJoCo would print them over several lines and write
    # MUJOCO_LOG.TXT into the current folder
    set_mju_user_warning(warnings.append)
    try:
        if path.lower().endswith(".mjb"):
            model = mjcffi.MjModel.from_binary_path(path)
        else:
            model = mjcffi.MjModel.from_xml_path(path)
    except ValueError as error:
        raise ValueError(f"cannot load {path}: {one_line(error, *warnings)}") from None
    finally:
        set_mju_user_warning(previous)
    for text in warnings:          # a model that loads keeps its warnings
        print(f"WARNING: {one_line(text)}", file=sys.stderr)
    return model


def unwritable(path):
    """Why no file can be written at `path` (a short phrase), or None if one can.
    Creates nothing."""
    if not path:
        return "the path is empty"
    if os.path.isdir(path):
        return "it is a folder"
    folder = os.path.dirname(os.path.abspath(path))
    if not os.path.exists(folder):
        return f"no such folder {folder}"
    if not os.path.isdir(folder):
        return f"{folder} is not a folder"
    if not os.access(folder, os.W_OK | os.X_OK) or (os.path.exists(path)
                                                   and not os.access(path, os.W_OK)):
        return "permission denied"
    return None


def check_writable(parser, option, path):
    """parser.error unless a file can be written at `path` (given by `option`)."""
    reason = None if path is None else unwritable(path)
    if reason:
        parser.error(f"argument {option}: cannot write {path}: {reason}")


def check_ray(parser):
    """parser.error unless Ray imports (for --ray), before any work is done."""
    from mjcffi.distributed._ray import require
    try:
        require()
    except ImportError as error:
        parser.error(f"argument --ray: {one_line(error)}")
