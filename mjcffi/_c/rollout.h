/* Declarations of the native rollout loop (mjcffi/_c/rollout.c), read by
   mjcffi/_c/build.py into the cffi cdef after the generated cdef.h, and used
   by mjcffi/rollout.py.  Hand-written. */

/* A pool of nthread - 1 worker threads that roll out chunks of a batch
   beside the calling thread, which works as the nthread-th: a batch takes
   nthread mjData, one per thread.  The threads persist until
   mjcffi_rollout_pool_free.  NULL when nthread < 2 or a thread could not be
   started. */
typedef struct mjcffi_rollout_pool_ mjcffi_rollout_pool;
mjcffi_rollout_pool* mjcffi_rollout_pool_new(int nthread);
void mjcffi_rollout_pool_free(mjcffi_rollout_pool* pool);

/* One batch of open-loop rollouts, as mujoco.rollout defines them.

   Rollout r (0 <= r < nbatch) uses model m[nmodel == 1 ? 0 : r] and starts
   from state0 + r*state0_stride (mjSTATE_FULLPHYSICS) and qacc_warmstart
   warmstart0 + r*warmstart0_stride (zero if warmstart0 is NULL).  Before
   step t it sets control + r*control_rstride + t*control_tstride under
   control_spec (if control is not NULL); after it, it writes rows
   r*nstep + t of state (nstate wide) and sensordata (nsensordata wide),
   either of which may be NULL.  A stride of 0 repeats one row for all.

   A rollout whose warning counters rise has diverged: its remaining rows
   repeat its last state and sensor values.  A rollout in which MuJoCo raises
   mju_error has failed: its data is reset, its remaining rows from the
   failed step on are NaN, failed[r] is set to 1 (failed may be NULL), and
   the other rollouts go on.

   d holds nthread data (the pool's, or 1 without a pool); chunk_size
   rollouts at a time go to each thread.  Calls on one pool run one after
   the other, but a call from a callback of a pool's job into that pool, or
   into a busy one, is refused.  Each d is held for the call, as mj_step
   holds its own (guard_chain.h): a d in a call on another thread refuses
   the rollout, and a callback of the rollout may not step, forward or reset
   the d it runs on, nor another thread's call use any d.  A SIGINT on the
   main thread (interrupt.h) stops every rollout at its next step.  Returns
   the number of failed rollouts, and copies the message of the lowest failed
   one into message (message_size bytes); -1 when refused (the error is
   pending: MJCFFI_ERROR_POOL_REENTRY, or MJCFFI_ERROR_BUSY or _REENTRY for a
   d held), -2 when a SIGINT stopped it. */
int mjcffi_rollout(mjcffi_rollout_pool* pool,
                   const mjModel* const* m, int nmodel, mjData* const* d,
                   int nbatch, int nstep, int control_spec, int chunk_size,
                   const mjtNum* state0, long long state0_stride,
                   const mjtNum* warmstart0, long long warmstart0_stride,
                   const mjtNum* control, long long control_rstride,
                   long long control_tstride,
                   mjtNum* state, mjtNum* sensordata,
                   unsigned char* failed, char* message, int message_size);

/* MjSimPool's step and forward: sim i (0 <= i < nsim) runs, on a thread of
   the pool (or the calling thread alone, without one), either
   mjcffi_step_substep(m[i], d[i], nsubsteps, substep ? substep[i] : NULL)
   or, when `forward`, mj_forward(m[i], d[i]); each under its own guard, so an
   mju_error (or a d[i] held by another call) stops that sim alone and the
   others go on.  The d[i] must all differ.  status[i] becomes 0, or
   1 + MJCFFI_ERROR_* (see guard.h) for a sim that failed.  Calls on one
   pool run one after the other, refused as mjcffi_rollout's are.  A SIGINT
   stops the steps of every sim at a step boundary.  Returns the number of
   failed sims, and copies the message of the lowest failed one into message
   (message_size bytes); -1 when refused, -2 when a SIGINT stopped it. */
int mjcffi_sim_pool_run(mjcffi_rollout_pool* pool,
                        const mjModel* const* m, mjData* const* d, const mjfGeneric* substep,
                        int nsim, int nsubsteps, int forward,
                        unsigned char* status, char* message, int message_size);
