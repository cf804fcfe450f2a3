// mjcffi's C helper: code that must run natively, beside the cffi wrappers.
// Compiled into mjcffi._mjcffi by mjcffi/_build.py; declared in _helper.h.

#define _GNU_SOURCE   // clock_gettime, and dl_iterate_phdr for the OpenGL check, under -std=c11

#include <limits.h>
#ifdef __linux__
#include <link.h>
#endif
#include <pthread.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include <mujoco/mujoco.h>
#include <mujoco/mjxmacro.h>

#include "_guard_chain.h"
#include "_helper.h"

// The import-time check compares this with mj_version(): the header version
// is baked in when the module is compiled, the library version when loaded.
int mjcffi_header_version(void) {
  return mjVERSION_HEADER;
}


//---------------------------------- fatal errors --------------------------------------------------
//
// mju_error ends in the active log handler, and the default one calls exit().
// A guarded call (the generated mjcffi_guard_* in _guards.c, or mjcffi_step)
// arms a setjmp target in its own frame and, for the duration of the call,
// installs our handler as this thread's log handler, which longjmps there.
//
// The handler is installed through libmujoco's thread-local hook, not the
// process-wide mju_setLogHandler or mju_user_error: the official bindings
// share this libmujoco in the same process and use the same hook, so each
// call saves the thread's previous handler and restores it on exit.  Nothing
// is left installed between calls, and other threads are never affected.

// Exported by libmujoco but declared in no public header: set this thread's
// log handler (it takes precedence over the global one) and return the
// previous one; and read the global one (mju_setLogHandler's, or the default).
mjfLogHandler _mjPRIVATE_setTlsLogHandler(mjfLogHandler handler);
mjfLogHandler _mjPRIVATE_getGlobalLogHandler(void);

// One record per thread: a guard, its error and its message never cross threads.
typedef struct {
  mjcffi_guard* innermost;      // the guard an error jumps to, or NULL
  int pending;                  // the last guarded call caught an error
  int kind;                     // MJCFFI_ERROR_*: what the pending error is
  char message[2048];           // subject is at most 1024; room for func and body
} mjcffi_errors;

static _Thread_local mjcffi_errors errors;

static void mjcffi_log_handler(const mjLogMessage* msg) {
  mjcffi_guard* guard = errors.innermost;

  // Warnings and info go where they would have gone without us: to the
  // handler we displaced or, if none, the global one (whose default also
  // serves mju_user_warning).  Called directly: mju_message drops messages
  // dispatched from inside a handler.
  if (msg->level != mjLOG_ERROR || !guard) {
    mjfLogHandler next = guard && guard->handler ? guard->handler
                                                 : _mjPRIVATE_getGlobalLogHandler();
    if (next) {
      next(msg);
    }
    return;
  }

  // "func: subject", the text MuJoCo gives a legacy mju_user_error (and the
  // official bindings their FatalError), then the multi-line body if any.
  const char* func = msg->func ? msg->func : "";
  snprintf(errors.message, sizeof(errors.message), "%s%s%s%s%s",
           func, *func ? ": " : "", msg->subject,
           msg->body ? "\n" : "", msg->body ? msg->body : "");
  errors.pending = 1;
  errors.kind = MJCFFI_ERROR_FATAL;
  longjmp(guard->env, 1);
}

// Push a guard on this thread's chain, ours as this thread's log handler.
void mjcffi_guard_enter(mjcffi_guard* guard) {
  guard->outer = errors.innermost;
  errors.innermost = guard;
  guard->handler = _mjPRIVATE_setTlsLogHandler(mjcffi_log_handler);
}

// Pop it and put back what it displaced.  pending then describes this call
// only, so a message that nobody took cannot be blamed on a later call.
void mjcffi_guard_leave(mjcffi_guard* guard, int caught) {
  _mjPRIVATE_setTlsLogHandler(guard->handler);
  errors.innermost = guard->outer;
  errors.pending = caught;
}

int mjcffi_error_kind(void) {
  return errors.kind;
}

const char* mjcffi_take_error(void) {
  if (!errors.pending) {
    return NULL;
  }
  errors.pending = 0;
  return errors.message;
}

// One guard around the whole loop: the per-step cost is mj_step's alone.
int mjcffi_step(const mjModel* m, mjData* d, int nstep) {
  return mjcffi_step_substep(m, d, nstep, NULL);
}

// mujoco-py's substep order: the callback runs before each mj_step, so it sees the
// state the step starts from and what the previous step computed (contacts, sensors).
// nstep 0 calls fn once and steps nothing (MjSim.substep_callback()).
int mjcffi_step_substep(const mjModel* m, mjData* d, int nstep, mjfGeneric fn) {
  mjcffi_guard guard;
  if (mjcffi_data_enter(d, 1, "mj_step")) {
    return 1;
  }
  mjcffi_guard_enter(&guard);
  if (setjmp(guard.env)) {
    mjcffi_guard_leave(&guard, 1);
    mjcffi_data_leave(d);
    return 1;
  }
  if (nstep == 0 && fn) {
    fn(m, d);
  }
  for (int i = 0; i < nstep; i++) {
    if (fn) {
      fn(m, d);
    }
    mj_step(m, d);
  }
  mjcffi_guard_leave(&guard, 0);
  mjcffi_data_leave(d);
  return 0;
}


//---------------------------------- OpenGL: the current context -----------------------------------
//
// MuJoCo's renderer calls OpenGL through function pointers that its loader (glad) fills
// once per process, at the first mjr_makeContext.  Before that every pointer is NULL, and
// an mjr_* call that draws jumps to address 0.  Once loaded, a call with no current
// context on the thread is a silent no-op (libglvnd's dispatch), except that it reads
// back nothing and leaves state unchanged.  And the loader runs only once: called with
// no current context it fails ("gladLoadGL error") and keeps failing for the rest of the
// process, even after a context is made current.
//
// So the checks ask the windowing libraries themselves which context is current on the
// calling thread: eglGetCurrentContext, OSMesaGetCurrentContext or glXGetCurrentContext
// of a library already in the process (looked up by name among the loaded objects, never
// loaded here).  The handle we keep on each library pins it: MuJoCo's function pointers
// stay valid even if the code that loaded it (a cffi dlopen) lets it go.

#ifdef __linux__
#include <dlfcn.h>

typedef void* (*mjcffi_current_fn)(void);

typedef struct {
  const char* prefix;           // the library's file name starts with this
  const char* symbol;           // its "which context is current" function
  int platform;                 // MJCFFI_GL_*
  mjcffi_current_fn current;    // found, or NULL
} mjcffi_gl_platform;

static mjcffi_gl_platform gl_platforms[] = {
  {"libEGL.so", "eglGetCurrentContext", MJCFFI_GL_EGL, NULL},
  {"libOSMesa.so", "OSMesaGetCurrentContext", MJCFFI_GL_OSMESA, NULL},
  {"libGLX.so", "glXGetCurrentContext", MJCFFI_GL_GLX, NULL},
  {"libGL.so", "glXGetCurrentContext", MJCFFI_GL_GLX, NULL},
};
#define MJCFFI_NPLATFORM ((int)(sizeof(gl_platforms) / sizeof(gl_platforms[0])))

static pthread_mutex_t gl_lock = PTHREAD_MUTEX_INITIALIZER;
static unsigned long long gl_adds = (unsigned long long)-1;   // dlpi_adds at the last scan

static int gl_adds_now(struct dl_phdr_info* info, size_t size, void* out) {
  (void)size;
  *(unsigned long long*)out = info->dlpi_adds;
  return 1;                     // the first object tells: every one carries the counter
}

static int gl_find(struct dl_phdr_info* info, size_t size, void* unused) {
  (void)size;
  (void)unused;
  const char* slash = info->dlpi_name ? strrchr(info->dlpi_name, '/') : NULL;
  const char* base = slash ? slash + 1 : info->dlpi_name;
  for (int i = 0; base && *base && i < MJCFFI_NPLATFORM; i++) {
    mjcffi_gl_platform* p = gl_platforms + i;
    if (p->current || strncmp(base, p->prefix, strlen(p->prefix)) != 0) {
      continue;
    }
    void* handle = dlopen(info->dlpi_name, RTLD_NOW | RTLD_NOLOAD);   // kept: pins it
    if (handle) {
      p->current = (mjcffi_current_fn)dlsym(handle, p->symbol);
    }
  }
  return 0;
}
#endif

void* mjcffi_gl_current(int* platform) {
  *platform = MJCFFI_GL_NONE;
#ifdef __linux__
  pthread_mutex_lock(&gl_lock);
  unsigned long long adds = 0;
  dl_iterate_phdr(gl_adds_now, &adds);
  if (adds != gl_adds) {        // objects were loaded since the last look
    gl_adds = adds;
    dl_iterate_phdr(gl_find, NULL);
  }
  pthread_mutex_unlock(&gl_lock);
  for (int i = 0; i < MJCFFI_NPLATFORM; i++) {
    mjcffi_current_fn current = gl_platforms[i].current;
    void* context = current ? current() : NULL;
    if (context) {
      *platform = gl_platforms[i].platform;
      return context;
    }
  }
  return NULL;
#else
  *platform = MJCFFI_GL_UNKNOWN;  // no way to ask here: the checks let every call through
  return NULL;
#endif
}

int mjcffi_gl_loader_ready(void) {
  // a context made by anyone (these bindings or the official ones) counts: MuJoCo's
  // mjr_getRendererInfo names the backend while one exists, and the loader, once it has
  // run, stays loaded
  static volatile int ready;
  if (!ready) {
    mjrRendererInfo info;
    mjr_getRendererInfo(&info);
    if (info.backend && info.backend[0]) {
      ready = 1;
    }
  }
  return ready;
}


//---------------------------------- mjr_makeContext without OpenGL -------------------------------
//
// mjr_makeContext raises its "no OpenGL platform library" mju_error inside a C++
// function-local static's initialization.  Our longjmp leaves that static's guard taken,
// and the next mjr_makeContext in the process aborts in the C++ runtime.  So the guard
// first looks for a loaded OpenGL library itself, as MuJoCo does, and after an error
// from that search inside mjr_makeContext refuses every later call with a FatalError.
// It also refuses while no OpenGL context is current on this thread: the loader would
// fail, and never run again (see above).  mjcffi.MjrContext checks that first, with a
// longer message.

static int render_failed;       // an mjr_makeContext call raised: the renderer is spent

#ifdef __linux__
static int find_gl_library(struct dl_phdr_info* info, size_t size, void* found) {
  (void)size;
  static const char* names[] = {"libGL.", "libGLX", "libEGL.", "libOSMesa.", "libOpenGL."};
  const char* slash = info->dlpi_name ? strrchr(info->dlpi_name, '/') : NULL;
  const char* base = slash ? slash + 1 : info->dlpi_name;
  for (size_t i = 0; base && i < sizeof(names) / sizeof(names[0]); i++) {
    if (strncmp(base, names[i], strlen(names[i])) == 0) {
      *(int*)found = 1;
      return 1;
    }
  }
  return 0;
}
#endif

int mjcffi_render_enter(const char* func) {
  const char* why = NULL;
  if (render_failed) {
    why = "an earlier mjr_makeContext failed in this process, and MuJoCo's renderer "
          "cannot be initialized again after that (a C++ static it left half-made); "
          "make the OpenGL context first, in a new process";
  }
#ifdef __linux__
  int found = 0;
  dl_iterate_phdr(find_gl_library, &found);
  if (!why && !found) {
    why = "an OpenGL platform library has not been loaded into this process, this most "
          "likely means that a valid OpenGL context has not been created before "
          "mjr_makeContext was called";
  }
  int platform;
  if (!why && !mjcffi_gl_current(&platform)) {
    why = "no OpenGL context is current on this thread: make a GLContext current first "
          "(mjcffi.GLContext(w, h).make_current()); MuJoCo would fail with "
          "\"gladLoadGL error\", and its OpenGL loader would not run again in this process";
  }
#endif
  if (why) {                    // MuJoCo's own text has no function name: nor has ours
    (void)func;
    snprintf(errors.message, sizeof(errors.message), "%s", why);
    errors.pending = 1;
    errors.kind = MJCFFI_ERROR_FATAL;
    return 1;
  }
  return 0;
}

void mjcffi_render_failed(void) {
  // only the search for the OpenGL library runs inside the static; other errors
  // (a framebuffer too large, ...) leave the renderer usable
  if (strstr(errors.message, "OpenGL platform library")) {
    render_failed = 1;
  }
}


//---------------------------------- what mjr_render follows --------------------------------------
//
// mjr_render indexes the scene's and the context's arrays with what the scene holds, all
// of it writable from Python (numpy views of the geoms, the flex and skin arrays) and
// none of it checked by MuJoCo: a geom's material and texture index the context's
// fixed tables, a flex or skin geom's objid the scene's flex and skin arrays and the
// context's skin buffers, flex and skin addresses the scene's vertex buffers, and a
// label is read up to its NUL.  One pass over them in C keeps the check off the frame
// time.  `sizes` holds what the scene's buffers were allocated for (nflex, nflexvert,
// nflexedge, flex faces, nskin, nskinvert); `skinface` the faces of each of the
// context's skins (con->nskin of them), which sized its face buffers.

static int render_refuse(char* why, size_t nwhy, const char* format, ...) {
  va_list args;
  va_start(args, format);
  vsnprintf(why, nwhy, format, args);
  va_end(args);
  return 1;
}

static int within(long long adr, long long num, long long size) {
  return adr >= 0 && num >= 0 && adr + num <= size;
}

int mjcffi_check_render(const mjvScene* scn, const mjrContext* con, const int* sizes,
                        const int* skinface, char* why, size_t nwhy) {
  int nflex = sizes[0], nflexvert = sizes[1], nflexedge = sizes[2], nflexface = sizes[3];
  int nskin = sizes[4], nskinvert = sizes[5];
  if (scn->ngeom < 0 || scn->ngeom > scn->maxgeom || (scn->ngeom && !scn->geoms)) {
    return render_refuse(why, nwhy, "scn.ngeom=%d is outside the scene's buffer (maxgeom %d)",
                         scn->ngeom, scn->maxgeom);
  }
  if (scn->nlight < 0 || scn->nlight > mjMAXLIGHT) {
    return render_refuse(why, nwhy, "scn.nlight=%d is outside 0..mjMAXLIGHT (%d)",
                         scn->nlight, mjMAXLIGHT);
  }
  if (con->ntexture < 0 || con->ntexture > mjMAXTEXTURE) {
    return render_refuse(why, nwhy, "con.ntexture=%d is outside 0..mjMAXTEXTURE (%d)",
                         con->ntexture, mjMAXTEXTURE);
  }
  if (scn->nskin < 0 || scn->nskin > nskin || scn->nskin > con->nskin) {
    return render_refuse(why, nwhy, "scn.nskin=%d: the scene's buffers hold %d skins and the "
                         "context %d (was it made for this model?)", scn->nskin, nskin,
                         con->nskin);
  }
  for (int i = 0; i < scn->nskin; i++) {
    if (!within(scn->skinvertadr[i], scn->skinvertnum[i], nskinvert)) {
      return render_refuse(why, nwhy, "skin %d: scn.skinvertadr, skinvertnum (%d, %d) reach "
                           "past the scene's %d skin vertices", i, scn->skinvertadr[i],
                           scn->skinvertnum[i], nskinvert);
    }
    if (scn->skinfacenum[i] < 0 || scn->skinfacenum[i] > skinface[i]) {
      return render_refuse(why, nwhy, "skin %d: scn.skinfacenum=%d, but the context holds %d "
                           "faces for it", i, scn->skinfacenum[i], skinface[i]);
    }
  }
  if (scn->nflex < 0 || scn->nflex > nflex) {
    return render_refuse(why, nwhy, "scn.nflex=%d: the scene's buffers hold %d flexes",
                         scn->nflex, nflex);
  }
  for (int f = 0; f < scn->nflex; f++) {
    int vadr = scn->flexvertadr[f], vnum = scn->flexvertnum[f];
    int eadr = scn->flexedgeadr[f], enm = scn->flexedgenum[f];
    if (!within(vadr, vnum, nflexvert)) {
      return render_refuse(why, nwhy, "flex %d: scn.flexvertadr, flexvertnum (%d, %d) reach "
                           "past the scene's %d flex vertices", f, vadr, vnum, nflexvert);
    }
    if (!within(eadr, enm, nflexedge)) {
      return render_refuse(why, nwhy, "flex %d: scn.flexedgeadr, flexedgenum (%d, %d) reach "
                           "past the scene's %d flex edges", f, eadr, enm, nflexedge);
    }
    if (!within(scn->flexfaceadr[f], scn->flexfaceused[f], nflexface)) {
      return render_refuse(why, nwhy, "flex %d: scn.flexfaceadr, flexfaceused (%d, %d) reach "
                           "past the scene's %d flex faces (mjv_makeScene leaves flexfaceused "
                           "unset until mjv_updateScene fills the scene)", f,
                           scn->flexfaceadr[f], scn->flexfaceused[f], nflexface);
    }
    for (int e = eadr; e < eadr + enm; e++) {
      int v1 = scn->flexedge[2*e], v2 = scn->flexedge[2*e+1];
      if (v1 < 0 || v2 < 0 || vadr + v1 >= nflexvert || vadr + v2 >= nflexvert) {
        return render_refuse(why, nwhy, "flex %d: edge %d joins vertices (%d, %d) past the "
                             "scene's %d flex vertices", f, e, v1, v2, nflexvert);
      }
    }
  }
  for (int i = 0; i < scn->ngeom; i++) {
    const mjvGeom* g = scn->geoms + i;
    if (g->matid >= mjMAXMATERIAL) {
      return render_refuse(why, nwhy, "scn.geoms[%d].matid=%d is past the context's "
                           "mjMAXMATERIAL (%d) materials", i, g->matid, mjMAXMATERIAL);
    }
    int texid = g->texid;
    if (texid < 0 && g->matid >= 0) {
      texid = con->mat_texid[mjNTEXROLE*g->matid + mjTEXROLE_RGB];
    }
    if (texid >= mjMAXTEXTURE) {
      return render_refuse(why, nwhy, "scn.geoms[%d] uses texture %d, past the context's "
                           "mjMAXTEXTURE (%d) textures (its texid, or con.mat_texid of its "
                           "material)", i, texid, mjMAXTEXTURE);
    }
    if (g->type == mjGEOM_FLEX && (g->objid < 0 || g->objid >= scn->nflex)) {
      return render_refuse(why, nwhy, "scn.geoms[%d] is flex %d, but the scene has %d", i,
                           g->objid, scn->nflex);
    }
    if (g->type == mjGEOM_SKIN && (g->objid < 0 || g->objid >= scn->nskin)) {
      return render_refuse(why, nwhy, "scn.geoms[%d] is skin %d, but the scene has %d", i,
                           g->objid, scn->nskin);
    }
    if (!memchr(g->label, 0, sizeof(g->label))) {
      return render_refuse(why, nwhy, "scn.geoms[%d].label has no terminating NUL", i);
    }
  }
  return 0;
}


//---------------------------------- one call per mjData -------------------------------------------
//
// A call that writes an mjData (the guards of functions taking a non-const mjData*) holds
// it for its duration.  Another thread's call on it is refused: MuJoCo's functions keep
// no lock, and two steps of one mjData overwrite each other's arena and stack.  The
// holding thread may nest calls (a callback may use the stack, compute a Jacobian,
// rerun kinematics), except those that restart the pipeline and reset the arena
// (mj_step, mj_forward, mj_resetData, ...): inside the call that is computing d, they
// would pull the contacts and constraint rows from under it.

typedef struct {
  const mjData* d;
  pthread_t owner;
  int depth;                    // calls on d on the owner's thread, nested
} mjcffi_claim;

#define MJCFFI_MAX_CLAIMS 1024  // mjData held at once, all threads together
static mjcffi_claim claims[MJCFFI_MAX_CLAIMS];
static int nclaims;
static pthread_mutex_t claims_lock = PTHREAD_MUTEX_INITIALIZER;

static int mjcffi_refuse_call(int kind, const char* func, const char* why) {
  snprintf(errors.message, sizeof(errors.message), "%s: %s", func, why);
  errors.pending = 1;
  errors.kind = kind;
  return 1;
}

int mjcffi_data_enter(const mjData* d, int restarts, const char* func) {
  if (!d) {
    return 0;                   // MuJoCo's own NULL check speaks for itself
  }
  pthread_t self = pthread_self();
  const char* why = NULL;
  int kind = MJCFFI_ERROR_BUSY;
  pthread_mutex_lock(&claims_lock);
  int i = 0;
  while (i < nclaims && claims[i].d != d) {
    i++;
  }
  if (i == nclaims) {
    if (nclaims < MJCFFI_MAX_CLAIMS) {
      claims[nclaims++] = (mjcffi_claim){d, self, 1};
    } else {
      why = "more mjData are in MuJoCo calls at once than mjcffi can track (1024)";
    }
  } else if (!pthread_equal(claims[i].owner, self)) {
    why = "this mjData is in a MuJoCo call on another thread; an mjData takes one "
          "call at a time (give each thread an MjData of its own)";
  } else if (restarts) {
    kind = MJCFFI_ERROR_REENTRY;
    why = "this mjData is in a MuJoCo call on this thread already (a callback "
          "re-entered MuJoCo with the data being computed); this call would reset "
          "the arrays that call is using";
  } else {
    claims[i].depth++;
  }
  pthread_mutex_unlock(&claims_lock);
  return why ? mjcffi_refuse_call(kind, func, why) : 0;
}

void mjcffi_data_leave(const mjData* d) {
  if (!d) {
    return;
  }
  pthread_mutex_lock(&claims_lock);
  for (int i = 0; i < nclaims; i++) {
    if (claims[i].d == d) {
      if (--claims[i].depth == 0) {
        claims[i] = claims[--nclaims];
      }
      break;
    }
  }
  pthread_mutex_unlock(&claims_lock);
}


//---------------------------------- the arena ----------------------------------------------------
//
// The contact, constraint and island arrays of an mjData live in its arena, allocated by
// MuJoCo's own mj_arenaAllocByte in a step: contacts at the start, then the constraint rows
// (MJDATA_ARENA_POINTERS_SOLVER in mjxmacro.h), the islands, and the dual solver's and the
// effective metric's arrays.  These two functions lay them out for given counts, as the
// official bindings' private _realloc_con_efc and _realloc_island do, so that arrays
// computed elsewhere (MJX, MuJoCo Warp) can be copied into an mjData.  As there, the dual
// solver's rows come right after the constraint rows (a step puts them after the islands).
// They return 0, or 1 when the arena is too small; then every count they laid out is 0.

// Exported by libmujoco but declared in no public header: bytes from the arena, aligned,
// or NULL when the arena (what the stack leaves of it) is full.
void* mj_arenaAllocByte(mjData* d, size_t bytes, size_t alignment);

// The X-macros' sizes, read from the model m and the data d in scope (put back below).
#undef MJ_M
#define MJ_M(n) m->n
#undef MJ_D
#define MJ_D(n) d->n

// Every arena array gone, every count of rows 0: what a failed layout leaves behind.
static void mjcffi_clear_arena(mjData* d) {
#define X(type, name, nr, nc) d->name = NULL;
  MJDATA_ARENA_POINTERS
#undef X
  d->contact = (mjContact*)d->arena;
  d->parena = 0;
  d->ncon = d->ne = d->nf = d->nl = d->nefc = d->nJ = d->nY = d->nA = 0;
  d->nisland = d->nidof = 0;
  d->efm_active = 0;
  d->nefmK = d->nefmcon = d->nefmT = d->nefmA = d->nefmdof = d->nefmL = 0;
}

// Allocate one X-macro list's arrays in order, or jump to `fail`.
#define MJCFFI_ALLOC(type, name, nr, nc)                                           \
  d->name = (type*)mj_arenaAllocByte(d, sizeof(type) * (size_t)(nr) * (size_t)(nc), \
                                     _Alignof(type));                               \
  if (!d->name) goto fail;

int mjcffi_realloc_con_efc(const mjModel* m, mjData* d, int ncon, int nefc, int nJ) {
  int keep_nJ = d->nJ;
  mjcffi_clear_arena(d);
  if (ncon < 0 || nefc < 0 || nJ < -1) {
    return 1;
  }
  d->ncon = ncon;
  d->nefc = nefc;
  d->nJ = nJ < 0 ? keep_nJ : nJ;   // as the official: an omitted nJ keeps the last one
  d->contact = (mjContact*)mj_arenaAllocByte(d, sizeof(mjContact) * (size_t)ncon,
                                             _Alignof(mjContact));
  if (!d->contact) goto fail;
#define X MJCFFI_ALLOC
  MJDATA_ARENA_POINTERS_SOLVER
  if (mj_isDual(m)) {
    MJDATA_ARENA_POINTERS_DUAL     // rows only: nY and nA are 0 until the solver runs
  }
#undef X
  return 0;
fail:
  mjcffi_clear_arena(d);
  return 1;
}

// Whether an arena array outside the island block ends after `start`, the island block's
// first byte: then the block is not the last thing in the arena and cannot be reused.
static int mjcffi_after_islands(const mjModel* m, const mjData* d, const char* start) {
  int after = 0;
#define X(type, name, nr, nc)                                                      \
  if (d->name && (const char*)d->name + sizeof(type) * (size_t)(nr) * (size_t)(nc) > start) \
    after = 1;
  MJDATA_ARENA_POINTERS_CONTACT
  MJDATA_ARENA_POINTERS_SOLVER
  MJDATA_ARENA_POINTERS_DUAL
  MJDATA_ARENA_POINTERS_EFM
#undef X
  return after;
}

static void mjcffi_clear_islands(mjData* d, size_t parena) {
#define X(type, name, nr, nc) d->name = NULL;
  MJDATA_ARENA_POINTERS_ISLAND
#undef X
  d->nisland = d->nidof = 0;
  d->parena = parena;
}

int mjcffi_realloc_island(const mjModel* m, mjData* d, int nisland, int nidof) {
  // where the island block starts, if it is in the arena
  char* arena = (char*)d->arena;
  char* start = NULL;
#define X(type, name, nr, nc)                                                      \
  if (d->name && (char*)d->name >= arena && (char*)d->name <= arena + d->parena && \
      (!start || (char*)d->name < start))                                          \
    start = (char*)d->name;
  MJDATA_ARENA_POINTERS_ISLAND
#undef X

  // reuse the old block when nothing follows it; else add a new one at the end
  size_t parena = d->parena;
  if (start && !mjcffi_after_islands(m, d, start)) {
    parena = (size_t)(start - arena);
  }
  mjcffi_clear_islands(d, parena);
  if (nisland < 0 || nidof < 0) {
    return 1;
  }
  d->nisland = nisland;
  d->nidof = nidof;
#define X MJCFFI_ALLOC
  MJDATA_ARENA_POINTERS_ISLAND
#undef X
  return 0;
fail:
  mjcffi_clear_islands(d, parena);
  return 1;
}

#undef MJCFFI_ALLOC
#undef MJ_M
#define MJ_M(n) n
#undef MJ_D
#define MJ_D(n) n


//---------------------------------- pickling an mjData ------------------------------------------
//
// A pickled mjData is (model, header, buffer, arena, layout): the header is mjData's own bytes up
// to `buffer` (sizes, statistics, counts), the buffer its nbuffer bytes, the arena the parena
// bytes in use (the stack above them is scratch), and the layout below.  Neither holds an
// address.  Unpickling takes every buffer pointer from a fresh mj_makeData of the model and every
// arena pointer from an offset that must lie, with room for its count, inside the arena bytes.
// It refuses any count that the model and the arena cannot hold, and any index that a step
// follows before recomputing it, before it writes anything.

// layout: tag | signature | the offset in the arena of each of its arrays (-1: none)
static const char mjcffi_tag[8] = {'m', 'j', 'c', 'f', 'f', 'i', 'D', '1'};

enum {
#define X(type, name, nr, nc) MJCFFI_ARENA_##name,
  MJDATA_ARENA_POINTERS
#undef X
  MJCFFI_NARENA
};

#define MJCFFI_INFO_SIZE offsetof(mjData, buffer)
#define MJCFFI_AT_SIGNATURE sizeof(mjcffi_tag)
#define MJCFFI_AT_OFFSETS (MJCFFI_AT_SIGNATURE + sizeof(uint64_t))
#define MJCFFI_LAYOUT_SIZE (MJCFFI_AT_OFFSETS + MJCFFI_NARENA * sizeof(int64_t))
#define MJCFFI_FIELD_SIZE(field) sizeof(((mjData*)0)->field)

size_t mjcffi_data_header_size(void) {
  return MJCFFI_INFO_SIZE;
}

size_t mjcffi_data_layout_size(void) {
  return MJCFFI_LAYOUT_SIZE;
}

int mjcffi_save_layout(const mjData* d, char* layout) {
  memcpy(layout, mjcffi_tag, sizeof(mjcffi_tag));
  memcpy(layout + MJCFFI_AT_SIGNATURE, &d->signature, sizeof(uint64_t));
  int64_t offsets[MJCFFI_NARENA];
#define X(type, name, nr, nc)                                                                   \
  offsets[MJCFFI_ARENA_##name] =                                                                \
      d->name ? (int64_t)((const char*)d->name - (const char*)d->arena) : -1;
  MJDATA_ARENA_POINTERS
#undef X
  memcpy(layout + MJCFFI_AT_OFFSETS, offsets, sizeof(offsets));

  // what belongs to this process alone: the thread pool, and the stack with its frame address
  // (empty at rest; left in use by a caught error, or seen so from a callback)
  return d->threadpool || d->threadlock || d->pstack || d->pbase;
}

void mjcffi_clear_local(char* header) {
#define MJCFFI_ZERO(field) memset(header + offsetof(mjData, field), 0, MJCFFI_FIELD_SIZE(field));
  MJCFFI_ZERO(threadpool) MJCFFI_ZERO(threadlock) MJCFFI_ZERO(pstack) MJCFFI_ZERO(pbase)
#undef MJCFFI_ZERO
}

// the int counts of a saved mjData, each checked to be >= 0 first
#define MJCFFI_COUNTS                                                                           \
  C(ncon) C(ne) C(nf) C(nl) C(nefc) C(nJ) C(efm_active) C(nefmK) C(nefmcon) C(nefmT) C(nefmA)  \
  C(nefmdof) C(nefmL) C(nY) C(nA) C(nisland) C(nidof) C(ntree_awake) C(nbody_awake)           \
  C(nparent_awake) C(nv_awake)

typedef struct {
  mjtSize narena, nbuffer;
  size_t pstack, pbase, parena;
  uintptr_t threadpool;
  int nplugin;
#define C(n) int n;
  MJCFFI_COUNTS
#undef C
} mjcffi_saved;

// Refuse: say why (which field, which bound) and return 1.
static int mjcffi_refuse(char* why, size_t nwhy, const char* format, ...) {
  va_list args;
  va_start(args, format);
  vsnprintf(why, nwhy, format, args);
  va_end(args);
  return 1;
}

// Whether an arena array at `offset` (-1: none) of `count` entries of `size` bytes, aligned to
// `align`, lies inside the parena bytes in use.
static int mjcffi_check_arena_array(const char* name, int64_t offset, int64_t count, size_t size,
                                    size_t align, size_t parena, char* why, size_t nwhy) {
  if (offset == -1) {
    return 0;
  }
  if (offset < 0 || (uint64_t)offset > parena || (uint64_t)offset % align) {
    return mjcffi_refuse(why, nwhy, "%s: arena offset %lld is not an offset in [0, parena = %zu] "
                         "aligned to %zu", name, (long long)offset, parena, align);
  }
  if (count < 0 || (uint64_t)count > (parena - (uint64_t)offset) / size) {
    return mjcffi_refuse(why, nwhy, "%s: %lld entries of %zu bytes at arena offset %lld overrun "
                         "parena = %zu", name, (long long)count, size, (long long)offset, parena);
  }
  return 0;
}

// Entry i of `field`, an array of d, as the saved buffer holds it (laid out as d's own).
static int mjcffi_saved_int(const mjData* d, const char* buffer, const void* field, int64_t i) {
  int value;
  memcpy(&value, buffer + ((const char*)field - (const char*)d->buffer) + i * sizeof(int),
         sizeof(int));
  return value;
}

static mjtNum mjcffi_saved_num(const mjData* d, const char* buffer, const void* field,
                               int64_t i) {
  mjtNum value;
  memcpy(&value, buffer + ((const char*)field - (const char*)d->buffer) + i * sizeof(mjtNum),
         sizeof(mjtNum));
  return value;
}

// Entries [start, start + n) of the saved int array `name` lie in [lo, hi).
#define MJCFFI_CHECK_INDICES(name, start, n, lo, hi)                                           \
  for (int64_t i = (start); i < (int64_t)(start) + (int64_t)(n); i++) {                        \
    int v = mjcffi_saved_int(d, buffer, d->name, i);                                           \
    if (v < (lo) || v >= (hi)) {                                                               \
      return mjcffi_refuse(why, nwhy, #name "[%lld] = %d is outside [%lld, %lld)",             \
                           (long long)i, v, (long long)(lo), (long long)(hi));                 \
    }                                                                                          \
  }

// The delay buffers in d->history, each [user, cursor, times(n), values(n*dim)]: they lie inside
// it (the model comes from the same pickle), and their ring cursors, which a step indexes with,
// are integers in [0, n).
static int mjcffi_check_history(const mjModel* m, const mjData* d, const char* buffer,
                                const char* what, int n, const int* history,
                                const int* historyadr, const int* dim, char* why, size_t nwhy) {
  for (int i = 0; i < n; i++) {
    int nsample = history[2*i];
    if (nsample <= 0) {
      continue;
    }
    int64_t end = (int64_t)historyadr[i] + 2 + (int64_t)nsample * (1 + (dim ? dim[i] : 1));
    if (historyadr[i] < 0 || (dim && dim[i] < 0) || end > m->nhistory) {
      return mjcffi_refuse(why, nwhy, "the model's history buffer of %s %d (address %d, %d "
                           "samples) overruns nhistory = %lld", what, i, historyadr[i], nsample,
                           (long long)m->nhistory);
    }
    mjtNum cursor = mjcffi_saved_num(d, buffer, d->history, (int64_t)historyadr[i] + 1);
    if (!(cursor >= 0 && cursor < nsample) || cursor != (mjtNum)(int)cursor) {
      return mjcffi_refuse(why, nwhy, "history: the cursor of %s %d is %g, not an integer in "
                           "[0, %d)", what, i, cursor, nsample);
    }
  }
  return 0;
}

// The contents of the saved buffer that a step follows as indices before recomputing them.
static int mjcffi_check_buffer(const mjModel* m, const mjData* d, const mjcffi_saved* s,
                               const char* buffer, char* why, size_t nwhy) {
  // sleep: tree_asleep links the trees of a sleeping island (< 0: awake), then the awake lists
  MJCFFI_CHECK_INDICES(tree_asleep, 0, m->ntree, INT_MIN, m->ntree)
  MJCFFI_CHECK_INDICES(body_awake_ind, 0, s->nbody_awake, 0, m->nbody)
  MJCFFI_CHECK_INDICES(parent_awake_ind, 0, s->nparent_awake, 0, m->nbody)
  MJCFFI_CHECK_INDICES(dof_awake_ind, 0, s->nv_awake, 0, m->nv)

  // tendon paths, kept as they are while a tendon sleeps: wrap_xpos holds 2*nwrap points
  for (int i = 0; i < m->ntendon; i++) {
    int adr = mjcffi_saved_int(d, buffer, d->ten_wrapadr, i);
    int num = mjcffi_saved_int(d, buffer, d->ten_wrapnum, i);
    if (adr < 0 || num < 0 || (int64_t)adr + num > 2 * (int64_t)m->nwrap) {
      return mjcffi_refuse(why, nwhy, "ten_wrapadr[%d] = %d, ten_wrapnum[%d] = %d: the path "
                           "leaves [0, 2*nwrap = %lld)", i, adr, i, num,
                           2 * (long long)m->nwrap);
    }
    MJCFFI_CHECK_INDICES(wrap_obj, adr, num, -2, m->ngeom)
  }

  // delay buffers
  return mjcffi_check_history(m, d, buffer, "actuator", m->nactuator, m->actuator_history,
                              m->actuator_historyadr, NULL, why, nwhy) ||
         mjcffi_check_history(m, d, buffer, "sensor", m->nsensor, m->sensor_history,
                              m->sensor_historyadr, m->sensor_dim, why, nwhy);
}

// The X-macros' sizes: the model's, and the saved data's counts (checked before they are used).
#undef MJ_M
#define MJ_M(n) ((int64_t)m->n)
#undef MJ_D
#define MJ_D(n) ((int64_t)s.n)

int mjcffi_restore_data(const mjModel* m, mjData* d, const char* info, size_t ninfo,
                        const char* buffer, size_t nbuffer, const char* arena, size_t narena,
                        const char* layout, size_t nlayout, char* why, size_t nwhy) {
  // the header's and the layout's sizes, the layout's tag; then the sizes and counts
  if (ninfo != MJCFFI_INFO_SIZE) {
    return mjcffi_refuse(why, nwhy, "does not fit its model: the header has %zu bytes, this "
                         "mjcffi's %zu", ninfo, (size_t)MJCFFI_INFO_SIZE);
  }
  if (nlayout != MJCFFI_LAYOUT_SIZE || memcmp(layout, mjcffi_tag, sizeof(mjcffi_tag))) {
    return mjcffi_refuse(why, nwhy, "the layout (%zu bytes) is not one that this mjcffi "
                         "writes (%zu bytes, tagged)", nlayout, (size_t)MJCFFI_LAYOUT_SIZE);
  }
  mjcffi_saved s;
#define MJCFFI_READ(field)                                                     \
  _Static_assert(sizeof(s.field) == MJCFFI_FIELD_SIZE(field), #field);         \
  memcpy(&s.field, info + offsetof(mjData, field), sizeof(s.field));
  MJCFFI_READ(narena) MJCFFI_READ(nbuffer) MJCFFI_READ(nplugin) MJCFFI_READ(pstack)
  MJCFFI_READ(pbase) MJCFFI_READ(parena) MJCFFI_READ(threadpool)
#define C(n) MJCFFI_READ(n)
  MJCFFI_COUNTS
#undef C
#undef MJCFFI_READ

  // sizes that the model fixes, and what a pickle never holds
  if (s.narena != d->narena || s.nbuffer != d->nbuffer || s.nplugin != d->nplugin) {
    return mjcffi_refuse(why, nwhy, "does not fit its model: narena, nbuffer, nplugin = %lld, "
                         "%lld, %d, but the model's data has %lld, %lld, %d", (long long)s.narena, (long long)s.nbuffer,
                         s.nplugin, (long long)d->narena, (long long)d->nbuffer, d->nplugin);
  }
  if (nbuffer != (size_t)d->nbuffer) {
    return mjcffi_refuse(why, nwhy, "does not fit its model: the buffer has %zu bytes, but "
                         "nbuffer = %lld", nbuffer,
                         (long long)d->nbuffer);
  }
  if (s.pstack || s.pbase || s.threadpool) {
    return mjcffi_refuse(why, nwhy, "pstack, pbase, threadpool = %zu, %zu, %zu: a pickle holds "
                         "no stack and no thread pool", s.pstack, s.pbase, (size_t)s.threadpool);
  }
  if (s.parena > (size_t)s.narena || narena != s.parena) {
    return mjcffi_refuse(why, nwhy, "parena = %zu, but %zu arena bytes and narena = %lld",
                         s.parena, narena, (long long)s.narena);
  }

  // flags: C booleans are 0 or 1, and threadlock is a running thread pool's (so 0)
  static const struct { const char* name; size_t offset; unsigned char most; } flags[] = {
    {"threadlock", offsetof(mjData, threadlock), 0},
    {"flg_energypos", offsetof(mjData, flg_energypos), 1},
    {"flg_energyvel", offsetof(mjData, flg_energyvel), 1},
    {"flg_subtreevel", offsetof(mjData, flg_subtreevel), 1},
    {"flg_rnepost", offsetof(mjData, flg_rnepost), 1},
  };
  for (size_t i = 0; i < sizeof(flags) / sizeof(flags[0]); i++) {
    unsigned char flag = (unsigned char)info[flags[i].offset];
    if (flag > flags[i].most) {
      return mjcffi_refuse(why, nwhy, "%s = %d is outside [0, %d]", flags[i].name, flag,
                           flags[i].most);
    }
  }

  // counts: none negative, each within what the model and the arena can hold
#define C(n) \
  if (s.n < 0) return mjcffi_refuse(why, nwhy, #n " = %d is negative", s.n);
  MJCFFI_COUNTS
#undef C
  int64_t most = s.narena / 4;    // arena entries are at least 4 bytes (int), contacts more
  const struct { const char* name; int64_t value, bound; } bounded[] = {
    {"ne + nf + nl", (int64_t)s.ne + s.nf + s.nl, s.nefc},
    {"nisland", s.nisland, m->ntree},
    {"nidof", s.nidof, m->nv},
    {"ntree_awake", s.ntree_awake, m->ntree},
    {"nbody_awake", s.nbody_awake, m->nbody},
    {"nparent_awake", s.nparent_awake, m->nbody},
    {"nv_awake", s.nv_awake, m->nv},
    {"efm_active", s.efm_active, 2},
    {"nefmT", s.nefmT, m->ntendon},
    {"nefmA", s.nefmA, m->nactuator},
    {"ncon", s.ncon, s.narena / (int64_t)sizeof(mjContact)},
    {"nefc", s.nefc, most}, {"nJ", s.nJ, most}, {"nY", s.nY, most}, {"nA", s.nA, most},
    {"nefmK", s.nefmK, most}, {"nefmcon", s.nefmcon, most}, {"nefmdof", s.nefmdof, most},
    {"nefmL", s.nefmL, most},
  };
  for (size_t i = 0; i < sizeof(bounded) / sizeof(bounded[0]); i++) {
    if (bounded[i].value > bounded[i].bound) {
      return mjcffi_refuse(why, nwhy, "%s = %lld exceeds %lld", bounded[i].name,
                           (long long)bounded[i].value, (long long)bounded[i].bound);
    }
  }

  // solver statistics: at most mjNSOLVER iterations are recorded per island
  for (int i = 0; i < mjNISLAND; i++) {
    int niter;
    memcpy(&niter, info + offsetof(mjData, solver_niter) + i * sizeof(int), sizeof(int));
    if (niter < 0 || niter > mjNSOLVER) {
      return mjcffi_refuse(why, nwhy, "solver_niter[%d] = %d is outside [0, mjNSOLVER = %d]",
                           i, niter, mjNSOLVER);
    }
  }

  // arena arrays: each inside the arena bytes, with room for its count
  int64_t offsets[MJCFFI_NARENA];
  memcpy(offsets, layout + MJCFFI_AT_OFFSETS, sizeof(offsets));
#define X(type, name, nr, nc)                                                                  \
  if (mjcffi_check_arena_array(#name, offsets[MJCFFI_ARENA_##name], (nr) * (int64_t)(nc),       \
                               sizeof(type), _Alignof(type), s.parena, why, nwhy)) {            \
    return 1;                                                                                  \
  }
  MJDATA_ARENA_POINTERS
#undef X

  if (mjcffi_check_buffer(m, d, &s, buffer, why, nwhy)) {
    return 1;
  }

  // All checked: copy.  Buffer pointers stay d's own and arena pointers come from the offsets;
  // the plugin ids and instances stay d's own too (two datas must not share an instance).
  uintptr_t* plugins = NULL;
  if (d->nplugin) {
    plugins = (uintptr_t*)malloc(2 * sizeof(uintptr_t) * d->nplugin);
    if (!plugins) {
      return mjcffi_refuse(why, nwhy, "out of memory");
    }
    for (int i = 0; i < d->nplugin; i++) {
      plugins[2*i] = (uintptr_t)d->plugin[i];
      plugins[2*i + 1] = d->plugin_data[i];
    }
  }
  void* buffer_now = d->buffer;
  void* arena_now = d->arena;
  uintptr_t threadpool = d->threadpool;
  memcpy(d, info, MJCFFI_INFO_SIZE);
  d->buffer = buffer_now;
  d->arena = arena_now;
  d->threadpool = threadpool;
  memcpy(&d->signature, layout + MJCFFI_AT_SIGNATURE, sizeof(uint64_t));
#define X(type, name, nr, nc)                                                                  \
  d->name = offsets[MJCFFI_ARENA_##name] < 0 ? NULL                                            \
                                             : (type*)((char*)arena_now + offsets[MJCFFI_ARENA_##name]);
  MJDATA_ARENA_POINTERS
#undef X
  memcpy(buffer_now, buffer, nbuffer);
  memcpy(arena_now, arena, narena);
  for (int i = 0; i < d->nplugin; i++) {
    d->plugin[i] = (int)plugins[2*i];
    d->plugin_data[i] = plugins[2*i + 1];
  }
  free(plugins);
  return 0;
}

#undef MJ_M
#define MJ_M(n) n
#undef MJ_D
#define MJ_D(n) n


//---------------------------------- MJB bytes -----------------------------------------------------
//
// mj_loadModelBuffer allocates the model that an MJB's sizes describe before it compares them with
// the bytes it was given, so one corrupted size can make it allocate gigabytes first.  This applies
// its final rule beforehand: the bytes hold exactly the header, the sizes, the structs and the
// arrays that those sizes describe.  (Sizes it would refuse, negative or too large, describe a
// wrong byte count too, or none that fits in a double exactly: refused here as well.)

#define MJCFFI_MJB_NHEADER 5    // ints before the sizes: id, sizeof(mjtNum), nsize, version, nptr

int mjcffi_check_mjb(const char* mjb, size_t n, char* why, size_t nwhy) {
  int nsize = 0;
#define X(name) nsize += _Generic(((mjModel*)0)->name, mjtSize: 1, default: 0);
  MJMODEL_SIZES
#undef X
  size_t at = MJCFFI_MJB_NHEADER * sizeof(int);
  int header[MJCFFI_MJB_NHEADER];
  if (n < at + nsize * sizeof(mjtSize)) {
    return 0;                     // too short: MuJoCo refuses it and says why
  }
  memcpy(header, mjb, sizeof(header));
  if (header[2] != nsize) {
    return 0;                     // another layout: likewise
  }

  // the sizes, as mj_loadModelBuffer reads them (-1 is a legal njmax or nconmax)
  mjModel model;
  mjModel* m = &model;
  memset(m, 0, sizeof(mjModel));
  const char* sizes = mjb + at;
#define X(name)                                                                  \
  if (_Generic(m->name, mjtSize: 1, default: 0)) {                               \
    mjtSize size;                                                                \
    memcpy(&size, sizes, sizeof(mjtSize));                                       \
    sizes += sizeof(mjtSize);                                                    \
    m->name = size;                                                              \
  }
  MJMODEL_SIZES
#undef X

  // the byte count that mj_loadModelBuffer requires (floating point: no overflow)
  size_t flags = offsetof(mjModel, flg_adhesion) + sizeof(mjtBool) -
                 offsetof(mjModel, flg_gravcomp);          // the mjtBool flg_* fields
  double expected = (double)(at + nsize * sizeof(mjtSize) + flags + sizeof(mjOption) +
                             sizeof(mjVisual) + sizeof(mjStatistic));
  {
    MJMODEL_POINTERS_PREAMBLE(m)
#define X(type, name, nr, nc) expected += (double)sizeof(type) * (double)(m->nr) * (double)(nc);
    MJMODEL_POINTERS
#undef X
  }
  if (expected != (double)n) {
    return mjcffi_refuse(why, nwhy, "the MJB holds %zu bytes, but its sizes describe %.0f",
                         n, expected);
  }
  return 0;
}


//---------------------------------- a timer ------------------------------------------------------

// An mjfTime for mjcb_time: a monotonic clock in seconds, read in C so that MuJoCo's
// profiler (dozens of calls per step) takes no GIL.
mjtNum mjcffi_timer(void) {
  struct timespec now;
  clock_gettime(CLOCK_MONOTONIC, &now);
  return (mjtNum)now.tv_sec + 1e-9 * (mjtNum)now.tv_nsec;
}
