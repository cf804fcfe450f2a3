// The claims: one call at a time on an mjData, and one thread at a time on an mjSpec;
// in a forked child, only the forking thread's.  Declared in guard_chain.h (C) and
// claims.h (the spec claims, for Python too).

#include <pthread.h>
#include <stdio.h>

#include <mujoco/mujoco.h>
#include <mujoco/mjbatch.h>

#include "guard_chain.h"
#include "guard.h"
#include "claims.h"

//---------------------------------- one call per mjData -------------------------------------------
//
// A call that writes an mjData (the guards of functions taking a non-const mjData*) holds
// it for its duration.  Another thread's call on it is refused: MuJoCo's functions keep
// no lock, and two steps of one mjData overwrite each other's arena and stack.  The
// holding thread may nest calls (a callback may use the stack, compute a Jacobian,
// rerun kinematics), except those that restart the pipeline and reset the arena
// (mj_step, mj_forward, mj_resetData, ...): inside the call that is computing d, they
// would pull the contacts and constraint rows from under it.

typedef enum {CLAIM_DATA, CLAIM_SPEC, CLAIM_BATCH} mjcffi_claim_kind;

typedef struct {
  const void* key;              // the mjData, mjSpec or mjBatch held
  pthread_t owner;
  int depth;                    // calls on it on the owner's thread, nested
  mjcffi_claim_kind kind;       // what key is: a fork recounts the specs held
} mjcffi_claim;

#define MJCFFI_MAX_CLAIMS 1024  // mjData and mjSpec held at once, all threads together
static mjcffi_claim claims[MJCFFI_MAX_CLAIMS];
static int nclaims;
static pthread_mutex_t claims_lock = PTHREAD_MUTEX_INITIALIZER;

static int mjcffi_refuse_call(int kind, const char* func, const char* why) {
  char text[1024];
  snprintf(text, sizeof(text), "%s: %s", func, why);
  return mjcffi_record_error(kind, text);
}

// The index of key's claim, or nclaims; under claims_lock.
static int find_claim(const void* key) {
  int i = 0;
  while (i < nclaims && claims[i].key != key) {
    i++;
  }
  return i;
}

// Drop one level of key's claim; returns 1 when that was the last.  Under claims_lock.
static int drop_claim(const void* key) {
  int i = find_claim(key);
  if (i < nclaims && --claims[i].depth == 0) {
    claims[i] = claims[--nclaims];
    return 1;
  }
  return 0;
}

int mjcffi_data_enter(const mjData* d, int restarts, const char* func) {
  if (!d) {
    return 0;                   // MuJoCo's own NULL check speaks for itself
  }
  pthread_t self = pthread_self();
  const char* why = NULL;
  int kind = MJCFFI_ERROR_BUSY;
  pthread_mutex_lock(&claims_lock);
  int i = find_claim(d);
  if (i == nclaims) {
    if (nclaims < MJCFFI_MAX_CLAIMS) {
      claims[nclaims++] = (mjcffi_claim){d, self, 1, CLAIM_DATA};
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
  drop_claim(d);
  pthread_mutex_unlock(&claims_lock);
}

// A rollout's caller holds every mjData of the call; a pool thread rolling out on one
// takes over its claim, so that a callback on that thread is judged as on the caller's
// (it may nest, and may not restart d's pipeline).  The caller's leave drops it.
void mjcffi_data_adopt(const mjData* d) {
  pthread_mutex_lock(&claims_lock);
  int i = find_claim(d);
  if (i < nclaims) {
    claims[i].owner = pthread_self();
  }
  pthread_mutex_unlock(&claims_lock);
}

//---------------------------------- one thread per mjSpec -----------------------------------------
//
// MuJoCo's spec functions keep no lock either: a compile on one thread beside a compile or
// to_xml on another frees memory the other is using.  Any call on a spec (or on one of its
// elements) holds the spec; another thread's call is refused with MJCFFI_ERROR_SPEC_BUSY.
// The holding thread may nest (mjcffi's Python holds a spec across a method that makes
// several calls).  `mjcffi_spec_holds` counts the specs held, for Python's quick test.

int mjcffi_spec_holds;

const mjSpec* mjcffi_spec_of(const mjsElement* element) {
  return element ? mjs_getSpec(element) : NULL;
}

int mjcffi_spec_enter(const mjSpec* s, const char* func) {
  if (!s) {
    return 0;
  }
  pthread_t self = pthread_self();
  const char* why = NULL;
  pthread_mutex_lock(&claims_lock);
  int i = find_claim(s);
  if (i == nclaims) {
    if (nclaims < MJCFFI_MAX_CLAIMS) {
      claims[nclaims++] = (mjcffi_claim){s, self, 1, CLAIM_SPEC};
      __atomic_add_fetch(&mjcffi_spec_holds, 1, __ATOMIC_RELAXED);
    } else {
      why = "more mjData and mjSpec are in MuJoCo calls at once than mjcffi can track (1024)";
    }
  } else if (!pthread_equal(claims[i].owner, self)) {
    why = "this spec is in a MuJoCo call on another thread; a spec and its elements take "
          "one thread at a time (give each thread a spec of its own: spec.copy())";
  } else {
    claims[i].depth++;
  }
  pthread_mutex_unlock(&claims_lock);
  return why ? mjcffi_refuse_call(MJCFFI_ERROR_SPEC_BUSY, func, why) : 0;
}

void mjcffi_spec_leave(const mjSpec* s) {
  if (!s) {
    return;
  }
  pthread_mutex_lock(&claims_lock);
  if (drop_claim(s)) {
    __atomic_sub_fetch(&mjcffi_spec_holds, 1, __ATOMIC_RELAXED);
  }
  pthread_mutex_unlock(&claims_lock);
}

int mjcffi_element_check(const mjsElement* element, const char* func) {
  const mjSpec* s = mjcffi_spec_of(element);
  if (mjcffi_spec_enter(s, func)) {
    return 1;
  }
  mjcffi_spec_leave(s);
  return 0;
}


//---------------------------------- one call per Batch --------------------------------------------
//
// A call on an mjBatch (the guards of functions taking a non-const mjBatch*) holds it.  A
// second call while it runs is refused, whichever thread makes it: from a callback on the
// batch's own threads (a cffi callback of mjb_apply, a Python mju_user_warning) it would
// wait for the call that waits for it, and MuJoCo keeps no lock for another thread's.

int mjcffi_batch_enter(const mjBatch* b, const char* func) {
  if (!b) {
    return 0;
  }
  int busy = 0;
  pthread_mutex_lock(&claims_lock);
  if (find_claim(b) < nclaims) {
    busy = 1;
  } else if (nclaims < MJCFFI_MAX_CLAIMS) {
    claims[nclaims++] = (mjcffi_claim){b, pthread_self(), 1, CLAIM_BATCH};
  } else {
    busy = 2;
  }
  pthread_mutex_unlock(&claims_lock);
  if (busy == 1) {
    return mjcffi_refuse_call(MJCFFI_ERROR_POOL_REENTRY, func,
                              "this Batch is in a call already (a callback on its threads "
                              "called it, or another thread is using it); a Batch takes one "
                              "call at a time");
  }
  return busy ? mjcffi_refuse_call(MJCFFI_ERROR_POOL_REENTRY, func, "more calls at once than "
                                   "mjcffi can track (1024)") : 0;
}

void mjcffi_batch_leave(const mjBatch* b) {
  if (!b) {
    return;
  }
  pthread_mutex_lock(&claims_lock);
  drop_claim(b);
  pthread_mutex_unlock(&claims_lock);
}


//---------------------------------- fork ----------------------------------------------------------
//
// fork() copies the calling thread alone.  claims_lock, held by another thread at that
// moment, would stay held in the child forever, and so would the claims of threads that
// do not exist there: the child could never use their mjData.  So the lock is taken
// across the fork, and the child keeps only the forking thread's claims.

static void claims_before_fork(void) {
  pthread_mutex_lock(&claims_lock);
}

static void claims_after_fork_in_parent(void) {
  pthread_mutex_unlock(&claims_lock);
}

static void claims_after_fork_in_child(void) {
  pthread_mutex_init(&claims_lock, NULL);
  pthread_t self = pthread_self();
  int specs = 0;
  int i = 0;
  while (i < nclaims) {
    if (!pthread_equal(claims[i].owner, self)) {
      claims[i] = claims[--nclaims];
      continue;
    }
    specs += claims[i].kind == CLAIM_SPEC;
    i++;
  }
  __atomic_store_n(&mjcffi_spec_holds, specs, __ATOMIC_RELAXED);
}

// Once, as the module is loaded: before any claim can be taken.
__attribute__((constructor)) static void claims_register_fork_handlers(void) {
  pthread_atfork(claims_before_fork, claims_after_fork_in_parent, claims_after_fork_in_child);
}
