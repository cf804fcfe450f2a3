"""The official `mujoco.egl.egl_ext` import path: PyOpenGL's EGL with the device
enumeration extension (eglQueryDevicesEXT, eglQueryDeviceAttribEXT,
eglGetPlatformDisplayEXT).  Needs PyOpenGL: `pip install 'mjcffi[egl-ext]'`.
See mjcffi.rendering._egl_ext.
"""

from ..rendering._egl_ext import *  # noqa: F401,F403
from ..rendering._egl_ext import (EGL_CUDA_DEVICE_NV, EGL_PLATFORM_DEVICE_EXT,  # noqa: F401
                                  eglGetPlatformDisplayEXT, eglQueryDeviceAttribEXT,
                                  eglQueryDevicesEXT)
