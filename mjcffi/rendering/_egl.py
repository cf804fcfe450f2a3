"""The EGL backend: a headless OpenGL context on a GPU or on Mesa's llvmpipe.

libEGL is bound with cffi in ABI mode: the handful of EGL functions below,
declared here and looked up by dlopen, with nothing compiled.  Loading
libEGL into the process is also what MuJoCo's renderer needs: mjr_makeContext
finds the loaded libEGL and takes every OpenGL function from its
eglGetProcAddress, so no libGL or libOpenGL is loaded besides.

The display is chosen once per process, in this order:

1. an EGL device (EGL_EXT_platform_device): a GPU, or Mesa's software device,
   so no X server is needed; MUJOCO_EGL_DEVICE_ID picks one (see _egl_devices);
2. Mesa's surfaceless platform;
3. the default display.

Contexts are surfaceless (EGL_KHR_surfaceless_context): MuJoCo renders into
its own framebuffer objects, so max_width and max_height only get checked.
"""

import os

import cffi  # type: ignore[import-untyped]  # cffi ships no stubs

from . import _current, _egl_devices
from ._base import GLContextBase

ffi = cffi.FFI()
ffi.cdef("""
typedef void *EGLDisplay;
typedef void *EGLConfig;
typedef void *EGLContext;
typedef void *EGLSurface;
typedef void *EGLDeviceEXT;
typedef int32_t EGLint;
typedef unsigned int EGLBoolean;
typedef unsigned int EGLenum;
typedef intptr_t EGLAttrib;

void *eglGetProcAddress(const char *procname);
EGLint eglGetError(void);
EGLDisplay eglGetDisplay(void *display_id);
EGLBoolean eglInitialize(EGLDisplay dpy, EGLint *major, EGLint *minor);
EGLBoolean eglTerminate(EGLDisplay dpy);
const char *eglQueryString(EGLDisplay dpy, EGLint name);
EGLBoolean eglChooseConfig(EGLDisplay dpy, const EGLint *attrib_list, EGLConfig *configs,
                           EGLint config_size, EGLint *num_config);
EGLBoolean eglBindAPI(EGLenum api);
EGLContext eglCreateContext(EGLDisplay dpy, EGLConfig config, EGLContext share_context,
                            const EGLint *attrib_list);
EGLBoolean eglDestroyContext(EGLDisplay dpy, EGLContext ctx);
EGLBoolean eglMakeCurrent(EGLDisplay dpy, EGLSurface draw, EGLSurface read, EGLContext ctx);
EGLBoolean eglReleaseThread(void);

/* extensions, through eglGetProcAddress */
typedef EGLBoolean (*QueryDevicesEXT)(EGLint max_devices, EGLDeviceEXT *devices,
                                      EGLint *num_devices);
typedef EGLBoolean (*QueryDeviceAttribEXT)(EGLDeviceEXT device, EGLint attribute,
                                           EGLAttrib *value);
typedef EGLDisplay (*GetPlatformDisplayEXT)(EGLenum platform, void *native_display,
                                            const EGLint *attrib_list);
""")

EGL_SUCCESS = 0x3000
EGL_NONE = 0x3038
EGL_VENDOR = 0x3053
EGL_EXTENSIONS = 0x3055
EGL_OPENGL_API = 0x30A2
EGL_PLATFORM_DEVICE_EXT = 0x313F
EGL_PLATFORM_SURFACELESS_MESA = 0x31DD
EGL_CUDA_DEVICE_NV = 0x323A

_ERRORS = {0x3000: "EGL_SUCCESS", 0x3001: "EGL_NOT_INITIALIZED", 0x3002: "EGL_BAD_ACCESS",
           0x3003: "EGL_BAD_ALLOC", 0x3004: "EGL_BAD_ATTRIBUTE", 0x3005: "EGL_BAD_CONFIG",
           0x3006: "EGL_BAD_CONTEXT", 0x3007: "EGL_BAD_CURRENT_SURFACE",
           0x3008: "EGL_BAD_DISPLAY", 0x3009: "EGL_BAD_MATCH", 0x300A: "EGL_BAD_NATIVE_PIXMAP",
           0x300B: "EGL_BAD_NATIVE_WINDOW", 0x300C: "EGL_BAD_PARAMETER",
           0x300D: "EGL_BAD_SURFACE", 0x300E: "EGL_CONTEXT_LOST"}

# 8-bit RGBA, 24-bit depth, 8-bit stencil, desktop OpenGL (MuJoCo needs its compatibility profile)
_CONFIG = (0x3024, 8, 0x3023, 8, 0x3022, 8, 0x3021, 8,    # red, green, blue, alpha
           0x3025, 24, 0x3026, 8,                          # depth, stencil
           0x303F, 0x308E,                                 # color buffer type: RGB
           0x3033, 0x0001,                                 # surface type: pbuffer
           0x3040, 0x0008,                                 # renderable type: OpenGL
           EGL_NONE)

_PACKAGES = ("On Debian or Ubuntu: apt-get install libegl1 libgl1-mesa-dri (Mesa, with its "
             "software renderer); with an NVIDIA GPU, its driver's EGL library")


def _open():
    try:
        return ffi.dlopen("libEGL.so.1")
    except OSError as error:
        raise ImportError(f"the EGL backend needs libEGL.so.1, which is not installed "
                          f"({error}).  {_PACKAGES}") from error


lib = _open()


def error_name():
    """The calling thread's last EGL error, by name."""
    code = lib.eglGetError()
    return _ERRORS.get(code, hex(code))


def _extensions(display):
    text = lib.eglQueryString(display, EGL_EXTENSIONS)
    return set(ffi.string(text).decode().split()) if text else set()


def _extension_function(name, ctype):
    address = lib.eglGetProcAddress(name.encode())
    return ffi.cast(ctype, address) if address else None


# ------------------------------------------------------------------ display


def _devices():
    """Every EGL device, in EGL's order."""
    query = _extension_function("eglQueryDevicesEXT", "QueryDevicesEXT")
    count = ffi.new("EGLint *")
    if query is None or not query(0, ffi.NULL, count) or count[0] <= 0:
        return []
    devices = ffi.new("EGLDeviceEXT[]", count[0])
    if not query(count[0], devices, count):
        return []
    return [devices[i] for i in range(count[0])]


def _cuda_ids(devices):
    """The CUDA id behind each device, where the driver tells it (NVIDIA), else None."""
    query = _extension_function("eglQueryDeviceAttribEXT", "QueryDeviceAttribEXT")
    value = ffi.new("EGLAttrib *")
    ids = []
    for device in devices:
        found = query is not None and query(device, EGL_CUDA_DEVICE_NV, value)
        ids.append(int(value[0]) if found else None)
    lib.eglGetError()            # Mesa's devices answer EGL_BAD_ATTRIBUTE: clear it
    return ids


def _initialized(display):
    """`display` if it initialises and offers surfaceless contexts, else None."""
    if not display:
        return None
    if not lib.eglInitialize(display, ffi.NULL, ffi.NULL):
        lib.eglGetError()
        return None
    if "EGL_KHR_surfaceless_context" not in _extensions(display):
        lib.eglTerminate(display)
        return None
    return display


def _device_displays(client):
    """(display, description) of the first device that initialises; or None."""
    device_id = os.environ.get("MUJOCO_EGL_DEVICE_ID")
    listable = "EGL_EXT_device_base" in client or "EGL_EXT_device_enumeration" in client
    if not listable or "EGL_EXT_platform_device" not in client:
        if device_id is not None:
            raise RuntimeError(f"MUJOCO_EGL_DEVICE_ID is {device_id}, but this EGL library "
                               "cannot list devices (no EGL_EXT_platform_device)")
        return None
    get_display = _extension_function("eglGetPlatformDisplayEXT", "GetPlatformDisplayEXT")
    devices = _devices()
    chosen = _egl_devices.candidates(devices, _cuda_ids(devices),
                                     os.environ.get("CUDA_VISIBLE_DEVICES"), device_id)
    for device in chosen:
        display = _initialized(get_display(EGL_PLATFORM_DEVICE_EXT, device, ffi.NULL))
        if display is not None:
            return display, f"EGL device {devices.index(device)} of {len(devices)}"
    if device_id is not None:
        raise RuntimeError(f"the EGL device that MUJOCO_EGL_DEVICE_ID={device_id} names "
                           f"does not initialise ({error_name()})")
    return None


def _open_display():
    """(display, description): an initialised display, chosen as the module says."""
    client = _extensions(ffi.NULL)
    found = _device_displays(client)
    if found is not None:
        return found
    if "EGL_MESA_platform_surfaceless" in client:
        get_display = _extension_function("eglGetPlatformDisplayEXT", "GetPlatformDisplayEXT")
        display = _initialized(get_display(EGL_PLATFORM_SURFACELESS_MESA, ffi.NULL, ffi.NULL))
        if display is not None:
            return display, "Mesa's surfaceless platform"
    display = _initialized(lib.eglGetDisplay(ffi.NULL))
    if display is not None:
        return display, "the default EGL display"
    raise RuntimeError("EGL found no display to render on: no device, no surfaceless "
                       f"platform, no default display.  {_PACKAGES}")


_display = None                  # (display, config, description), made on first use


def display():
    """(EGLDisplay, EGLConfig, description) of this process, initialised on first use."""
    global _display
    with _current.LOCK:
        if _display is None:
            handle, description = _open_display()
            configs = ffi.new("EGLConfig[1]")
            count = ffi.new("EGLint *")
            if not lib.eglChooseConfig(handle, ffi.new("EGLint[]", _CONFIG), configs, 1, count) \
                    or count[0] < 1:
                raise RuntimeError(f"{description} has no 8-bit RGBA framebuffer configuration "
                                   f"with a 24-bit depth and 8-bit stencil buffer for OpenGL")
            _display = (handle, configs[0], description)
        return _display


def vendor():
    """The EGL vendor string of the chosen display ('Mesa Project', 'NVIDIA')."""
    return ffi.string(lib.eglQueryString(display()[0], EGL_VENDOR)).decode()


# ------------------------------------------------------------------ context


class GLContext(GLContextBase):
    """An EGL context for headless OpenGL rendering, on a GPU or in software.

    `GLContext(max_width, max_height)`, then `make_current()` before MuJoCo's
    mjr_* functions.  The display is an EGL device when the library offers
    them (MUJOCO_EGL_DEVICE_ID picks one), else Mesa's surfaceless platform.
    A context is current on one thread at a time; see `mjcffi.rendering._base`.
    """

    backend = "egl"
    max_size = 32768

    def _create(self, width, height):
        handle, config, description = display()
        lib.eglBindAPI(EGL_OPENGL_API)      # per thread: eglCreateContext makes one of its API
        context = lib.eglCreateContext(handle, config, ffi.NULL, ffi.NULL)
        if not context:
            raise RuntimeError(f"eglCreateContext failed on {description}: {error_name()}")
        self._display = handle
        return context

    def _bind(self):
        if not lib.eglMakeCurrent(self._display, ffi.NULL, ffi.NULL, self._native):
            raise RuntimeError(f"eglMakeCurrent failed: {error_name()}")

    def _unbind(self):
        lib.eglBindAPI(EGL_OPENGL_API)      # releasing acts on the thread's current API
        lib.eglMakeCurrent(self._display, ffi.NULL, ffi.NULL, ffi.NULL)

    def _thread_ended(self, ident):
        super()._thread_ended(ident)
        lib.eglReleaseThread()

    def _gl_handle(self, native):
        return int(ffi.cast("uintptr_t", native))

    def _destroy(self, native):
        lib.eglDestroyContext(self._display, native)
