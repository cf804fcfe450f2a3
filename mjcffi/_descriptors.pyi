# The C field descriptors (mjcffi/_c/descriptors.c): private to mjcffi/_support/views.py.
from typing import Any

MOVING: int

class Holder:
    """The C base of mjcffi's struct wrappers."""
    _dyn: list[Any] | None
    def _forget_memory(self) -> None: ...

class Field(property):
    """A property whose get reads its field in C."""
    @property
    def _kind(self) -> int: ...
    def _bind_scalar(self, owner: type, offset: int, kind: int, struct_size: int, /) -> None: ...
    def _bind_moving(self, owner: type, index: int, key_offsets: tuple[int, ...],
                     struct_size: int, /) -> None: ...
