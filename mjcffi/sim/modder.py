"""mujoco-py's `mujoco_py.modder` path: TextureModder, MaterialModder, LightModder
and CameraModder (with Texture and BaseModder), from mjcffi/rendering/_simmodder."""

from ..rendering._simmodder import BaseModder, CameraModder, LightModder, MaterialModder, \
    Texture, TextureModder

__all__ = ["TextureModder", "MaterialModder", "LightModder", "CameraModder", "Texture",
           "BaseModder"]
