"""The OSMesa backend: Mesa's off-screen software renderer, with no display or GPU.

libOSMesa is bound with cffi in ABI mode (four functions, nothing compiled).
Loading it is all MuJoCo needs: mjr_makeContext finds the loaded libOSMesa
and takes the OpenGL functions from its OSMesaGetProcAddress.

Each context draws into a max_width x max_height RGBA byte buffer of its own,
the default framebuffer; MuJoCo's offscreen rendering uses its own
framebuffer objects instead, so the buffer only has to exist.
"""

import cffi  # type: ignore[import-untyped]  # cffi ships no stubs

from ._base import GLContextBase

ffi = cffi.FFI()
ffi.cdef("""
typedef void *OSMesaContext;
OSMesaContext OSMesaCreateContextExt(unsigned int format, int depthBits, int stencilBits,
                                     int accumBits, OSMesaContext sharelist);
unsigned char OSMesaMakeCurrent(OSMesaContext ctx, void *buffer, unsigned int type,
                                int width, int height);
void OSMesaDestroyContext(OSMesaContext ctx);
OSMesaContext OSMesaGetCurrentContext(void);
""")

OSMESA_RGBA = 0x1908             # GL_RGBA
GL_UNSIGNED_BYTE = 0x1401

_NAMES = ("libOSMesa.so.8", "libOSMesa.so.6", "libOSMesa.so")


def _open():
    errors = []
    for name in _NAMES:
        try:
            return ffi.dlopen(name)
        except OSError as error:
            errors.append(str(error))
    raise ImportError("the OSMesa backend needs libOSMesa, which is not installed "
                      f"({'; '.join(errors)}).  On Debian or Ubuntu: apt-get install libosmesa6")


lib = _open()


class GLContext(GLContextBase):
    """An OSMesa context: OpenGL in software, with no display, GPU or window.

    `GLContext(max_width, max_height)`, then `make_current()` before MuJoCo's
    mjr_* functions.  Sizes up to 16384 pixels a side, Mesa's limit; the
    context keeps a max_width x max_height x 4 byte buffer.  A context is
    current on one thread at a time; see `mjcffi.rendering._base`.
    """

    backend = "osmesa"
    max_size = 16384             # Mesa's software framebuffer limit (SWRAST_MAX_WIDTH)

    def _create(self, width, height):
        # 24-bit depth and 8-bit stencil, as MuJoCo's window framebuffer asks
        context = lib.OSMesaCreateContextExt(OSMESA_RGBA, 24, 8, 0, ffi.NULL)
        if not context:
            raise RuntimeError("OSMesaCreateContextExt failed to make a context")
        self._buffer = ffi.new("unsigned char[]", width * height * 4)
        return context

    def _bind(self):
        if not lib.OSMesaMakeCurrent(self._native, self._buffer, GL_UNSIGNED_BYTE,
                                     self._max_width, self._max_height):
            raise RuntimeError("OSMesaMakeCurrent failed")

    def _unbind(self):
        lib.OSMesaMakeCurrent(ffi.NULL, ffi.NULL, 0, 0, 0)

    def _gl_handle(self, native):
        return int(ffi.cast("uintptr_t", native))

    def _destroy(self, native):
        lib.OSMesaDestroyContext(native)
        self._buffer = None
