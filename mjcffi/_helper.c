// mjcffi's C helper: code that must run natively, beside the cffi wrappers.
// Compiled into mjcffi._mjcffi by mjcffi/_build.py; declared in _helper.h.

#define _POSIX_C_SOURCE 200809L   // clock_gettime, also under a strict -std=c11

#include <setjmp.h>
#include <stdint.h>
#include <stdio.h>
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

const char* mjcffi_take_error(void) {
  if (!errors.pending) {
    return NULL;
  }
  errors.pending = 0;
  return errors.message;
}

// One guard around the whole loop: the per-step cost is mj_step's alone.
int mjcffi_step(const mjModel* m, mjData* d, int nstep) {
  mjcffi_guard guard;
  mjcffi_guard_enter(&guard);
  if (setjmp(guard.env)) {
    mjcffi_guard_leave(&guard, 1);
    return 1;
  }
  for (int i = 0; i < nstep; i++) {
    mj_step(m, d);
  }
  mjcffi_guard_leave(&guard, 0);
  return 0;
}


// Unpickling an mjData: `dest` is a fresh mj_makeData of the same model.  Copy
// the saved struct whole (scalars, counters, statistics), then move each of
// its pointers from the saved allocation onto dest's own buffer and arena,
// using mjxmacro.h's lists of them, and copy the buffer and the used arena.
static void* mjcffi_rebase(const void* p, uintptr_t old, size_t size, void* now) {
  uintptr_t address = (uintptr_t)p;
  if (!p || address < old || address >= old + size) return NULL;
  return (char*)now + (address - old);
}

int mjcffi_restore_data(mjData* dest, const char* header, const char* buffer,
                        const char* arena, size_t arena_used) {
  const mjData* saved = (const mjData*)header;
  if (saved->nbuffer != dest->nbuffer || saved->narena != dest->narena ||
      arena_used > (size_t)dest->narena) {
    return 1;
  }
  void* buffer_now = dest->buffer;
  void* arena_now = dest->arena;
  uintptr_t buffer_old = (uintptr_t)saved->buffer;
  uintptr_t arena_old = (uintptr_t)saved->arena;
  memcpy(dest, saved, sizeof(mjData));
  dest->buffer = buffer_now;
  dest->arena = arena_now;
  dest->threadpool = 0;
#define X(type, name, nr, nc) \
  dest->name = (type*)mjcffi_rebase(saved->name, buffer_old, saved->nbuffer, buffer_now);
  MJDATA_POINTERS
#undef X
#define X(type, name, nr, nc) \
  dest->name = (type*)mjcffi_rebase(saved->name, arena_old, saved->narena, arena_now);
  MJDATA_ARENA_POINTERS
#undef X
  memcpy(buffer_now, buffer, dest->nbuffer);
  memcpy(arena_now, arena, arena_used);
  return 0;
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


//---------------------------------- a timer ------------------------------------------------------

// An mjfTime for mjcb_time: a monotonic clock in seconds, read in C so that MuJoCo's
// profiler (dozens of calls per step) takes no GIL.
mjtNum mjcffi_timer(void) {
  struct timespec now;
  clock_gettime(CLOCK_MONOTONIC, &now);
  return (mjtNum)now.tv_sec + 1e-9 * (mjtNum)now.tv_nsec;
}
