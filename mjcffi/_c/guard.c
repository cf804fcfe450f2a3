// The guard chain: MuJoCo's fatal errors caught per thread.  Declared in guard.h
// (Python) and guard_chain.h (C).

#define _GNU_SOURCE

#include <setjmp.h>
#include <stdio.h>
#include <string.h>

#include <mujoco/mujoco.h>

#include "guard_chain.h"
#include "guard.h"

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

// A refusal or an error found before MuJoCo ran (claims.c, gl.c): the pending error of
// this thread, as a caught mju_error is.
int mjcffi_record_error(int kind, const char* text) {
  snprintf(errors.message, sizeof(errors.message), "%s", text);
  errors.pending = 1;
  errors.kind = kind;
  return 1;
}

const char* mjcffi_last_message(void) {
  return errors.message;
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
