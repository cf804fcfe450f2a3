"""Independent Python calls spread over Ray tasks, results in order."""

from ._ray import connect


def map_calls(function, calls, shared=()):
    """[function(*shared, *args) for args in calls], each call a Ray task.

    `function` must be importable by name on the workers (a module-level function).
    The `shared` arguments go into the object store once, not once per call."""
    ray = connect()
    task = ray.remote(function)
    shared = [ray.put(value) for value in shared]
    return ray.get([task.remote(*shared, *args) for args in calls])
