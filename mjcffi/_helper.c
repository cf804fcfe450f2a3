// mjcffi's C helper: code that must run natively, beside the cffi wrappers.
// Compiled into mjcffi._mjcffi by mjcffi/_build.py; declared in _helper.h.

#include <setjmp.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

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
      arena_used > dest->narena) {
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
