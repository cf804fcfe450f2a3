"""A tqdm progress bar when tqdm is installed (`pip install 'mjcffi[progress]'`), else nothing."""


class _Silent:
    def update(self, n=1):
        pass

    def set_postfix_str(self, text):
        pass

    def close(self):
        pass


def bar(total, description, enabled=True):
    """A bar over `total` evaluations, or a silent stand-in when disabled or tqdm is missing."""
    if not enabled:
        return _Silent()
    try:
        from tqdm.auto import tqdm
    except ImportError:
        return _Silent()
    return tqdm(total=total, desc=description, unit="eval", leave=False)
