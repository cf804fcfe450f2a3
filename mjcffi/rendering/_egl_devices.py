"""Which EGL devices to try, and in what order, for MUJOCO_EGL_DEVICE_ID.

EGL lists its devices (GPUs, and Mesa's software device) in its own order.
NVIDIA's driver also tells the CUDA id behind each device; when it does, the
devices CUDA_VISIBLE_DEVICES names lead, in its order (else those with a CUDA
id, by id), and the rest follow in EGL's order, so that
MUJOCO_EGL_DEVICE_ID=k picks the GPU that CUDA calls k, as the official
bindings do.  MUJOCO_EGL_DEVICE_ID=k means, in turn: the k-th visible device,
the visible device with physical CUDA id k, the device with CUDA id k, and
the k-th device in that order.  Pure logic on opaque device handles.
"""


def cuda_map(devices, cuda_ids):
    """{CUDA id: device}, or None unless some devices have one and no two share it."""
    mapping = {}
    for device, cuda_id in zip(devices, cuda_ids):
        if cuda_id is None:
            continue
        if cuda_id in mapping:
            return None
        mapping[cuda_id] = device
    return mapping or None


def parse_visible(value):
    """CUDA_VISIBLE_DEVICES as a list of ids, or None when unset or not plain ints."""
    if not value:
        return None
    ids = []
    for part in value.split(","):
        part = part.strip()
        if not part:
            continue
        if not part.isdigit():       # UUIDs ('GPU-...'), negative ids: no mapping
            return None
        ids.append(int(part))
    return ids or None


def _visible(mapping, visible):
    """The devices CUDA_VISIBLE_DEVICES names, in its order; None when it names others."""
    if not visible or mapping is None:
        return None
    if all(cuda_id in mapping for cuda_id in visible):
        return [mapping[cuda_id] for cuda_id in visible]
    if all(index in mapping for index in range(len(visible))):   # ids already renumbered
        return [mapping[index] for index in range(len(visible))]
    return None


def ordered(devices, mapping, visible):
    """Every device once: those CUDA_VISIBLE_DEVICES names first (else all with a CUDA
    id, by id), then the rest in EGL's order."""
    if mapping is None:
        return list(devices)
    lead = _visible(mapping, visible) or [mapping[k] for k in sorted(mapping)]
    return lead + [device for device in devices if device not in lead]


def candidates(devices, cuda_ids, visible_env, device_id_env):
    """The devices to try in turn; one when MUJOCO_EGL_DEVICE_ID names one.

    Raises RuntimeError when MUJOCO_EGL_DEVICE_ID is not an int or names no device.
    """
    mapping = cuda_map(devices, cuda_ids)
    visible = parse_visible(visible_env)
    order = ordered(devices, mapping, visible)
    if device_id_env is None:
        return order
    try:
        device_id = int(device_id_env)
    except ValueError:
        raise RuntimeError(f"MUJOCO_EGL_DEVICE_ID must be an integer, got "
                           f"{device_id_env!r}") from None
    return [_pick(order, mapping, visible, device_id)]


def _pick(order, mapping, visible, device_id):
    shown = _visible(mapping, visible)
    if shown:
        if 0 <= device_id < len(shown):
            return shown[device_id]
        if device_id in visible:
            return shown[visible.index(device_id)]
    if mapping is not None and device_id in mapping:
        return mapping[device_id]
    if not order:
        raise RuntimeError(f"MUJOCO_EGL_DEVICE_ID is {device_id}, but EGL lists no device")
    if not 0 <= device_id < len(order):
        raise RuntimeError(f"MUJOCO_EGL_DEVICE_ID must be an integer between 0 and "
                           f"{len(order) - 1} (inclusive), got {device_id}")
    return order[device_id]
