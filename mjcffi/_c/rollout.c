// mjcffi's native rollout loop: batches of open-loop trajectories, with the
// semantics of the official mujoco.rollout, run by a small pthread pool.
// Compiled into mjcffi._mjcffi by mjcffi/_c/build.py; declared in rollout.h.
//
// Each rollout is guarded on its own thread (the guard chain of guard.c is
// per thread), so an mju_error fails that rollout alone and never reaches
// MuJoCo's default handler, which would end the process.

#include <math.h>
#include <pthread.h>
#include <sched.h>
#include <setjmp.h>
#include <signal.h>
#include <stdatomic.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#include <mujoco/mujoco.h>
#include <mujoco/mjbatch.h>   // guards.h declares the mjb_* guards too

#include "guard_chain.h"
#include "guards.h"
#include "guard.h"
#include "interrupt.h"
#include "rollout.h"

#define MESSAGE_SIZE 2048   // as guard.c's record of a caught error

// One batch, shared read-only by the threads that roll it out; only `next`
// changes while they run.
typedef struct {
  const mjModel* const* m;
  int nmodel;
  mjData* const* d;
  int nbatch, nstep, control_spec, chunk_size, nchunk;
  size_t nstate, nsensordata;
  const mjtNum* state0;
  long long state0_stride;
  const mjtNum* warmstart0;
  long long warmstart0_stride;
  const mjtNum* control;
  long long control_rstride, control_tstride;
  mjtNum* state;
  mjtNum* sensordata;
  unsigned char* failed;
  int token;                  // the caller's SIGINT token (interrupt.h): stop when it moves
  atomic_int next;            // the next chunk to hand out
} rollout_job;

// The items (rollouts, sims) that failed on one thread: how many, and the lowest
// with its message and kind (MJCFFI_ERROR_*).
typedef struct {
  int nfailed;
  int first;
  int kind;
  char message[MESSAGE_SIZE];
} rollout_failures;


//---------------------------------- one rollout ---------------------------------------------------

// Write row `row` of the outputs from d: its full physics state and sensor values.
static void record(const rollout_job* job, const mjModel* m, const mjData* d, size_t row) {
  if (job->state) {
    mj_getState(m, d, job->state + row*job->nstate, mjSTATE_FULLPHYSICS);
  }
  if (job->sensordata) {
    mju_copy(job->sensordata + row*job->nsensordata, d->sensordata, (int)job->nsensordata);
  }
}

static void fill_nan(mjtNum* rows, size_t n) {
  for (size_t i = 0; i < n; i++) {
    rows[i] = NAN;
  }
}

static int warned(const mjData* d) {
  for (int i = 0; i < mjNWARNING; i++) {
    if (d->warning[i].number) {
      return 1;
    }
  }
  return 0;
}

static void note_failure(rollout_failures* failures, int r, int kind, const char* message) {
  if (failures->nfailed++ == 0 || r < failures->first) {
    failures->first = r;
    failures->kind = kind;
    snprintf(failures->message, MESSAGE_SIZE, "%s", message ? message : "mju_error");
  }
}

// Roll out trajectory r on d.  The inputs that control_spec leaves out are
// reset from the model, so nothing left in d from before changes the result.
static void roll_one(const rollout_job* job, mjData* d, int r, rollout_failures* failures) {
  const mjModel* m = job->m[job->nmodel == 1 ? 0 : r];
  int spec = job->control_spec;
  size_t row0 = (size_t)r * (size_t)job->nstep;
  volatile int reached = 0;   // the step under way when an error jumps back here
  mjcffi_guard guard;

  mjcffi_guard_enter(&guard);
  if (setjmp(guard.env)) {
    mjcffi_guard_leave(&guard, 1);
    note_failure(failures, r, MJCFFI_ERROR_FATAL, mjcffi_take_error());
    mj_resetData(m, d);       // the error skipped the release of d's stack frames
    size_t from = row0 + (size_t)reached, n = (size_t)job->nstep - (size_t)reached;
    if (job->state) fill_nan(job->state + from*job->nstate, n*job->nstate);
    if (job->sensordata) fill_nan(job->sensordata + from*job->nsensordata, n*job->nsensordata);
    if (job->failed) job->failed[r] = 1;
    return;
  }

  if (!(spec & mjSTATE_MOCAP_POS) || !(spec & mjSTATE_MOCAP_QUAT)) {
    for (mjtSize i = 0; i < m->nbody; i++) {
      int id = m->body_mocapid[i];
      if (id < 0) continue;
      if (!(spec & mjSTATE_MOCAP_POS)) mju_copy3(d->mocap_pos + 3*id, m->body_pos + 3*i);
      if (!(spec & mjSTATE_MOCAP_QUAT)) mju_copy4(d->mocap_quat + 4*id, m->body_quat + 4*i);
    }
  }
  if (!(spec & mjSTATE_EQ_ACTIVE)) {
    for (mjtSize i = 0; i < m->neq; i++) {
      d->eq_active[i] = m->eq_active0[i];
    }
  }
  mj_setState(m, d, job->state0 + r*job->state0_stride, mjSTATE_FULLPHYSICS);
  if (job->warmstart0) {
    mju_copy(d->qacc_warmstart, job->warmstart0 + r*job->warmstart0_stride, (int)m->nv);
  } else {
    mju_zero(d->qacc_warmstart, (int)m->nv);
  }
  for (int i = 0; i < mjNWARNING; i++) {
    d->warning[i].number = 0;
  }

  for (int t = 0; t < job->nstep && !mjcffi_interrupted(job->token); t++) {
    reached = t;
    // a warning means the rollout diverged: repeat its last outputs to the end
    if (warned(d)) {
      for (; t < job->nstep; t++) {
        record(job, m, d, row0 + t);
      }
      break;
    }
    if (job->control) {
      mj_setState(m, d, job->control + r*job->control_rstride + t*job->control_tstride, spec);
    }
    mj_step(m, d);
    record(job, m, d, row0 + t);
  }
  mjcffi_guard_leave(&guard, 0);
}

// Take chunks of the batch until none is left, rolling them out on this thread's data.
static void rollout_work(void* arg, int thread, rollout_failures* failures) {
  rollout_job* job = (rollout_job*)arg;
  mjData* d = job->d[thread];
  const mjModel* m = job->m[0];
  int spec = job->control_spec;
  if (thread) {
    mjcffi_data_adopt(d);     // the caller holds it: its callbacks here are judged as there
  }
  for (;;) {
    int chunk = atomic_fetch_add_explicit(&job->next, 1, memory_order_relaxed);
    if (chunk >= job->nchunk || mjcffi_interrupted(job->token)) {
      return;
    }
    // inputs left out of control_spec start at zero; the sizes are every model's
    if (!(spec & mjSTATE_CTRL)) mju_zero(d->ctrl, (int)m->nu);
    if (!(spec & mjSTATE_QFRC_APPLIED)) mju_zero(d->qfrc_applied, (int)m->nv);
    if (!(spec & mjSTATE_XFRC_APPLIED)) mju_zero(d->xfrc_applied, 6*(int)m->nbody);
    int start = chunk * job->chunk_size;
    int end = job->nbatch - start < job->chunk_size ? job->nbatch : start + job->chunk_size;
    for (int r = start; r < end; r++) {
      roll_one(job, d, r, failures);
    }
  }
}


//---------------------------------- thread pool ---------------------------------------------------
//
// A job is a function that every thread runs with its index (the calling
// thread is 0, worker i is i), taking items (chunks of rollouts, sims) from a
// shared counter until none is left.  A job is published with a new
// generation; every worker takes part (one that finds no item left just
// checks in), and the caller returns once all have checked in, so no worker
// touches a job after its call.
//
// Waking a sleeping thread costs tens of microseconds (more in a VM), as much
// as a short batch.  So a worker that has checked in, and a caller waiting
// for the others, first spin for a while (SPIN_NS, yielding the core now and
// then) on the generation or the count, and only then sleep on a condition
// variable; `sleepers` tells the caller whether anyone must be woken.

#define SPIN_NS 50000

// What a thread of a job runs: its share of `job`, failures noted in `failures`.
typedef void (*pool_work)(void* job, int thread, rollout_failures* failures);

// The pool whose job this thread is running now (its caller's share or a worker's), or
// NULL: a callback that the job runs must not call into that pool, which waits for it.
static _Thread_local mjcffi_rollout_pool* running_pool;

typedef struct {
  mjcffi_rollout_pool* pool;
  int id;
} rollout_worker;

struct mjcffi_rollout_pool_ {
  int nthread;                  // data per batch: the workers and the caller
  int nstarted;                 // worker threads running
  pthread_t* threads;
  rollout_worker* workers;
  rollout_failures* failures;   // one per thread; [0] is the caller's
  pthread_mutex_t call;         // one batch at a time
  pthread_mutex_t lock;         // for sleeping and waking
  pthread_cond_t wake, done;
  int sleepers;                 // workers asleep on `wake` (under lock)
  atomic_ulong generation;      // bumped for each batch (changed under lock)
  atomic_int busy;              // workers not yet done with this batch
  atomic_int stop;
  pool_work work;               // the job: written before the generation it belongs to
  void* job;
};

static void relax(void) {
#if defined(__x86_64__) || defined(__i386__)
  __builtin_ia32_pause();
#elif defined(__aarch64__)
  __asm__ __volatile__("yield");
#endif
}

static long long now_ns(void) {
  struct timespec t;
  clock_gettime(CLOCK_MONOTONIC, &t);
  return (long long)t.tv_sec * 1000000000LL + t.tv_nsec;
}

// The pace of one spin-wait: `while (!ready && keep_spinning(&s))`.
typedef struct {
  int i;
  long long deadline;
} spinner;

// 1 while the wait may go on spinning, 0 once SPIN_NS have passed.
static int keep_spinning(spinner* s) {
  if ((++s->i & 63) == 0) {
    long long t = now_ns();
    if (!s->deadline) {
      s->deadline = t + SPIN_NS;
    } else if (t > s->deadline) {
      return 0;
    }
    sched_yield();      // on a busy machine, let whoever waits for this core run
  }
  relax();
  return 1;
}

static void* worker_main(void* arg) {
  rollout_worker* self = (rollout_worker*)arg;
  mjcffi_rollout_pool* pool = self->pool;
  unsigned long seen = 0;
  for (;;) {
    unsigned long generation;
    spinner spin = {0, 0};
    while ((generation = atomic_load_explicit(&pool->generation, memory_order_acquire)) == seen &&
           !atomic_load(&pool->stop) && keep_spinning(&spin)) {}
    if (generation == seen && !atomic_load(&pool->stop)) {
      pthread_mutex_lock(&pool->lock);
      pool->sleepers++;
      while ((generation = atomic_load(&pool->generation)) == seen &&
             !atomic_load(&pool->stop)) {
        pthread_cond_wait(&pool->wake, &pool->lock);
      }
      pool->sleepers--;
      pthread_mutex_unlock(&pool->lock);
    }
    if (atomic_load(&pool->stop)) {
      return NULL;
    }
    seen = generation;
    running_pool = pool;
    pool->work(pool->job, self->id, &pool->failures[self->id]);
    running_pool = NULL;
    if (atomic_fetch_sub(&pool->busy, 1) == 1) {
      pthread_mutex_lock(&pool->lock);     // the caller may be asleep on `done`
      pthread_cond_signal(&pool->done);
      pthread_mutex_unlock(&pool->lock);
    }
  }
}

void mjcffi_rollout_pool_free(mjcffi_rollout_pool* pool) {
  if (!pool) {
    return;
  }
  pthread_mutex_lock(&pool->lock);
  atomic_store(&pool->stop, 1);
  pthread_cond_broadcast(&pool->wake);
  pthread_mutex_unlock(&pool->lock);
  for (int i = 0; i < pool->nstarted; i++) {
    pthread_join(pool->threads[i], NULL);
  }
  pthread_cond_destroy(&pool->done);
  pthread_cond_destroy(&pool->wake);
  pthread_mutex_destroy(&pool->lock);
  pthread_mutex_destroy(&pool->call);
  free(pool->failures);
  free(pool->workers);
  free(pool->threads);
  free(pool);
}

mjcffi_rollout_pool* mjcffi_rollout_pool_new(int nthread) {
  if (nthread < 2) {
    return NULL;
  }
  mjcffi_rollout_pool* pool = (mjcffi_rollout_pool*)calloc(1, sizeof(mjcffi_rollout_pool));
  if (!pool) {
    return NULL;
  }
  pool->nthread = nthread;
  pool->threads = (pthread_t*)calloc(nthread, sizeof(pthread_t));
  pool->workers = (rollout_worker*)calloc(nthread, sizeof(rollout_worker));
  pool->failures = (rollout_failures*)calloc(nthread, sizeof(rollout_failures));
  pthread_mutex_init(&pool->call, NULL);
  pthread_mutex_init(&pool->lock, NULL);
  pthread_cond_init(&pool->wake, NULL);
  pthread_cond_init(&pool->done, NULL);
  atomic_init(&pool->generation, 0);
  atomic_init(&pool->busy, 0);
  atomic_init(&pool->stop, 0);
  if (!pool->threads || !pool->workers || !pool->failures) {
    mjcffi_rollout_pool_free(pool);
    return NULL;
  }

  // workers inherit a mask that blocks every signal: Python handles them on its own thread
  sigset_t all, previous;
  sigfillset(&all);
  pthread_sigmask(SIG_SETMASK, &all, &previous);
  for (int i = 1; i < nthread; i++) {
    pool->workers[i].pool = pool;
    pool->workers[i].id = i;
    if (pthread_create(&pool->threads[pool->nstarted], NULL, worker_main, &pool->workers[i])) {
      break;
    }
    pool->nstarted++;
  }
  pthread_sigmask(SIG_SETMASK, &previous, NULL);
  if (pool->nstarted != nthread - 1) {
    mjcffi_rollout_pool_free(pool);
    return NULL;
  }
  return pool;
}


//---------------------------------- a job ---------------------------------------------------------

// Merge `f` into `into`: the counts add up, the lowest item's message wins.
static void merge_failures(rollout_failures* into, const rollout_failures* f) {
  if (!f->nfailed) {
    return;
  }
  if (!into->nfailed || f->first < into->first) {
    into->first = f->first;
    into->kind = f->kind;
    snprintf(into->message, MESSAGE_SIZE, "%s", f->message);
  }
  into->nfailed += f->nfailed;
}

// Take `pool` for a job on this thread: 0, or 1 with the refusal pending.  A thread
// running one of the pool's jobs (a callback inside it) is refused, as the pool would
// wait for that very callback; so is one running another pool's job when this pool is
// busy, as two pools whose callbacks call each other would each wait for the other.
// Other threads wait their turn: calls on one pool run one after the other.
static int take_pool(mjcffi_rollout_pool* pool, const char* func) {
  const char* why = NULL;
  if (running_pool == pool) {
    why = "this pool is running the call whose callback made this one; a pool's "
          "callback may not call that pool";
  } else if (running_pool) {
    if (pthread_mutex_trylock(&pool->call)) {
      why = "this pool is busy, and this call comes from a callback of another pool's "
            "call: it does not wait, as the two pools could wait for each other forever";
    }
    if (!why) return 0;
  } else {
    pthread_mutex_lock(&pool->call);
    return 0;
  }
  char text[512];
  snprintf(text, sizeof(text), "%s: %s", func, why);
  return mjcffi_record_error(MJCFFI_ERROR_POOL_REENTRY, text);
}

// This thread's share of a job, with running_pool saying whose it is.
static void work_share(mjcffi_rollout_pool* pool, pool_work work, void* job,
                       rollout_failures* failures) {
  mjcffi_rollout_pool* outer = running_pool;
  running_pool = pool;
  work(job, 0, failures);
  running_pool = outer;
}

// Hold the `n` mjData of a call for this thread (claims.c), all or none: 0, or 1 with
// the refusal pending.
static int hold_data(mjData* const* d, int n, const char* func) {
  for (int i = 0; i < n; i++) {
    if (mjcffi_data_enter(d[i], 1, func)) {
      while (i--) mjcffi_data_leave(d[i]);
      return 1;
    }
  }
  return 0;
}

static void release_data(mjData* const* d, int n) {
  for (int i = 0; i < n; i++) {
    mjcffi_data_leave(d[i]);
  }
}

// Run `job` on every thread of `pool` (or on the calling thread alone, when
// `alone` or without a pool), holding the `nheld` mjData `held` for its duration
// (taken once it is this call's turn on the pool: calls on one pool wait for each
// other, not refuse); its failures end up in `result`.  0, or 1 when the call was
// refused (see take_pool, hold_data).
static int run_job(mjcffi_rollout_pool* pool, int alone, pool_work work, void* job,
                   mjData* const* held, int nheld, rollout_failures* result,
                   const char* func) {
  result->nfailed = 0;
  if (pool && take_pool(pool, func)) {
    return 1;
  }
  if (hold_data(held, nheld, func)) {
    if (pool) pthread_mutex_unlock(&pool->call);
    return 1;
  }
  if (!pool || alone) {
    work_share(pool, work, job, result);
    release_data(held, nheld);
    if (pool) pthread_mutex_unlock(&pool->call);
    return 0;
  }

  for (int i = 0; i < pool->nthread; i++) {
    pool->failures[i].nfailed = 0;
  }
  pool->work = work;
  pool->job = job;
  atomic_store(&pool->busy, pool->nstarted);
  pthread_mutex_lock(&pool->lock);
  atomic_fetch_add_explicit(&pool->generation, 1, memory_order_release);
  if (pool->sleepers) {
    pthread_cond_broadcast(&pool->wake);
  }
  pthread_mutex_unlock(&pool->lock);

  work_share(pool, work, job, &pool->failures[0]);

  // wait for every worker to check in: spin a while, then sleep
  spinner spin = {0, 0};
  while (atomic_load(&pool->busy) && keep_spinning(&spin)) {}
  pthread_mutex_lock(&pool->lock);
  while (atomic_load(&pool->busy)) {
    pthread_cond_wait(&pool->done, &pool->lock);
  }
  pthread_mutex_unlock(&pool->lock);
  pool->work = NULL;
  pool->job = NULL;

  for (int i = 0; i < pool->nthread; i++) {
    merge_failures(result, &pool->failures[i]);
  }
  release_data(held, nheld);
  pthread_mutex_unlock(&pool->call);
  return 0;
}


//---------------------------------- a batch of rollouts -------------------------------------------

int mjcffi_rollout(mjcffi_rollout_pool* pool,
                   const mjModel* const* m, int nmodel, mjData* const* d,
                   int nbatch, int nstep, int control_spec, int chunk_size,
                   const mjtNum* state0, long long state0_stride,
                   const mjtNum* warmstart0, long long warmstart0_stride,
                   const mjtNum* control, long long control_rstride,
                   long long control_tstride,
                   mjtNum* state, mjtNum* sensordata,
                   unsigned char* failed, char* message, int message_size) {
  if (nbatch < 1 || nstep < 1) {
    return 0;
  }
  if (chunk_size < 1) {
    chunk_size = 1;
  }
  rollout_job job = {
    .m = m, .nmodel = nmodel, .d = d,
    .nbatch = nbatch, .nstep = nstep, .control_spec = control_spec, .chunk_size = chunk_size,
    .nchunk = (int)(((long long)nbatch + chunk_size - 1) / chunk_size),
    .nstate = (size_t)mj_stateSize(m[0], mjSTATE_FULLPHYSICS),
    .nsensordata = (size_t)m[0]->nsensordata,
    .state0 = state0, .state0_stride = state0_stride,
    .warmstart0 = warmstart0, .warmstart0_stride = warmstart0_stride,
    .control = control, .control_rstride = control_rstride,
    .control_tstride = control_tstride,
    .state = state, .sensordata = sensordata, .failed = failed,
  };
  atomic_init(&job.next, 0);
  job.token = mjcffi_interrupt_token();

  // one chunk needs no other thread; d[0] is this thread's data.  Every d is held, as
  // mj_step holds its own: MuJoCo's mj_step inside does not claim it
  rollout_failures result;
  if (run_job(pool, job.nchunk == 1, rollout_work, &job, d, pool ? pool->nthread : 1,
              &result, "rollout")) {
    return -1;
  }
  if (mjcffi_interrupted(job.token)) {
    return -2;
  }
  if (result.nfailed) snprintf(message, message_size, "%s", result.message);
  return result.nfailed;
}


//---------------------------------- a step of many sims -------------------------------------------

// One call of mjcffi_sim_pool_run, shared by its threads; only `next` changes.
typedef struct {
  const mjModel* const* m;
  mjData* const* d;
  const mjfGeneric* substep;
  int nsim, nsubsteps, forward;
  unsigned char* status;
  int token;                  // the caller's SIGINT token (interrupt.h)
  atomic_int next;            // the next sim to hand out
} sim_job;

// Take sims one at a time until none is left, stepping (or forwarding) each
// under its own guard: an error stops that sim alone.
static void sim_work(void* arg, int thread, rollout_failures* failures) {
  sim_job* job = (sim_job*)arg;
  (void)thread;               // each sim has its own mjData
  for (;;) {
    int i = atomic_fetch_add_explicit(&job->next, 1, memory_order_relaxed);
    if (i >= job->nsim || mjcffi_interrupted(job->token)) {
      return;
    }
    int caught = job->forward
        ? mjcffi_guard_mj_forward(job->m[i], job->d[i])
        : mjcffi_step_loop(job->m[i], job->d[i], job->nsubsteps,
                           job->substep ? job->substep[i] : NULL, job->token);
    // a sim that a SIGINT stopped has not failed: the call as a whole returns -2
    if (caught && caught != MJCFFI_STEP_STOPPED) {
      int kind = mjcffi_error_kind();
      job->status[i] = (unsigned char)(1 + kind);
      note_failure(failures, i, kind, mjcffi_take_error());
    }
  }
}

int mjcffi_sim_pool_run(mjcffi_rollout_pool* pool,
                        const mjModel* const* m, mjData* const* d, const mjfGeneric* substep,
                        int nsim, int nsubsteps, int forward,
                        unsigned char* status, char* message, int message_size) {
  if (nsim < 1) {
    return 0;
  }
  sim_job job = {
    .m = m, .d = d, .substep = substep,
    .nsim = nsim, .nsubsteps = nsubsteps, .forward = forward, .status = status,
  };
  atomic_init(&job.next, 0);
  for (int i = 0; i < nsim; i++) {
    status[i] = 0;
  }
  job.token = forward ? -1 : mjcffi_interrupt_token();
  rollout_failures result;     // each sim's step or forward holds its own d
  if (run_job(pool, nsim == 1, sim_work, &job, NULL, 0, &result, "MjSimPool")) {
    return -1;
  }
  if (mjcffi_interrupted(job.token)) {
    return -2;
  }
  if (result.nfailed) snprintf(message, message_size, "%s", result.message);
  return result.nfailed;
}
