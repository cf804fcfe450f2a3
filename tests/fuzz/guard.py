"""Arrays placed against a guard page, so that reading or writing one element
past their end (or before their start) faults at once.

Each array gets its own anonymous mapping: [guard][data pages][guard], both
guard pages PROT_NONE (mprotect through libc).  `back` (the default) puts the
array's last byte on the last byte before the back guard page, so that an
over-read by one element segfaults; `front` puts its first byte just after the
front guard page, for under-reads (index -1).  A zero-size array points at the
guard page itself.  `readonly=True` also makes the data pages PROT_READ and the
array non-writable, so that a write into a const input faults too.

The mapping lives as long as the array (np.frombuffer keeps the mmap object
as its base; the mmap unmaps when it is collected).
"""

import ctypes
import mmap

import numpy as np

PAGE = mmap.PAGESIZE
_PROT_NONE, _PROT_READ = 0, 1

_libc = ctypes.CDLL(None, use_errno=True)
_libc.mprotect.argtypes = (ctypes.c_void_p, ctypes.c_size_t, ctypes.c_int)
_libc.mprotect.restype = ctypes.c_int


def _protect(address, length, prot):
    if _libc.mprotect(address, length, prot) != 0:
        raise OSError(ctypes.get_errno(), "mprotect failed")


def _address(mapping):
    anchor = ctypes.c_char.from_buffer(mapping)
    try:
        return ctypes.addressof(anchor)
    finally:
        del anchor                      # drop the buffer export, or the mmap cannot close


def guarded(values, dtype=None, *, front=False, readonly=False):
    """A copy of `values` (any array-like) as a C-contiguous array against a guard page."""
    source = np.asarray(values, dtype=dtype)
    nbytes = source.nbytes
    pages = max(1, -(-nbytes // PAGE))
    mapping = mmap.mmap(-1, (pages + 2) * PAGE, prot=mmap.PROT_READ | mmap.PROT_WRITE)
    base = _address(mapping)
    _protect(base, PAGE, _PROT_NONE)                           # the front guard
    _protect(base + (pages + 1) * PAGE, PAGE, _PROT_NONE)      # the back guard
    offset = PAGE if front else (pages + 1) * PAGE - nbytes
    if nbytes == 0:
        offset = PAGE if front else (pages + 1) * PAGE          # at a guard itself
        # frombuffer cannot take 0 bytes at the very end of the buffer's offset range
        flat = np.frombuffer(mapping, np.uint8, 0, offset if offset < len(mapping) else 0)
        out = flat.view(source.dtype).reshape(source.shape)
    else:
        out = np.frombuffer(mapping, source.dtype, source.size, offset).reshape(source.shape)
        out[...] = source
    if readonly:
        if nbytes:
            _protect(base + PAGE, pages * PAGE, _PROT_READ)
        out.flags.writeable = False
    return out


def zeros(shape, dtype=np.float64, **kw):
    return guarded(np.zeros(shape, dtype), **kw)


def address(array):
    """The address of `array`'s first byte."""
    return array.__array_interface__["data"][0]
