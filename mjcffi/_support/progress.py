"""Progress bars: tqdm's when it is installed (`pip install 'mjcffi[progress]'`) and asked
for, else a silent stand-in with the same calls."""


class Silent:
    """What a bar offers (update, set_postfix_str, close, with), doing nothing."""

    def update(self, n=1):
        pass

    def set_postfix_str(self, text):
        pass

    def close(self):
        pass

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
        return False


def bar(total, description, unit, enabled=True, leave=True):
    """A tqdm bar over `total` `unit`s (None: a count), or Silent() when not `enabled` or
    tqdm is missing; `leave`: keep the finished bar on screen.  Close it, or use it in a
    with statement."""
    if not enabled:
        return Silent()
    try:
        from tqdm.auto import tqdm
    except ImportError:
        return Silent()
    return tqdm(total=total, desc=description, unit=unit, leave=leave)
