"""SimBase: what mujoco-py's helpers take, MjSim's base class.

The render contexts, the modders, the viewer and the flattened states check
that they are given an MjSim.  They check against this class, which imports
nothing, rather than MjSim itself: mjcffi/sim/_sim.py imports them, and they
would otherwise import it back.
"""


class SimBase:
    """The base of MjSim (mjcffi/sim/_sim.py): a sim's `model` and `data`."""

    __slots__ = ()
