"""Ctrl-C in mjcffi's long C loops: the Python side of mjcffi/_c/interrupt.c.

Python handles SIGINT by setting a flag that its own loop reads, so a C loop running
with the GIL released never saw it.  mjcffi's C puts a counting handler in front of
Python's (on the main thread's long calls only), and the loops of mj_step(m, d,
nstep), rollout and MjSimPool.step stop at the next step boundary when it counts a
SIGINT; the steps done stay.  Each says so (mjcffi_step's MJCFFI_STEP_STOPPED, the pools'
-2), and the call ends in `stopped`: Python's own handler raises KeyboardInterrupt, and
where a handler of the user's own raises nothing, `stopped` does, as the call did not
do all it was asked.

Support module: imports only the compiled module.
"""

import threading

from .library import lib

# the thread Python runs its signal handlers on
lib.mjcffi_interrupt_init(threading.main_thread().ident)


def stopped(what):
    """After a loop that a SIGINT stopped: give Python's SIGINT handler its turn (it
    runs as a Python function is entered, and by default raises KeyboardInterrupt);
    if it raised nothing (a handler of the user's own), raise KeyboardInterrupt, as
    the call's results are incomplete."""
    _enter()
    raise KeyboardInterrupt(f"{what} was interrupted: its outputs are incomplete")


def _enter():
    """Nothing: entering a Python function is where Python runs pending signal handlers."""
