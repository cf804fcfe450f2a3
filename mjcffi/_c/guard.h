/* The guard chain (guard.c): the caught error's message and kind; mj_step's loops (step.c).
   Read by mjcffi/_c/build.py into the cffi cdef, and included by the C files.
   Hand-written. */

/* mjVERSION_HEADER of the headers this module was compiled against. */
int mjcffi_header_version(void);

/* The message of the mju_error caught by the last guarded call on this thread
   (an mjcffi_guard_* function or mjcffi_step), or NULL if that call caught
   none.  Clears it: a second call returns NULL.  The text stays valid until
   the next error caught on this thread. */
const char* mjcffi_take_error(void);

/* What the last error caught on this thread was: MuJoCo's mju_error (0), a call
   refused because another thread's call holds its mjData (1), or because it would
   restart the pipeline of an mjData that a call on this thread is computing (2), or
   because another thread's call holds its mjSpec (3; see claims.h), or because a
   callback of a pool's job called into a pool that is waiting for it (4: a Rollout,
   an MjSimPool, a Batch). */
#define MJCFFI_ERROR_FATAL 0
#define MJCFFI_ERROR_BUSY 1
#define MJCFFI_ERROR_REENTRY 2
#define MJCFFI_ERROR_SPEC_BUSY 3
#define MJCFFI_ERROR_POOL_REENTRY 4
int mjcffi_error_kind(void);

/* mj_step(m, d) nstep times under one guard (cffi releases the GIL around
   it): 0 when all steps ran, 1 when an mju_error was caught, MJCFFI_STEP_STOPPED
   when a SIGINT on the main thread stopped the loop before its last step (the
   steps done stay; interrupt.h).  After 1, d is left mid-step; see
   mjcffi/_support/errors.py for how to make it usable again. */
#define MJCFFI_STEP_STOPPED 2
int mjcffi_step(const mjModel* m, mjData* d, int nstep);

/* mujoco-py's substeps: nstep times fn(m, d) (when fn is not NULL) then mj_step(m, d),
   under one guard as mjcffi_step (mju_error in fn is caught too).  nstep 0: fn once,
   no step.  0, 1 when an error was caught or d is busy, or MJCFFI_STEP_STOPPED. */
int mjcffi_step_substep(const mjModel* m, mjData* d, int nstep, mjfGeneric fn);

/* Their loop, stopped by a SIGINT after `token` (interrupt.h; -1: never): for the pool
   threads, whose caller took the token, and for the benchmark of what Ctrl-C costs. */
int mjcffi_step_loop(const mjModel* m, mjData* d, int nstep, mjfGeneric fn, int token);
