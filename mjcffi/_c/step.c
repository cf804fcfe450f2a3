// mj_step's nstep and substep loops: the steps under one guard, with the mjData held,
// stopped at a step boundary by Ctrl-C (interrupt.c).  Declared in guard.h.

#include <setjmp.h>

#include <mujoco/mujoco.h>

#include "guard_chain.h"
#include "guard.h"
#include "interrupt.h"

// One guard around the whole loop: the per-step cost is mj_step's alone.
int mjcffi_step(const mjModel* m, mjData* d, int nstep) {
  return mjcffi_step_loop(m, d, nstep, NULL, nstep > 1 ? mjcffi_interrupt_token() : -1);
}

int mjcffi_step_substep(const mjModel* m, mjData* d, int nstep, mjfGeneric fn) {
  return mjcffi_step_loop(m, d, nstep, fn, nstep > 1 ? mjcffi_interrupt_token() : -1);
}

// mujoco-py's substep order: the callback runs before each mj_step, so it sees the
// state the step starts from and what the previous step computed (contacts, sensors).
// nstep 0 calls fn once and steps nothing (MjSim.substep_callback()).  A SIGINT after
// `token` stops the loop before the next step (and its callback): the steps done stay,
// and MJCFFI_STEP_STOPPED says so, since a Python handler of the user's own that does
// not raise would otherwise leave the caller unaware that steps are missing.
int mjcffi_step_loop(const mjModel* m, mjData* d, int nstep, mjfGeneric fn, int token) {
  mjcffi_guard guard;
  if (mjcffi_data_enter(d, 1, "mj_step")) {
    return 1;
  }
  mjcffi_guard_enter(&guard);
  if (setjmp(guard.env)) {
    mjcffi_guard_leave(&guard, 1);
    mjcffi_data_leave(d);
    return 1;
  }
  if (nstep == 0 && fn) {
    fn(m, d);
  }
  int i = 0;
  for (; i < nstep && !mjcffi_interrupted(token); i++) {
    if (fn) {
      fn(m, d);
    }
    mj_step(m, d);
  }
  mjcffi_guard_leave(&guard, 0);
  mjcffi_data_leave(d);
  return i < nstep ? MJCFFI_STEP_STOPPED : 0;
}
