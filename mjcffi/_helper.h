/* Declarations of mjcffi's own C helper (mjcffi/_helper.c), read by
   mjcffi/_build.py into the cffi cdef after the generated _cdef.h.
   Hand-written: the helper is not generated. */

/* mjVERSION_HEADER of the headers this module was compiled against. */
int mjcffi_header_version(void);

/* The message of the mju_error caught by the last guarded call on this thread
   (an mjcffi_guard_* function or mjcffi_step), or NULL if that call caught
   none.  Clears it: a second call returns NULL.  The text stays valid until
   the next error caught on this thread. */
const char* mjcffi_take_error(void);

/* What the last error caught on this thread was: MuJoCo's mju_error (0), a call
   refused because another thread's call holds its mjData (1), or because it would
   restart the pipeline of an mjData that a call on this thread is computing (2). */
#define MJCFFI_ERROR_FATAL 0
#define MJCFFI_ERROR_BUSY 1
#define MJCFFI_ERROR_REENTRY 2
int mjcffi_error_kind(void);

/* mj_step(m, d) nstep times under one guard (cffi releases the GIL around
   it): 0 when all steps ran, 1 when an mju_error was caught.  After 1, d is
   left mid-step; see mjcffi/_errors.py for how to make it usable again. */
int mjcffi_step(const mjModel* m, mjData* d, int nstep);

/* mujoco-py's substeps: nstep times fn(m, d) (when fn is not NULL) then mj_step(m, d),
   under one guard as mjcffi_step (mju_error in fn is caught too).  nstep 0: fn once,
   no step.  0, or 1 when an error was caught or d is busy. */
int mjcffi_step_substep(const mjModel* m, mjData* d, int nstep, mjfGeneric fn);

/* Pickling an mjData (see mjcffi/data.py): its header is mjData's bytes up to `buffer`
   (mjcffi_data_header_size()); its layout (mjcffi_data_layout_size() bytes, written by
   mjcffi_save_layout) holds a tag, the signature and each arena array as an offset, -1 for
   none.  mjcffi_save_layout returns 1 when the header holds something of this process alone
   (thread pool, stack in use): mjcffi_clear_local zeroes that in a copy of the header.
   mjcffi_restore_data checks a header, a buffer (nbuffer bytes), the used arena (parena
   bytes) and a layout against m and against d, a fresh mj_makeData of m, and only then
   copies them into d: buffer pointers stay d's own, arena pointers come from the checked
   offsets, and d keeps its plugin instances.  It returns 0, or 1 with the reason (the field
   and its bound) in `why` (which may be NULL, nwhy 0), d untouched. */
size_t mjcffi_data_header_size(void);
size_t mjcffi_data_layout_size(void);
int mjcffi_save_layout(const mjData* d, char* layout);
void mjcffi_clear_local(char* header);
int mjcffi_restore_data(const mjModel* m, mjData* d, const char* header, size_t nheader,
                        const char* buffer, size_t nbuffer, const char* arena, size_t narena,
                        const char* layout, size_t nlayout, char* why, size_t nwhy);

/* Whether `mjb` (n bytes) holds exactly what its sizes describe, the rule mj_loadModelBuffer
   applies only after allocating that much: 0, or 1 with why.  Bytes too short for the sizes,
   or of another layout, pass: MuJoCo refuses them before allocating, with its message. */
int mjcffi_check_mjb(const char* mjb, size_t n, char* why, size_t nwhy);

/* Lay out the arena arrays of d (made for m) as MuJoCo does: ncon contacts, nefc constraint
   rows with nJ Jacobian entries (nJ -1: keep d->nJ), and their dual-solver rows when m's
   solver is dual; every other arena array is dropped.  0, or 1 when the arena is too small
   (or a count negative): then the arena is empty and every row count 0. */
int mjcffi_realloc_con_efc(const mjModel* m, mjData* d, int ncon, int nefc, int nJ);

/* Lay out d's island arrays for nisland islands over nidof dofs, reusing the old island
   block when nothing follows it in the arena, else after everything.  0, or 1 when the
   arena is too small (or a count negative): then no island arrays, nisland = nidof = 0. */
int mjcffi_realloc_island(const mjModel* m, mjData* d, int nisland, int nidof);

/* An mjfTime: CLOCK_MONOTONIC in seconds, for mjcb_time (no Python, no GIL per call). */
mjtNum mjcffi_timer(void);

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
