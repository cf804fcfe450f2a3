// mj_step's nstep and substep loops: the steps under one guard, with the mjData held.
// Declared in guard.h.

#include <setjmp.h>

#include <mujoco/mujoco.h>

#include "guard_chain.h"
#include "guard.h"

// One guard around the whole loop: the per-step cost is mj_step's alone.
int mjcffi_step(const mjModel* m, mjData* d, int nstep) {
  return mjcffi_step_substep(m, d, nstep, NULL);
}

// mujoco-py's substep order: the callback runs before each mj_step, so it sees the
// state the step starts from and what the previous step computed (contacts, sensors).
// nstep 0 calls fn once and steps nothing (MjSim.substep_callback()).
int mjcffi_step_substep(const mjModel* m, mjData* d, int nstep, mjfGeneric fn) {
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
  for (int i = 0; i < nstep; i++) {
    if (fn) {
      fn(m, d);
    }
    mj_step(m, d);
  }
  mjcffi_guard_leave(&guard, 0);
  mjcffi_data_leave(d);
  return 0;
}
