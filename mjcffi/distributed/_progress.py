"""A progress bar of shards done: tqdm's when it is installed and asked for, else none."""

import contextlib


class _Silent:
    def update(self, n=1):
        pass


@contextlib.contextmanager
def bar(total, wanted):
    """A bar over `total` shards (an object with update(n)); silent unless `wanted`."""
    if wanted:
        try:
            from tqdm.auto import tqdm
        except ImportError:
            tqdm = None
        if tqdm is not None:
            with tqdm(total=total, unit="shard", desc="rollout") as shown:
                yield shown
            return
    yield _Silent()
