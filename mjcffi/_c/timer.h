/* A C timer for mjcb_time (timer.c).
   Read by mjcffi/_c/build.py into the cffi cdef, and included by the C files.
   Hand-written. */

/* An mjfTime: CLOCK_MONOTONIC in seconds, for mjcb_time (no Python, no GIL per call). */
mjtNum mjcffi_timer(void);
