// The per-mjData claims: one call at a time on an mjData.  Declared in guard_chain.h.

#include <pthread.h>
#include <stdio.h>

#include <mujoco/mujoco.h>

#include "guard_chain.h"
#include "guard.h"

//---------------------------------- one call per mjData -------------------------------------------
//
// A call that writes an mjData (the guards of functions taking a non-const mjData*) holds
// it for its duration.  Another thread's call on it is refused: MuJoCo's functions keep
// no lock, and two steps of one mjData overwrite each other's arena and stack.  The
// holding thread may nest calls (a callback may use the stack, compute a Jacobian,
// rerun kinematics), except those that restart the pipeline and reset the arena
// (mj_step, mj_forward, mj_resetData, ...): inside the call that is computing d, they
// would pull the contacts and constraint rows from under it.

typedef struct {
  const mjData* d;
  pthread_t owner;
  int depth;                    // calls on d on the owner's thread, nested
} mjcffi_claim;

#define MJCFFI_MAX_CLAIMS 1024  // mjData held at once, all threads together
static mjcffi_claim claims[MJCFFI_MAX_CLAIMS];
static int nclaims;
static pthread_mutex_t claims_lock = PTHREAD_MUTEX_INITIALIZER;

static int mjcffi_refuse_call(int kind, const char* func, const char* why) {
  char text[1024];
  snprintf(text, sizeof(text), "%s: %s", func, why);
  return mjcffi_record_error(kind, text);
}

int mjcffi_data_enter(const mjData* d, int restarts, const char* func) {
  if (!d) {
    return 0;                   // MuJoCo's own NULL check speaks for itself
  }
  pthread_t self = pthread_self();
  const char* why = NULL;
  int kind = MJCFFI_ERROR_BUSY;
  pthread_mutex_lock(&claims_lock);
  int i = 0;
  while (i < nclaims && claims[i].d != d) {
    i++;
  }
  if (i == nclaims) {
    if (nclaims < MJCFFI_MAX_CLAIMS) {
      claims[nclaims++] = (mjcffi_claim){d, self, 1};
    } else {
      why = "more mjData are in MuJoCo calls at once than mjcffi can track (1024)";
    }
  } else if (!pthread_equal(claims[i].owner, self)) {
    why = "this mjData is in a MuJoCo call on another thread; an mjData takes one "
          "call at a time (give each thread an MjData of its own)";
  } else if (restarts) {
    kind = MJCFFI_ERROR_REENTRY;
    why = "this mjData is in a MuJoCo call on this thread already (a callback "
          "re-entered MuJoCo with the data being computed); this call would reset "
          "the arrays that call is using";
  } else {
    claims[i].depth++;
  }
  pthread_mutex_unlock(&claims_lock);
  return why ? mjcffi_refuse_call(kind, func, why) : 0;
}

void mjcffi_data_leave(const mjData* d) {
  if (!d) {
    return;
  }
  pthread_mutex_lock(&claims_lock);
  for (int i = 0; i < nclaims; i++) {
    if (claims[i].d == d) {
      if (--claims[i].depth == 0) {
        claims[i] = claims[--nclaims];
      }
      break;
    }
  }
  pthread_mutex_unlock(&claims_lock);
}
