"""PyOpenGL's EGL with the device-enumeration extension functions, for
`mjcffi.egl.egl_ext` (the official `mujoco.egl.egl_ext`).

Robot-learning frameworks import this module to pick an EGL device themselves:
every name of `OpenGL.EGL`, plus `eglQueryDevicesEXT(max_devices=10)` (a list of
devices), `eglQueryDeviceAttribEXT(device, attribute)` (an int),
`eglGetPlatformDisplayEXT(platform, device, attributes)` and the constants
`EGL_PLATFORM_DEVICE_EXT` and `EGL_CUDA_DEVICE_NV`.  mjcffi's own EGL context
(mjcffi.rendering._egl) binds libEGL with cffi and needs none of this: PyOpenGL
is imported here only, when this module is, and is an optional dependency
(`pip install 'mjcffi[egl-ext]'`).
"""

import ctypes
import os

# PyOpenGL picks its platform when first imported; the official `mujoco.egl` asks
# for EGL the same way, unless the user chose one.
os.environ.setdefault("PYOPENGL_PLATFORM", "egl")

try:
    from OpenGL.platform import ctypesloader
except ImportError as exc:
    raise ImportError("mjcffi.egl.egl_ext re-exports PyOpenGL's EGL, and PyOpenGL is not "
                      "installed. Fix: pip install 'mjcffi[egl-ext]' (or pyopengl)") from exc

try:
    # NVIDIA's driver wants libOpenGL (not libGL) loaded globally before its EGL is
    # used from several threads; elsewhere the library may be absent, which is fine.
    ctypesloader.loadLibrary(ctypes.cdll, "OpenGL", mode=ctypes.RTLD_GLOBAL)
except OSError:
    pass

from OpenGL import EGL, error  # noqa: E402
from OpenGL.EGL import *  # noqa: E402,F401,F403

EGL_PLATFORM_DEVICE_EXT = 0x313F        # EGL_EXT_platform_device
EGL_CUDA_DEVICE_NV = 0x323A             # EGL_NV_device_cuda

# The extension functions, looked up through eglGetProcAddress: ctypes prototypes.
_QUERY_DEVICES = ctypes.CFUNCTYPE(EGL.EGLBoolean, EGL.EGLint,
                                  ctypes.POINTER(EGL.EGLDeviceEXT), ctypes.POINTER(EGL.EGLint))
_PLATFORM_DISPLAY = ctypes.CFUNCTYPE(EGL.EGLDisplay, EGL.EGLenum, ctypes.c_void_p,
                                     ctypes.POINTER(EGL.EGLint))
_QUERY_ATTRIB = ctypes.CFUNCTYPE(EGL.EGLBoolean, EGL.EGLDeviceEXT, EGL.EGLint,
                                 ctypes.POINTER(ctypes.c_ssize_t))


def _extension(name, prototype, required):
    """The extension function `name` as `prototype`, or None (ImportError when required)."""
    address = EGL.eglGetProcAddress(name)
    if not address:
        if required:
            raise ImportError(f"{name} is not available: this libEGL lacks the extension")
        return None
    return prototype(address)


_eglQueryDevicesEXT = _extension("eglQueryDevicesEXT", _QUERY_DEVICES, True)
eglGetPlatformDisplayEXT = _extension("eglGetPlatformDisplayEXT", _PLATFORM_DISPLAY, True)
_eglQueryDeviceAttribEXT = _extension("eglQueryDeviceAttribEXT", _QUERY_ATTRIB, False)


def _failed(function, result):
    return error.GLError(err=EGL.eglGetError(), baseOperation=function, result=result)


def eglQueryDevicesEXT(max_devices=10):  # noqa: N802 (EGL's name)
    """The EGL devices of this machine, at most `max_devices`, as a list."""
    devices = (EGL.EGLDeviceEXT * max_devices)()
    count = EGL.EGLint()
    result = _eglQueryDevicesEXT(max_devices, devices, count)
    if result != EGL.EGL_TRUE:
        raise _failed(eglQueryDevicesEXT, result)
    return [devices[i] for i in range(count.value)]


def eglQueryDeviceAttribEXT(device, attribute):  # noqa: N802 (EGL's name)
    """The value of `attribute` (such as EGL_CUDA_DEVICE_NV) of EGL `device`, an int."""
    if _eglQueryDeviceAttribEXT is None:
        raise ImportError("eglQueryDeviceAttribEXT is not available: this libEGL lacks "
                          "EGL_EXT_device_query")
    value = ctypes.c_ssize_t()
    result = _eglQueryDeviceAttribEXT(device, attribute, ctypes.byref(value))
    if result != EGL.EGL_TRUE:
        raise _failed(eglQueryDeviceAttribEXT, result)
    return value.value
