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
        tqdm = _tqdm_class()
    except ImportError:
        return Silent()
    return tqdm(total=total, desc=description, unit=unit, leave=leave)


def _tqdm_class():
    """tqdm's notebook bar where ipywidgets can draw it, else its text bar: tqdm.auto
    would pick the notebook bar without ipywidgets and warn, naming a local path."""
    import importlib.util
    try:
        widgets = importlib.util.find_spec("ipywidgets") is not None
    except ValueError:                   # sys.modules["ipywidgets"] is None: not usable
        widgets = False
    if widgets:
        from tqdm.auto import tqdm
    else:
        from tqdm.std import tqdm
    return tqdm
