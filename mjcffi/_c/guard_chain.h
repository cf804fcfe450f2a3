/* The chain of guards that mjcffi/_c/guard.c keeps per thread, shared with the
   generated mjcffi/_c/generated/guards.c.  C only: cffi's cdef never reads this file (it
   cannot parse jmp_buf).  The guards on a thread form a chain, innermost
   first; enter arms one, leave disarms it, with caught=1 after a longjmp. */

#ifndef MJCFFI_GUARD_CHAIN_H_
#define MJCFFI_GUARD_CHAIN_H_

#include <setjmp.h>

#include <mujoco/mujoco.h>
#include <mujoco/mjbatch.h>

typedef struct mjcffi_guard_ {
  jmp_buf env;                  /* where a caught mju_error lands */
  struct mjcffi_guard_* outer;  /* enclosing guard on this thread, or NULL */
  mjfLogHandler handler;        /* thread-local log handler to restore on exit */
} mjcffi_guard;

void mjcffi_guard_enter(mjcffi_guard* guard);

/* Hold d for a call that writes it (d may be NULL): 0, or 1 with the error pending
   (MJCFFI_ERROR_BUSY: another thread holds it; MJCFFI_ERROR_REENTRY: this thread
   does, and `restarts`, a call that resets the arena, may not nest).  func names
   the call in the message.  Each 0 is matched by one mjcffi_data_leave. */
int mjcffi_data_enter(const mjData* d, int restarts, const char* func);
void mjcffi_data_leave(const mjData* d);

/* For a thread working for the caller that holds d (a rollout pool's): d's claim becomes
   this thread's, for the rest of the call; the caller's mjcffi_data_leave drops it. */
void mjcffi_data_adopt(const mjData* d);

/* Hold batch b for a call (b may be NULL): 0, or 1 with MJCFFI_ERROR_POOL_REENTRY pending
   when a call holds it already, on any thread.  Each 0 is matched by mjcffi_batch_leave. */
int mjcffi_batch_enter(const mjBatch* b, const char* func);
void mjcffi_batch_leave(const mjBatch* b);

/* The spec of `element` (mjs_getSpec), or NULL for NULL: what the guards of functions
   taking an element hold, with mjcffi_spec_enter/leave (claims.h). */
const mjSpec* mjcffi_spec_of(const mjsElement* element);

/* mjr_makeContext's guard: 0, or 1 with a FatalError pending when no OpenGL library is
   loaded or an earlier call failed; mjcffi_render_failed records a failure. */
int mjcffi_render_enter(const char* func);
void mjcffi_render_failed(void);
void mjcffi_guard_leave(mjcffi_guard* guard, int caught);

/* Make `text` this thread's pending error, of MJCFFI_ERROR_* `kind`, as a caught
   mju_error is (for a refusal before MuJoCo runs); returns 1.  mjcffi_last_message:
   the text of the last error recorded on this thread, taken or not. */
int mjcffi_record_error(int kind, const char* text);
const char* mjcffi_last_message(void);

#endif  /* MJCFFI_GUARD_CHAIN_H_ */
