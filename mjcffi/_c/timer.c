// A C timer for mjcb_time.  Declared in timer.h.

#define _GNU_SOURCE   // clock_gettime under -std=c11

#include <time.h>

#include <mujoco/mujoco.h>

#include "timer.h"

//---------------------------------- a timer ------------------------------------------------------

// An mjfTime for mjcb_time: a monotonic clock in seconds, read in C so that MuJoCo's
// profiler (dozens of calls per step) takes no GIL.
mjtNum mjcffi_timer(void) {
  struct timespec now;
  clock_gettime(CLOCK_MONOTONIC, &now);
  return (mjtNum)now.tv_sec + 1e-9 * (mjtNum)now.tv_nsec;
}
