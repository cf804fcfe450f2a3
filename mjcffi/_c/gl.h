/* OpenGL as the renderer meets it (gl.c): the current context, the loader, mjr_render's scene.
   Read by mjcffi/_c/build.py into the cffi cdef, and included by the C files.
   Hand-written. */

/* The OpenGL context current on the calling thread, as its windowing library reports it
   (eglGetCurrentContext, OSMesaGetCurrentContext or glXGetCurrentContext of a library
   already loaded; none is loaded here): its handle, or NULL when none is current.
   *platform gets which library answered (MJCFFI_GL_*); MJCFFI_GL_UNKNOWN where the
   question cannot be asked (not Linux).  mjcffi_gl_loader_ready: whether MuJoCo's
   OpenGL loader has run (an mjrContext was made in this process, by either binding):
   before that MuJoCo's OpenGL function pointers are NULL. */
#define MJCFFI_GL_NONE 0
#define MJCFFI_GL_EGL 1
#define MJCFFI_GL_OSMESA 2
#define MJCFFI_GL_GLX 3
#define MJCFFI_GL_UNKNOWN 4
void* mjcffi_gl_current(int* platform);
int mjcffi_gl_loader_ready(void);

/* Whether mjr_render may follow what scn and con hold: 0, or 1 with the reason in why.
   sizes: what the scene's buffers were allocated for (nflex, nflexvert, nflexedge, flex
   faces, nskin, nskinvert); skinface: the faces of each of con's skins (con->nskin). */
int mjcffi_check_render(const mjvScene* scn, const mjrContext* con, const int* sizes,
                        const int* skinface, char* why, size_t nwhy);
