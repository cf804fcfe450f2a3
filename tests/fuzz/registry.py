"""Every target the fuzzer knows: MuJoCo's functions (functions.py) and the other
public entry points (entries.py)."""

_cache = None


def targets():
    global _cache
    if _cache is None:
        from . import entries, functions
        _cache = functions.targets() + entries.targets()
    return _cache


def targets_by_name():
    return {t.name: t for t in targets() + selftest_targets()}


def find(name):
    """The target called `name` (the self-test ones without building the others)."""
    if name.startswith("case:selftest"):
        return {t.name: t for t in selftest_targets()}.get(name)
    return targets_by_name().get(name)


def all_keys():
    """Every call key, in a fixed order."""
    out = []
    for target in targets():
        out.extend(target.keys())
    return out


def random_keys(n, rng, only=""):
    """`n` further keys from the targets with random variants (byte flips, cuts)."""
    makers = [t for t in targets() if hasattr(t, "random_key")]
    out = []
    if not makers:
        return out
    tries = 0
    while len(out) < n and tries < n * 10:
        tries += 1
        key = rng.choice(makers).random_key(rng)
        if only in key:
            out.append(key)
    return out


def selftest_targets():
    """Targets that misbehave on purpose, to check the fuzzer itself (tests/test_fuzz.py):
    never in all_keys()."""
    from .target import Case

    def segfault(env):
        """reads address 8"""
        import ctypes
        ctypes.string_at(8, 1)

    def guard_overread(env):
        """reads one element past a guarded array"""
        import ctypes
        from . import guard
        a = guard.guarded([1.0, 2.0])
        ctypes.c_double.from_address(guard.address(a) + a.nbytes).value

    def guard_underread(env):
        """reads one element before a front-guarded array"""
        import ctypes
        from . import guard
        a = guard.guarded([1.0, 2.0], front=True)
        ctypes.c_double.from_address(guard.address(a) - 8).value

    def guard_readonly_write(env):
        """writes into a read-only guarded array"""
        import ctypes
        from . import guard
        a = guard.guarded([1.0, 2.0], readonly=True)
        ctypes.c_double.from_address(guard.address(a)).value = 3.0

    def undocumented(env):
        """raises OverflowError"""
        raise OverflowError("self-test")

    def documented(env):
        """raises ValueError"""
        raise ValueError("self-test")

    def hang(env):
        """sleeps past the timeout"""
        import time
        time.sleep(3600)

    return [Case("selftest", {"segfault": segfault, "guard overread": guard_overread,
                              "guard underread": guard_underread,
                              "guard read-only write": guard_readonly_write,
                              "undocumented": undocumented, "documented": documented,
                              "hang": hang, "ok": lambda env: None})]
