"""Which calls a run makes: a fixed sample of the key space for a seed."""

import math
import random

from . import registry


def _group(key):
    """The family of a key: 'fn', 'set', 'named', ..., or a case's own name."""
    target = key.split("|", 1)[0]
    if target.startswith("case:"):
        return target
    return target.split(":", 1)[0]


def _allot(sizes, total):
    """Split `total` calls over groups in proportion to the square root of their sizes
    (a small family, such as the MjVfs calls, is then covered whole, and the thirty
    thousand function calls are sampled), never more than a group holds."""
    share = {g: 0 for g in sizes}
    left = total
    open_groups = {g for g, n in sizes.items() if n}
    while left > 0 and open_groups:
        weight = sum(math.sqrt(sizes[g]) for g in open_groups)
        given = 0
        for g in sorted(open_groups):
            room = sizes[g] - share[g]
            add = min(room, max(1, int(left * math.sqrt(sizes[g]) / weight)))
            share[g] += add
            given += add
        left -= given
        open_groups = {g for g in open_groups if share[g] < sizes[g]}
        if given == 0:
            break
    return share


def keys(calls, seed, only=""):
    """`calls` keys for `seed`: a sample of every key (stratified by family), or all of
    them and random variants past that, shuffled so that a worker's batch mixes targets
    (a call that corrupts memory is then caught by the calls after it)."""
    everything = [k for k in registry.all_keys() if only in k]
    rng = random.Random(seed)
    if calls >= len(everything):
        chosen = list(everything)
        chosen += registry.random_keys(calls - len(everything), rng, only)
    else:
        # Every function's valid call is in any sample that has room for them: with its
        # arrays against guard pages, it checks the extents the wrappers give MuJoCo.
        chosen = [k for k in everything if k.startswith("fn:") and k.endswith("|-|valid")]
        chosen = chosen if len(chosen) <= calls // 3 else []
        taken = set(chosen)
        rest = [k for k in everything if k not in taken]
        groups = {}
        for key in rest:
            groups.setdefault(_group(key), []).append(key)
        share = _allot({g: len(v) for g, v in groups.items()}, calls - len(chosen))
        for g in sorted(groups):
            chosen += rng.sample(groups[g], share[g])
        chosen = chosen[:calls]
    rng.shuffle(chosen)
    return chosen
