/* Ctrl-C in mjcffi's long C loops (interrupt.c): mj_step's nstep loop, rollouts, MjSimPool.
   Read by mjcffi/_c/build.py into the cffi cdef, and included by the C files.
   Hand-written. */

/* Record the thread that Python delivers SIGINT to (threading.main_thread().ident). */
void mjcffi_interrupt_init(unsigned long main_thread);

/* For a loop about to start on this thread: the count of SIGINTs so far, to pass to
   mjcffi_interrupted, or -1 when a SIGINT cannot stop it (not the main thread, or
   SIGINT is ignored or left to the system).  Puts mjcffi's SIGINT handler in front of
   the one installed now (Python's), which it forwards every SIGINT to. */
int mjcffi_interrupt_token(void);

/* 1 when a SIGINT arrived since `token` was taken (never for -1). */
int mjcffi_interrupted(int token);
