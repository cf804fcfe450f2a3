"""Which GLContext is current on which thread.

OpenGL makes a context current per thread, and one context may be current on
one thread at a time.  The C libraries disagree on what a second thread gets:
EGL answers EGL_BAD_ACCESS; Mesa's GLX (GLFW's backend) and OSMesa answer
nothing at all, and both threads then draw into one context at once (undefined
behaviour; the GLX specification asks for a BadAccess X error, whose default
handler ends the process).  So every GLContext records the thread it is current on,
and `make_current` on another thread is refused in Python before any C call.

Each thread's record is a `_Slot` in a thread-local.  It holds the context
strongly, so a context stays alive while current (MuJoCo may still draw with
it), and when the thread ends, the slot's finaliser runs on that thread and
releases the context there: afterwards another thread may make it current.
"""

import threading

# Guards every record and the C calls that go with it.  Reentrant: dropping the
# last reference to a context inside a locked section runs its __del__ -> free().
LOCK = threading.RLock()

_local = threading.local()


class _Slot:
    """The context current on one thread; at the thread's end, released there."""

    __slots__ = ("context", "thread")

    def __init__(self):
        self.context = None
        self.thread = threading.get_ident()

    def __del__(self):
        # runs on the ending thread itself, while its C thread-locals still exist
        context, self.context = self.context, None
        if context is not None:
            try:
                context._thread_ended(self.thread)
            except Exception:       # a finaliser must not raise; the thread is gone anyway
                pass


def slot():
    """This thread's record, made on first use."""
    try:
        return _local.slot
    except AttributeError:
        record = _local.slot = _Slot()
        return record


def current():
    """The GLContext current on this thread by these records, or None."""
    return slot().context


def thread_name(ident):
    """A thread's name, for messages ('thread 140...' when it is not a threading.Thread)."""
    for thread in threading.enumerate():
        if thread.ident == ident:
            return repr(thread.name)
    return f"{ident}"
