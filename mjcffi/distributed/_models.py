"""Models on their way to the workers: MJB bytes in Ray's object store, named by content.

The driver saves each distinct model of a call (mj_saveModel) and names it by a hash of
its bytes, so a model changed in place gets a new name; the bytes go into the object store
once per name.  A worker fetches only the names it has not cached.
"""

import collections
import hashlib

from .._support import marshal as _marshal
from .._support.library import ffi

_KEEP = 256          # names (and object refs) the driver keeps between calls


def key_of(mjb):
    """The name of MJB bytes: a hash of their content."""
    return hashlib.blake2b(mjb, digest_size=16).hexdigest()


def sizes_of(model):
    """The model's sizes (the head of mjModel): models with the same sizes share MjData."""
    return ffi.buffer(model._ptr, _marshal._SIZES)[:]


class Store:
    """The driver's side: model -> name, and name -> object ref, kept for later calls."""

    def __init__(self, ray):
        self._ray = ray
        self._refs = collections.OrderedDict()      # name -> ObjectRef of the MJB bytes

    def names(self, models):
        """The names of `models` (one MjModel or a list), put into the object store as needed.

        Returns a name, or a list with one name per model."""
        single = not isinstance(models, list)
        seen = {}                                   # id(model) -> name, within this call
        out = []
        for m in [models] if single else models:
            name = seen.get(id(m))
            if name is None:
                mjb = m.to_bytes()
                name = seen[id(m)] = key_of(mjb)
                if name in self._refs:
                    self._refs.move_to_end(name)
                else:
                    self._refs[name] = self._ray.put(mjb)
            out.append(name)
        while len(self._refs) > max(_KEEP, len(seen)):
            self._refs.popitem(last=False)
        return out[0] if single else out

    def refs(self, names):
        """{name: ObjectRef} for the given names (a name or a list of them)."""
        if isinstance(names, str):
            names = [names]
        return {n: self._refs[n] for n in set(names)}
