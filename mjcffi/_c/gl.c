// OpenGL as MuJoCo's renderer meets it: which context is current on this thread, whether
// mjr_makeContext can run at all, and what mjr_render will follow in a scene.  Declared
// in gl.h (Python) and guard_chain.h (mjr_makeContext's guard).

#define _GNU_SOURCE   // dl_iterate_phdr, under -std=c11

#include <limits.h>
#ifdef __linux__
#include <link.h>
#endif
#include <pthread.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <string.h>

#include <mujoco/mujoco.h>

#include "guard_chain.h"
#include "guard.h"
#include "gl.h"

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
    return mjcffi_record_error(MJCFFI_ERROR_FATAL, why);
  }
  return 0;
}

void mjcffi_render_failed(void) {
  // only the search for the OpenGL library runs inside the static; other errors
  // (a framebuffer too large, ...) leave the renderer usable
  if (strstr(mjcffi_last_message(), "OpenGL platform library")) {
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
