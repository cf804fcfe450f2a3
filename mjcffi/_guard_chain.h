/* The chain of guards that mjcffi/_helper.c keeps per thread, shared with the
   generated mjcffi/_guards.c.  C only: cffi's cdef never reads this file (it
   cannot parse jmp_buf).  The guards on a thread form a chain, innermost
   first; enter arms one, leave disarms it, with caught=1 after a longjmp. */

#ifndef MJCFFI_GUARD_CHAIN_H_
#define MJCFFI_GUARD_CHAIN_H_

#include <setjmp.h>

#include <mujoco/mujoco.h>

typedef struct mjcffi_guard_ {
  jmp_buf env;                  /* where a caught mju_error lands */
  struct mjcffi_guard_* outer;  /* enclosing guard on this thread, or NULL */
  mjfLogHandler handler;        /* thread-local log handler to restore on exit */
} mjcffi_guard;

void mjcffi_guard_enter(mjcffi_guard* guard);
void mjcffi_guard_leave(mjcffi_guard* guard, int caught);

#endif  /* MJCFFI_GUARD_CHAIN_H_ */
